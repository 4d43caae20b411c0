// Issue 36: a beauty render nothing denoises gets a kernel without AOV features
// (EmitOptions::aovs = false: no normal, depth or albedo, no jittered sums) and
// reads back only the colour and the march steps (RenderSettings::read_features).
// Both draw bit for bit the colour and the steps of the full kernel.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "driver/compile.h"
#include "scene_render.h"
#include "vk_check.h"
#include "vulkan_context.h"

namespace sdfc {
namespace {

std::string readExample(const std::string& name) {
  std::ifstream f(std::filesystem::path(SDFC_SOURCE_DIR) / "examples" / name, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

CompiledScene compileKernel(const std::string& name, KernelView view, bool aovs) {
  CompileOptions options;
  options.emit.view = view;
  options.emit.aovs = aovs;
  Diagnostics diags;
  CompiledScene c = compileSource(name, readExample(name), options, diags);
  EXPECT_TRUE(c.ok) << diags.format();
  return c;
}

// Code only the feature recording has.
const char* const kFeatureSymbols[] = {"g_aov_normal", "g_aov_albedo", "aov_nd", "coverage",
                                       "kAovSpecular", "aovThroughSpecular", "aov_follow"};

TEST(KernelFeatures, BeautyWithoutFeaturesHoldsNoFeatureCode) {
  // glass_and_metal: specular materials (kAovSpecular); colonnade: a sphere light.
  for (const char* name : {"glass_and_metal.sdf", "colonnade.sdf"}) {
    SCOPED_TRACE(name);
    const CompiledScene full = compileKernel(name, KernelView::Beauty, true);
    const CompiledScene bare = compileKernel(name, KernelView::Beauty, false);
    ASSERT_TRUE(full.ok && bare.ok);
    EXPECT_TRUE(bare.emitted.stats.features.count("SDFC_NO_AOVS"));
    for (const char* symbol : kFeatureSymbols) EXPECT_EQ(bare.emitted.glsl.find(symbol), std::string::npos) << symbol;
    EXPECT_NE(full.emitted.glsl.find("g_aov_normal"), std::string::npos);
    EXPECT_NE(bare.emitted.glsl.find("g_aov_steps"), std::string::npos);  // the step statistics
    EXPECT_LT(bare.spirv.size(), full.spirv.size());
    // The other views keep theirs (the all-in-one kernel's debug views read them).
    for (KernelView view : {KernelView::All, KernelView::Iterations, KernelView::Normal}) {
      const CompiledScene other = compileKernel(name, view, false);
      EXPECT_FALSE(other.emitted.stats.features.count("SDFC_NO_AOVS")) << kernelViewName(view);
      EXPECT_EQ(other.emitted.glsl, compileKernel(name, view, true).emitted.glsl) << kernelViewName(view);
    }
  }
}

TEST(KernelFeatures, OnlyADenoisedBeautyImageReadsThem) {
  ImageOptions o;  // nlr, the default
  EXPECT_TRUE(imageReadsFeatures(gpu::kViewBeauty, 2, o));
  EXPECT_FALSE(imageReadsFeatures(gpu::kViewBeauty, 1, o));  // no second half: nlr does nothing
  EXPECT_FALSE(imageReadsFeatures(gpu::kViewNormal, 16, o));
  o.denoiser = Denoiser::None;
  EXPECT_FALSE(imageReadsFeatures(gpu::kViewBeauty, 64, o));
  o.denoiser = Denoiser::Bilateral;  // needs no halves: filters a 1-spp image
  EXPECT_TRUE(imageReadsFeatures(gpu::kViewBeauty, 1, o));
}

// The featureless kernel, and the full kernel read back without features, draw
// the full kernel's colour and primary-ray steps bit for bit.
TEST(KernelFeatures, SameColourAndStepsAsTheFullKernel) {
  VulkanContext context;
  createContext(context);
  // glass_and_metal: specular materials; colonnade: a sphere light.
  for (const char* name : {"glass_and_metal.sdf", "colonnade.sdf"}) {
    SCOPED_TRACE(name);
    const CompiledScene full = compileKernel(name, KernelView::Beauty, true);
    const CompiledScene bare = compileKernel(name, KernelView::Beauty, false);
    ASSERT_TRUE(full.ok && bare.ok);
    Renderer full_renderer(context, full);
    Renderer bare_renderer(context, bare);
    // Steps of the AOV ray, and (jittered, as nlr's 1-spp image asks) their mean
    // over the samples' first rays.
    for (int spp : {1, 3}) for (bool jittered : {false, true}) {
      SCOPED_TRACE(std::to_string(spp) + (jittered ? " spp, jittered" : " spp"));
      RenderOverrides o;
      o.width = 48;
      o.height = 27;
      o.spp = spp;
      RenderSettings settings = renderSettingsFor(full, o);
      settings.max_samples_per_pass = 2;  // 3 spp: two passes, the AOV ray in the last
      settings.jittered_aovs = jittered;
      const RenderOutput expected = full_renderer.render(cameraFor(full.scene), settings);
      settings.read_features = false;
      for (Renderer* r : {&full_renderer, &bare_renderer}) {
        const RenderOutput got = r->render(cameraFor(full.scene), settings);
        ASSERT_EQ(got.color.rgba.size(), expected.color.rgba.size());
        size_t colour_differing = 0;  // jittered: a is the coverage, which the bare kernel has not
        for (size_t i = 0; i < got.color.rgba.size(); ++i)
          colour_differing += (!jittered || i % 4 != 3) && got.color.rgba[i] != expected.color.rgba[i];
        EXPECT_EQ(colour_differing, 0u);
        EXPECT_TRUE(got.normal_depth.empty());
        ASSERT_EQ(got.albedo_steps.rgba.size(), expected.albedo_steps.rgba.size());
        size_t differing = 0, steps = 0;
        for (size_t i = 3; i < got.albedo_steps.rgba.size(); i += 4) {
          differing += got.albedo_steps.rgba[i] != expected.albedo_steps.rgba[i];
          steps += expected.albedo_steps.rgba[i] > 0;
        }
        EXPECT_EQ(differing, 0u);
        EXPECT_GT(steps, 0u);
      }
    }
    // A denoiser fed by the featureless kernel would see zeros: refused.
    RenderOverrides o;
    o.width = 8;
    o.height = 6;
    o.spp = 2;
    EXPECT_THROW(renderImage(bare_renderer, bare, renderSettingsFor(bare, o), ImageOptions{}), RuntimeError);
  }
  destroyContext(context);
  EXPECT_EQ(validationMessageCount(), 0);
}

}  // namespace
}  // namespace sdfc
