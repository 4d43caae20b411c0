// Assembles a kernel shader the way the emitter does (docs/kernel_contract.md):
// #version 450, shader_interface.h, prelude.glsl, scene code, pathtrace.glsl,
// with the SDFC_* feature macros as real #defines (SDFC_TRACE and SDFC_ALL_VIEWS
// unless a view macro is given). Header-only because the test
// CMakeLists globs *_test.cpp only.
#pragma once
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "spirv/glsl_to_spirv.h"

namespace sdfc::test {

inline std::string readSourceFile(const std::string& relative_path) {
  const std::string path = std::string(SDFC_SOURCE_DIR) + "/" + relative_path;
  std::ifstream file(path);
  if (!file) throw std::runtime_error("cannot read " + path);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

inline std::string kernelScene(const std::string& name) {
  return readSourceFile("tests/kernel_scenes/" + name);
}

// `defines` are "NAME" or "NAME VALUE" lines placed after #version, before all else.
inline std::string assembleKernel(const std::string& scene_code,
                                  const std::vector<std::string>& defines) {
  std::string source = "#version 450\n";
  // Without a view macro: the all-in-one kernel (every view at run time), as
  // these tests draw several views from one pipeline.
  bool view_given = false;
  for (const std::string& d : defines)
    view_given = view_given || d.rfind("SDFC_TRACE", 0) == 0 || d.rfind("SDFC_VIEW_", 0) == 0;
  if (!view_given) source += "#define SDFC_TRACE\n#define SDFC_ALL_VIEWS\n";
  for (const std::string& d : defines) source += "#define " + d + "\n";
  source += readSourceFile("runtime/shader_interface.h");
  source += "\n" + readSourceFile("compiler/emit/kernel/prelude.glsl");
  source += "\n" + scene_code + "\n";
  source += readSourceFile("compiler/emit/kernel/pathtrace.glsl");
  return source;
}

inline SpirvResult compileKernel(const std::string& scene_code,
                                 const std::vector<std::string>& defines,
                                 const std::string& name = "kernel_test.frag") {
  return glslToSpirv(assembleKernel(scene_code, defines), ShaderStage::Fragment, name);
}

}  // namespace sdfc::test
