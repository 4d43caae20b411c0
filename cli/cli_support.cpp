#include "cli_support.h"

#include <CLI/CLI.hpp>

#include "diag/warnings.h"
#include "api/scene.h"
#include "image_io.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <sstream>
#include <fstream>
#include <iostream>
#include <stdexcept>
#include <sys/stat.h>
#include <unistd.h>

namespace sdfc {

CompileOptions compileOptionsFrom(const CommandLine& cl) {
  CompileOptions o = api::LoadOptions::defaultCompileOptions();
  o.emit.bounding_volumes = !cl.no_bounds;
  o.emit.planned_bounds = !cl.no_bounds;
  o.emit.line_directives = cl.line_directives;
  o.emit.sobol = !cl.white_noise;
  o.emit.march.paper_baseline = cl.paper_baseline;
  o.emit.scene_box = !cl.paper_baseline;  // the paper marches every ray from the camera
  o.emit.count_evaluations = cl.count_evaluations;
  o.emit.count_event = cl.count_event;
  // The paper marches every surface; --no-analytic-spheres for A/B runs.
  o.emit.analytic_spheres = !cl.paper_baseline && !cl.no_analytic_spheres;
  o.emit.prune = cl.prune;
  o.fuse_transforms = !cl.no_fuse;
  if (!cl.mesh_mode.empty()) o.check.mesh_mode = cl.mesh_mode == "exact" ? MeshMode::Exact : MeshMode::Grid;
  o.instancing.threshold = cl.instance_threshold;
  o.optimize_spirv = cl.optimize;
  // `compile --timings N` measures glslang itself: no cache there.
  o.spirv_cache = !cl.no_cache && cl.timings == 0;
  // The kernel holds only the code of the view it draws (docs/kernel_contract.md).
  o.emit.view = kernelViewFromName(cl.view).value_or(KernelView::Beauty);
  o.emit.layers = cl.layers;
  return o;
}

// 'text', or a long one (30,000 digits) by its start and length.
static std::string quotedValue(const std::string& text) {
  if (text.size() <= 80) return "'" + text + "'";
  return "'" + text.substr(0, 60) + "...' (" + std::to_string(text.size()) + " characters)";
}

int loadOptionsFrom(const CommandLine& cl, api::LoadOptions& load) {
  for (const std::string& d : cl.defines) {
    const auto define = api::parseDefine(d);
    if (!define) {
      std::cerr << "sdfc: error: -D expects name=number with a plain decimal number such as 2, "
                   "-0.5 or 1e3 (finite in float32), got "
                << quotedValue(d) << "\n";
      return kExitUsage;
    }
    load.defines[define->first] = define->second;
  }
  load.werror = cl.werror;
  for (const std::string& w : cl.warning_options) {
    if (w == "error") {
      load.werror = true;
      continue;
    }
    const std::string name = w.substr(0, 3) == "no-" ? w.substr(3) : "";
    if (!isWarningName(name)) {
      std::string list;
      for (const WarningInfo& info : kWarnings) list += std::string(list.empty() ? "" : ", ") + info.name;
      const std::string near = nearestName(name.empty() ? w : name, warningNames());
      std::cerr << "sdfc: error: -W" << w << ": "
                << (name.empty() ? "expected -Wno-NAME or -Werror"
                                 : "no warning is named '" + name + "'")
                << (near.empty() ? "" : "; did you mean '-Wno-" + near + "'?") << " (warnings: " << list
                << ")\n";
      return kExitUsage;
    }
    load.disabled_warnings.push_back(name);
  }
  return kExitOk;
}

bool outputIsAnInput(const std::string& output, const std::string& scene_path, const CompiledScene& c) {
  struct stat out;
  if (output.empty() || output == "-" || ::stat(output.c_str(), &out) != 0) return false;  // nothing there yet
  std::vector<std::pair<std::string, const char*>> inputs = {{scene_path, nullptr}};
  for (const auto& file : c.scene.imported_sources) inputs.push_back({file->path, "imports"});
  for (const std::string& path : c.scene.data_files) inputs.push_back({path, "reads"});
  for (const auto& [input, how] : inputs) {
    struct stat in;
    if (::stat(input.c_str(), &in) == 0 && in.st_dev == out.st_dev && in.st_ino == out.st_ino) {
      std::cerr << "sdfc: error: the output '" << output << "' is "
                << (how ? "'" + input + "', which the scene " + how : std::string("the scene being read"))
                << "; choose another -o\n";
      return true;
    }
  }
  return false;
}

LoadedScene loadScene(const CommandLine& cl, Diagnostics& diags, bool emit, bool spirv,
                      CompileOptions options, bool options_given) {
  LoadedScene out;
  api::LoadOptions load;
  load.compile = options_given ? options : compileOptionsFrom(cl);
  load.compile.produce_spirv = spirv;
  load.emit = emit;
  out.exit_code = loadOptionsFrom(cl, load);
  if (out.exit_code != kExitOk) return out;
  for (const std::string& name : load.disabled_warnings) diags.disableWarning(name);
  std::unique_ptr<api::Scene> scene = api::loadFile(cl.input, load);
  if (!scene->io_error.empty()) {
    std::cerr << "sdfc: error: " << scene->io_error << "\n";
    out.exit_code = kExitIo;
    return out;
  }
  if (cl.diagnostics_format == "json") {
    std::cerr << scene->diagnosticsJson(cl.error_limit);
  } else {
    std::cerr << scene->diagnosticsText(isatty(STDERR_FILENO), cl.error_limit);
  }
  if (!scene->ok()) out.exit_code = kExitScene;
  out.compiled = std::move(scene->compiled);
  // Every command that writes -o: never over one of its inputs (a scene
  // exported or compiled over itself was lost).
  // (A sequence writes other names: render checks each frame's.)
  if (out.exit_code == kExitOk && cl.frames.empty() && outputIsAnInput(cl.output, cl.input, out.compiled))
    out.exit_code = kExitUsage;
  // The caller's list keeps the diagnostics, and the files they point into, alive.
  for (const Diagnostic& d : scene->diagnostics.all()) diags.add(d);
  out.keep = std::move(scene);
  return out;
}

std::optional<double> parsePlainNumber(const std::string& text) { return api::parsePlainNumber(text); }

CLI::Validator numberIn(double lo, double hi, bool open_low) {
  std::ostringstream range;
  range << (open_low ? "(" : "[") << lo << ", " << hi << "]";
  return CLI::Validator(
      [lo, hi, open_low, range = range.str()](std::string& text) {
        const std::optional<double> value = parsePlainNumber(text);
        if (value && (open_low ? *value > lo : *value >= lo) && *value <= hi) return std::string();
        return "expects a number in " + range + ", got " + quotedValue(text);
      },
      "NUMBER in " + range.str());
}

CLI::Validator wholeNumberIn(long long lo, long long hi) {
  std::ostringstream range;
  range << lo << " to " << hi;
  return CLI::Validator(
      [lo, hi, range = range.str()](std::string& text) {
        // [-+]?[0-9]{1,18}, scanned by hand (std::regex recurses per character).
        const size_t sign = !text.empty() && (text[0] == '-' || text[0] == '+') ? 1 : 0;
        const size_t digits = text.size() - sign;
        if (digits >= 1 && digits <= 18 && text.find_first_not_of("0123456789", sign) == std::string::npos) {
          const long long value = std::stoll(text);
          if (value >= lo && value <= hi) return std::string();
        }
        return "expects a whole number from " + range + ", got " + quotedValue(text);
      },
      "WHOLE NUMBER from " + range.str());
}

CLI::Validator limitOf(api::Option option) {
  const api::OptionLimit& l = api::optionLimit(option);
  return l.whole ? wholeNumberIn((long long)l.lo, (long long)l.hi) : numberIn(l.lo, l.hi, l.open_low);
}

bool checkTimeOption(double time, const char* option) {
  const std::string problem = api::optionProblem(api::Option::Time, time, option);
  if (problem.empty()) return true;
  std::cerr << "sdfc: error: " << problem << "\n";
  return false;
}

bool renderOverridesFrom(const CommandLine& cl, RenderOverrides& o) {
  if (!cl.size.empty()) {
    const auto size = parseImageSize(cl.size);
    if (!size) {
      std::cerr << "sdfc: error: --size expects WxH with sides from 1 to 16384, e.g. 640x360\n";
      return false;
    }
    o.width = size->first;
    o.height = size->second;
  }
  if (cl.spp > 0) o.spp = cl.spp;
  if (cl.bounces >= 0) o.bounces = cl.bounces;
  if (cl.light_samples >= 0) o.light_samples = cl.light_samples;
  if (!checkTimeOption(cl.time)) return false;
  o.seed = cl.seed;
  o.time = cl.time;
  return true;
}

bool checkImageExtension(const std::string& path) {
  try {
    imageFormatFromPath(path);
    return true;
  } catch (const std::exception& e) {
    std::cerr << "sdfc: error: -o '" << path << "': " << e.what() << "\n";
    return false;
  }
}

std::unique_ptr<SourceFile> readSceneFile(const std::string& path) {
  if (const std::string why = sourceFileProblem(path); !why.empty()) {
    std::cerr << "sdfc: error: cannot read '" << path << "': " << why << "\n";
    return nullptr;
  }
  std::unique_ptr<SourceFile> file = readSourceFile(path);
  if (!file) std::cerr << "sdfc: error: cannot read '" << path << "': " << std::strerror(errno) << "\n";
  return file;
}

}  // namespace sdfc
