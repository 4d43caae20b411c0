// Jittered AOVs (RenderSettings::jittered_aovs, gpu::kAovJittered): the
// denoisers' first-hit features as means over the colour's own jittered
// samples. They must leave the beauty image unchanged, not depend on how the
// samples are split into passes, and agree with the unjittered AOV ray away
// from edges.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "driver/compile.h"
#include "renderer.h"
#include "scene_render.h"
#include "vulkan_context.h"

namespace sdfc {
namespace {

TEST(KernelJitteredAovs, MeansOverTheSamples) {
  std::ifstream file(std::filesystem::path(SDFC_SOURCE_DIR) / "examples" / "castle.sdf");
  std::stringstream text;
  text << file.rdbuf();
  Diagnostics diags;
  const CompiledScene compiled = compileSource("castle.sdf", text.str(), CompileOptions{}, diags);
  ASSERT_TRUE(compiled.ok) << diags.format();
  VulkanContext context;
  createContext(context);
  {
    Renderer renderer(context, compiled);
    RenderOverrides o;
    o.width = 160;
    o.height = 90;
    o.spp = 8;
    RenderSettings centre = renderSettingsFor(compiled, o);
    RenderSettings jittered = centre;
    jittered.jittered_aovs = true;
    RenderSettings split = jittered;
    split.max_samples_per_pass = 3;  // passes of 3, 3, 2 samples
    const CameraDesc camera = cameraFor(compiled.scene);
    const RenderOutput c = renderer.render(camera, centre);
    RenderOutput j = renderer.render(camera, jittered);
    const RenderOutput s = renderer.render(camera, split);

    const size_t pixels = c.color.pixelCount();
    size_t partial = 0;
    for (size_t i = 0; i < pixels; ++i) {
      // The beauty image is the same; a holds the coverage.
      for (int k = 0; k < 3; ++k) ASSERT_EQ(j.color.rgba[i * 4 + k], c.color.rgba[i * 4 + k]) << i;
      const float coverage = j.color.rgba[i * 4 + 3];
      ASSERT_GE(coverage, 0.0f);
      ASSERT_LE(coverage, 1.0f);
      partial += coverage > 0.0f && coverage < 1.0f;
      // Another pass split: the same means up to float rounding.
      for (int k = 0; k < 4; ++k) {
        ASSERT_NEAR(s.normal_depth.rgba[i * 4 + k], j.normal_depth.rgba[i * 4 + k],
                    1e-4f * (1.0f + std::fabs(j.normal_depth.rgba[i * 4 + k])))
            << i;
        ASSERT_NEAR(s.albedo_steps.rgba[i * 4 + k], j.albedo_steps.rgba[i * 4 + k],
                    1e-4f * (1.0f + std::fabs(j.albedo_steps.rgba[i * 4 + k])))
            << i;
      }
    }
    EXPECT_GT(partial, 0u);  // silhouettes against the sky

    resolveJitteredAovs(j);
    size_t same_side = 0, interior = 0, agreeing = 0;
    for (size_t i = 0; i < pixels; ++i) {
      EXPECT_EQ(j.color.rgba[i * 4 + 3], 1.0f);
      const float* nj = &j.normal_depth.rgba[i * 4];
      const float* nc = &c.normal_depth.rgba[i * 4];
      same_side += (nj[3] >= 0) == (nc[3] >= 0);
      if (nj[3] < 0 || nc[3] < 0) continue;
      // Inside a surface the mean over the pixel is the centre's value.
      const float* aj = &j.albedo_steps.rgba[i * 4];
      const float* ac = &c.albedo_steps.rgba[i * 4];
      const float dot = nj[0] * nc[0] + nj[1] * nc[1] + nj[2] * nc[2];
      ++interior;
      agreeing += dot > 0.99f && std::fabs(nj[3] - nc[3]) < 0.02f * nc[3] &&
                  std::fabs(aj[0] - ac[0]) < 1e-3f;
    }
    EXPECT_GT(same_side, pixels * 97 / 100);
    EXPECT_GT(interior, pixels / 4);
    EXPECT_GT(agreeing, interior * 80 / 100);
    std::printf("jittered AOVs: %zu of %zu pixels partly covered; %zu of %zu hit pixels as the "
                "centre ray\n",
                partial, pixels, agreeing, interior);
  }
  destroyContext(context);
  EXPECT_EQ(validationMessageCount(), 0);
}

}  // namespace
}  // namespace sdfc
