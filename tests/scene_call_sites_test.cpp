// Issue 29: lavapipe inlines every call of a scene function, so each call site
// in the kernel is a whole copy of the scene (of every instance group's lookup
// and traversal) that LLVM compiles at the first draw. A scene of one material
// has one: march() evaluates its normal's taps in its own loop.
#include <gtest/gtest.h>

#include <sstream>
#include <string>

#include "driver/compile.h"

namespace sdfc {
namespace {

// Calls of sdScene or sdSceneMaterial in the kernel (after the scene's own
// functions), comments left out.
int kernelSceneCalls(const std::string& glsl) {
  const size_t kernel = glsl.find("// ---- kernel:");
  EXPECT_NE(kernel, std::string::npos);
  std::istringstream lines(glsl.substr(kernel));
  int calls = 0;
  for (std::string line; std::getline(lines, line);) {
    line = line.substr(0, line.find("//"));
    for (const char* call : {"sdScene(", "sdSceneMaterial("})
      for (size_t at = line.find(call); at != std::string::npos; at = line.find(call, at + 1)) ++calls;
  }
  return calls;
}

CompiledScene compileText(const std::string& text, KernelView view, bool aovs) {
  CompileOptions options;
  options.emit.view = view;
  options.emit.aovs = aovs;
  Diagnostics diags;
  CompiledScene c = compileSource("groups.sdf", text, options, diags);
  EXPECT_TRUE(c.ok) << diags.format();
  return c;
}

// Two instance groups of one material (bench/instance_groups.py's kind).
std::string twoGroups(const std::string& materials) {
  std::ostringstream s;
  s << materials << "camera(position: [0, 6, 14], target: [0, 0, 0])\nscene {\n  plane(normal: [0, 1, 0], offset: 0)\n";
  for (int g = 0; g < 2; ++g) {
    s << "  instances(positions: [";
    for (int i = 0; i < 40; ++i) s << (i ? ", " : "") << "[" << (i % 7) - 3 + g * 0.5 << ", 1, " << (i / 7) - 3 << "]";
    s << "]) { " << (g ? "sphere(radius: 0.2)" : "box(size: [0.3, 0.3, 0.3])") << " }\n";
  }
  s << "}\n";
  return s.str();
}

TEST(SceneCallSites, OneMaterialHasOneInTheKernel) {
  const std::string text = twoGroups("");
  for (KernelView view : {KernelView::Beauty, KernelView::All, KernelView::Normal, KernelView::Albedo,
                          KernelView::Iterations}) {
    for (bool aovs : {false, true}) {
      SCOPED_TRACE(std::string(kernelViewName(view)) + (aovs ? " with AOVs" : ""));
      const CompiledScene c = compileText(text, view, aovs);
      ASSERT_TRUE(c.ok);
      EXPECT_TRUE(c.emitted.stats.features.count("SDFC_ONE_MATERIAL"));
      EXPECT_EQ(kernelSceneCalls(c.emitted.glsl), 1);
    }
  }
}

// Several materials: the taps read them through sdSceneMaterial, the march
// sdScene (no material bookkeeping per step): two, as before.
TEST(SceneCallSites, SeveralMaterialsHaveTwo) {
  std::string text = twoGroups("let red = diffuse(albedo: [0.8, 0.1, 0.1])\n");
  text.replace(text.find("box(size: [0.3, 0.3, 0.3])"), 26, "box(size: [0.3, 0.3, 0.3], material: red)");
  const CompiledScene c = compileText(text, KernelView::Beauty, false);
  ASSERT_TRUE(c.ok);
  EXPECT_FALSE(c.emitted.stats.features.count("SDFC_ONE_MATERIAL"));
  EXPECT_EQ(kernelSceneCalls(c.emitted.glsl), 2);
}

}  // namespace
}  // namespace sdfc
