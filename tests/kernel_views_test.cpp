// Kernels specialised per view (EmitOptions::view): a debug view's kernel holds
// no path tracing (no bounce loop, random numbers, BSDFs or lights beyond the
// visible sphere lights), the beauty kernel no debug-view code, and each draws
// exactly the image the all-in-one kernel draws for that view.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "driver/compile.h"
#include "scene_render.h"
#include "vulkan_context.h"

namespace sdfc {
namespace {

std::string readExample(const std::string& name) {
  std::ifstream f(std::filesystem::path(SDFC_SOURCE_DIR) / "examples" / name, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

CompiledScene compileView(const std::string& name, const std::string& text, KernelView view) {
  CompileOptions options;
  options.emit.view = view;
  Diagnostics diags;
  CompiledScene c = compileSource(name, text, options, diags);
  EXPECT_TRUE(c.ok) << diags.format();
  return c;
}

// True when the SPIR-V's debug names (OpName strings) contain `name`.
bool spirvNames(const std::vector<uint32_t>& words, const std::string& name) {
  const std::string bytes(reinterpret_cast<const char*>(words.data()), words.size() * 4);
  return bytes.find(name) != std::string::npos;
}

// Symbols only the path tracer has: the bounce loop's function, the sampler,
// light sampling and the BSDFs.
const char* const kTraceSymbols[] = {"tracePath", "rand2", "beginSample", "pcg4d", "evalBsdf",
                                     "sampleLight", "misBsdfWeight"};

TEST(KernelViews, DebugViewKernelsHoldNoPathTracing) {
  const std::string castle = readExample("castle.sdf");
  for (KernelView view : {KernelView::Normal, KernelView::Steps, KernelView::Depth, KernelView::Albedo}) {
    SCOPED_TRACE(kernelViewName(view));
    const CompiledScene c = compileView("castle.sdf", castle, view);
    ASSERT_TRUE(c.ok);
    for (const char* symbol : kTraceSymbols) {
      EXPECT_EQ(c.emitted.glsl.find(symbol), std::string::npos) << symbol;
      EXPECT_FALSE(spirvNames(c.spirv, symbol)) << symbol;
    }
    EXPECT_EQ(c.emitted.glsl.find("frame.view"), std::string::npos);  // no run-time view choice
    // Only the albedo view reads materials (march()'s normal taps evaluate sdSceneMaterial).
    EXPECT_EQ(c.emitted.glsl.find("? sdSceneMaterial(q)") != std::string::npos,
              view == KernelView::Albedo);
  }
  // The beauty kernel has the tracer and no debug views.
  const CompiledScene beauty = compileView("castle.sdf", castle, KernelView::Beauty);
  EXPECT_NE(beauty.emitted.glsl.find("tracePath"), std::string::npos);
  EXPECT_EQ(beauty.emitted.glsl.find("kViewSteps) color"), std::string::npos);
  EXPECT_EQ(beauty.emitted.glsl.find("frame.view"), std::string::npos);
  // And the all-in-one kernel both.
  const CompiledScene all = compileView("castle.sdf", castle, KernelView::All);
  EXPECT_NE(all.emitted.glsl.find("kViewSteps) color"), std::string::npos);
  EXPECT_NE(all.emitted.glsl.find("frame.view"), std::string::npos);
  EXPECT_LT(compileView("castle.sdf", castle, KernelView::Normal).spirv.size() * 3,
            all.spirv.size() * 2);  // the normal kernel is well under 2/3 of the all-in-one
}

TEST(KernelViewNames, RoundTrip) {
  for (int i = 0; i <= static_cast<int>(KernelView::All); ++i) {
    const KernelView v = static_cast<KernelView>(i);
    EXPECT_EQ(kernelViewFromName(kernelViewName(v)), v);
  }
  EXPECT_FALSE(kernelViewFromName("beauty2"));
  EXPECT_EQ(static_cast<uint32_t>(KernelView::Normal), gpu::kViewNormal);
  EXPECT_EQ(static_cast<uint32_t>(KernelView::Iterations), gpu::kViewIterations);
}

// Each view's kernel draws bit for bit what the all-in-one kernel draws for that
// view: colour, and the attachments the view computes (the march steps always).
TEST(KernelViews, EachViewEqualsTheAllInOneKernel) {
  VulkanContext context;
  createContext(context);
  // castle: analytic planes, sun; colonnade: a sphere light (visible in every view).
  for (const char* name : {"castle.sdf", "colonnade.sdf"}) {
    SCOPED_TRACE(name);
    const std::string text = readExample(name);
    const CompiledScene all = compileView(name, text, KernelView::All);
    ASSERT_TRUE(all.ok);
    Renderer all_renderer(context, all);
    for (KernelView view : {KernelView::Normal, KernelView::Steps, KernelView::Depth, KernelView::Albedo,
                            KernelView::Beauty, KernelView::Iterations}) {
      SCOPED_TRACE(kernelViewName(view));
      const CompiledScene one = compileView(name, text, view);
      ASSERT_TRUE(one.ok);
      Renderer renderer(context, one);
      RenderOverrides o;
      o.width = 160;
      o.height = 90;
      o.spp = 2;
      o.view = static_cast<uint32_t>(view);
      const RenderSettings settings = renderSettingsFor(one, o);
      const RenderOutput expected = all_renderer.render(cameraFor(all.scene), settings);
      const RenderOutput got = renderer.render(cameraFor(one.scene), settings);
      EXPECT_EQ(got.color.rgba, expected.color.rgba);
      const size_t pixels = size_t(o.width.value()) * o.height.value();
      size_t hits = 0, differing = 0;
      for (size_t i = 0; i < pixels; ++i) {
        const float* e_nd = &expected.normal_depth.rgba[4 * i];
        const float* g_nd = &got.normal_depth.rgba[4 * i];
        const float* e_as = &expected.albedo_steps.rgba[4 * i];
        const float* g_as = &got.albedo_steps.rgba[4 * i];
        hits += e_nd[3] >= 0;
        differing += g_as[3] != e_as[3];  // steps
        differing += g_nd[3] != e_nd[3];  // depth
        if (view != KernelView::Steps && view != KernelView::Depth)
          for (int k = 0; k < 3; ++k) differing += g_nd[k] != e_nd[k];
        if (view == KernelView::Albedo || view == KernelView::Beauty || view == KernelView::Iterations)
          for (int k = 0; k < 3; ++k) differing += g_as[k] != e_as[k];
      }
      EXPECT_EQ(differing, 0u);
      EXPECT_GT(hits, pixels / 4);  // the scene is in view
    }
  }
  destroyContext(context);
  EXPECT_EQ(validationMessageCount(), 0);
}

}  // namespace
}  // namespace sdfc
