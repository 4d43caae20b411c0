// `sdfc view`: the frame loop. Each frame: poll input (or run the script), poll the
// file, swap in a finished background build, draw one progressive pass with the
// shared Renderer (dynamic resolution while the camera moves), tone-map exactly as
// the PNG writer does and present.
#pragma once
#include <string>

#include "api/scene.h"
#include "image_io.h"

namespace sdfc::view {

// What `sdfc view` is asked for (the command line fills it from its flags).
struct ViewOptions {
  std::string input;
  // -D, -W and the compiler's flags; load.compile.emit.view is set per build.
  api::LoadOptions load;
  std::string diagnostics_format = "text";  // text | json, as `sdfc check`
  int error_limit = kDefaultErrorLimit;
  std::string size;       // "WxH", empty: the scene's
  int device = -1;
  bool stage_timings = false, no_cache = false, force_bounds = false;
  std::string view = "beauty";
  bool denoise = false;   // --denoise other than none
  bool dynamic_resolution = true;
  int spp = 0, bounces = -1, light_samples = -1;  // 0 / -1: the scene's
  unsigned seed = 0;
  double time = 0;
  ToneMap tone;
  std::string script, frame_log;
};

// Exit codes as the other commands: 0 on quit, 3 without a display or on a device
// failure (or any validation message when validation is on), 2 for a bad script.
int runView(const ViewOptions& options);

}  // namespace sdfc::view
