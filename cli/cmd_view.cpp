// `sdfc view`: the command line's flags as the viewer's options (viewer/ does not
// know CommandLine).
#include "cli_support.h"

#include <iostream>

#include "commands.h"
#include "view_loop.h"

namespace sdfc {

int runView(const CommandLine& cl) {
  if (!checkTimeOption(cl.time)) return kExitUsage;
  // As render's --size (a bad one was ignored, the scene's size used instead).
  if (!cl.size.empty() && !parseImageSize(cl.size)) {
    std::cerr << "sdfc: error: --size expects WxH with sides from 1 to 16384, e.g. 640x360\n";
    return kExitUsage;
  }
  view::ViewOptions o;
  o.input = cl.input;
  o.load.compile = compileOptionsFrom(cl);
  if (const int code = loadOptionsFrom(cl, o.load); code != kExitOk) return code;
  o.diagnostics_format = cl.diagnostics_format;
  o.error_limit = cl.error_limit;
  o.size = cl.size;
  o.device = cl.device;
  o.stage_timings = cl.stage_timings;
  o.no_cache = cl.no_cache;
  o.force_bounds = cl.force_bounds;
  o.view = cl.view;
  o.denoise = !cl.denoiser.empty() && cl.denoiser != "none";
  o.dynamic_resolution = !cl.no_dynamic_resolution;
  o.spp = cl.spp;
  o.bounces = cl.bounces;
  o.light_samples = cl.light_samples;
  o.seed = cl.seed;
  o.time = cl.time;
  o.tone.exposure_stops = float(cl.exposure);
  o.tone.curve = cl.aces ? ToneCurve::AcesFit : *toneCurveFromName(cl.tonemap);
  o.script = cl.script;
  o.frame_log = cl.frame_log;
  return view::runView(o);
}

}  // namespace sdfc
