#include "cli_support.h"

#include <cstdio>
#include <fstream>
#include <iostream>
#include <stdexcept>
#include <unistd.h>

namespace sdfc {

CompileOptions compileOptionsFrom(const CommandLine& cl) {
  CompileOptions o;
  o.emit.bounding_volumes = !cl.no_bounds;
  o.emit.line_directives = cl.line_directives;
  o.emit.sobol = !cl.white_noise;
  o.emit.march.paper_baseline = cl.paper_baseline;
  o.emit.scene_box = !cl.paper_baseline;  // the paper marches every ray from the camera
  o.emit.count_evaluations = cl.count_evaluations;
  o.fuse_transforms = !cl.no_fuse;
  o.instancing.threshold = cl.instance_threshold;
  o.optimize_spirv = cl.optimize;
  return o;
}

LoadedScene loadScene(const CommandLine& cl, Diagnostics& diags, bool emit, bool spirv,
                      CompileOptions options, bool options_given) {
  LoadedScene out;
  if (!options_given) options = compileOptionsFrom(cl);
  for (const std::string& d : cl.defines) {
    const size_t eq = d.find('=');
    char* end = nullptr;
    const double value = eq == std::string::npos ? 0 : std::strtod(d.c_str() + eq + 1, &end);
    if (eq == std::string::npos || eq == 0 || end == d.c_str() + eq + 1 || *end != '\0') {
      std::cerr << "sdfc: error: -D expects name=number, got '" << d << "'\n";
      out.exit_code = kExitUsage;
      return out;
    }
    options.check.defines[d.substr(0, eq)] = value;
  }
  std::unique_ptr<SourceFile> file = readSourceFile(cl.input);
  if (!file) {
    std::cerr << "sdfc: error: cannot read '" << cl.input << "'\n";
    out.exit_code = kExitIo;
    return out;
  }
  options.produce_spirv = spirv;
  out.compiled = emit ? compileSource(cl.input, std::move(file->text), options, diags)
                      : checkSource(cl.input, std::move(file->text), options, diags);
  if (cl.diagnostics_format == "json") {
    std::cerr << diags.formatJson();
  } else {
    std::cerr << diags.format(isatty(STDERR_FILENO));
  }
  const bool warnings = diags.all().size() > static_cast<size_t>(diags.errorCount());
  if (diags.hasErrors() || (cl.werror && warnings) || !out.compiled.scene.root)
    out.exit_code = kExitScene;
  return out;
}

void writeFileAtomically(const std::string& path, const std::string& bytes) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary);
    if (!f || !f.write(bytes.data(), static_cast<std::streamsize>(bytes.size())) || !f.flush()) {
      std::remove(tmp.c_str());
      throw std::runtime_error("cannot write '" + path + "'");
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw std::runtime_error("cannot write '" + path + "'");
  }
}

}  // namespace sdfc
