// A render drawn in several full-width bands (kBandPixels) must equal the
// same samples drawn as one full-size pass: the kernel's random sequence
// depends only on the absolute pixel, which FrameParams.tile_x/y restore.
#include <gtest/gtest.h>

#include "driver/compile.h"
#include "scene_render.h"
#include "vulkan_context.h"

namespace sdfc {
namespace {

TEST(RuntimeBands, BandedRenderEqualsOneFullSizePass) {
  Diagnostics diags;
  const CompiledScene c = compileSource(
      "t.sdf",
      "sun(direction: [0.3, 1, 0.2])\n"
      "scene { plane(normal: [0, 1, 0]) translate([0, 0.6, 0]) { sphere(radius: 0.6) } }\n",
      {}, diags);
  ASSERT_TRUE(c.ok) << diags.format();
  VulkanContext context;
  createContext(context);
  {
    Renderer renderer(context, c);
    RenderOverrides o;
    o.width = 512;
    o.height = 300;  // 153,600 pixels: two bands of kBandPixels / 512 rows
    ASSERT_GT(uint64_t(*o.width) * *o.height, kBandPixels);
    o.spp = 2;
    o.seed = 5;
    RenderSettings settings = renderSettingsFor(c, o);
    settings.max_samples_per_pass = 2;  // one pass, so both sides hold the same samples
    const RenderOutput banded = renderer.render(cameraFor(c.scene), settings);

    gpu::FrameParams p = makeFrameParams(cameraFor(c.scene), 512, 300, 0);
    p.seed = 5;
    p.view = gpu::kViewBeauty;
    p.max_bounces = settings.max_bounces;
    p.light_samples = settings.light_samples;
    p.sample_base = 0;
    p.sample_count = 2;
    FloatImage color, normal_depth, albedo_steps;
    renderer.renderPass(p, 60, color, normal_depth, albedo_steps);
    ASSERT_EQ(banded.color.rgba.size(), color.rgba.size());
    size_t differing = 0;
    for (size_t i = 0; i < color.rgba.size(); i += 4)
      for (int ch = 0; ch < 3; ++ch) differing += banded.color.rgba[i + ch] != color.rgba[i + ch];
    EXPECT_EQ(differing, 0u);
    EXPECT_EQ(banded.normal_depth.rgba, normal_depth.rgba);
  }
  destroyContext(context);
  EXPECT_EQ(validationMessageCount(), 0);
}

}  // namespace
}  // namespace sdfc
