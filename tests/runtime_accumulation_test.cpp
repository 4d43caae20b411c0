// The progressive core shared by `sdfc render` and `sdfc view`: an accumulation
// drawn pass by pass (Renderer::addPass, one pass a frame in the view) must show
// exactly the image render() returns for the same samples and pass split, and
// its AOVs (read back in the first pass) must equal render()'s (final pass).
#include <gtest/gtest.h>

#include "driver/compile.h"
#include "scene_render.h"
#include "vulkan_context.h"

namespace sdfc {
namespace {

TEST(RuntimeAccumulation, PassByPassMeanEqualsRender) {
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
    o.height = 300;  // two bands
    o.spp = 3;
    o.seed = 7;
    RenderSettings settings = renderSettingsFor(c, o);
    settings.max_samples_per_pass = 1;  // the view's split: one sample a pass
    const RenderOutput rendered = renderer.render(cameraFor(c.scene), settings);

    Accumulation acc = renderer.startAccumulation(cameraFor(c.scene), settings, true);
    EXPECT_EQ(acc.band_count, 2u);
    const FloatImage before = acc.mean();
    for (float v : before.rgba) ASSERT_EQ(v, 0.0f);
    FloatImage one_sample;
    for (uint32_t i = 0; i < 3; ++i) {
      renderer.addPass(acc, 1);
      if (i == 0) one_sample = acc.mean();
    }
    EXPECT_EQ(acc.samples_done, 3u);
    const FloatImage mean = acc.mean();
    ASSERT_EQ(mean.rgba.size(), rendered.color.rgba.size());
    size_t differing = 0, changed = 0;
    for (size_t i = 0; i < mean.rgba.size(); i += 4)
      for (int ch = 0; ch < 3; ++ch) {
        differing += mean.rgba[i + ch] != rendered.color.rgba[i + ch];
        changed += mean.rgba[i + ch] != one_sample.rgba[i + ch];
      }
    EXPECT_EQ(differing, 0u);
    EXPECT_GT(changed, mean.rgba.size() / 40);  // more samples really refine the image
    // One pass (kept as floats, Accumulation::first_pass) gives render()'s 1-spp image.
    {
      RenderSettings one = settings;
      one.spp = 1;
      const RenderOutput single = renderer.render(cameraFor(c.scene), one);
      EXPECT_EQ(one_sample.rgba, single.color.rgba);
      Accumulation whole = renderer.startAccumulation(cameraFor(c.scene), one, false);
      whole.settings.band_pixels = 0;
      renderer.addPass(whole, 1);
      FloatImage reused(3, 3);  // meanInto resizes and overwrites
      whole.meanInto(reused);
      EXPECT_EQ(reused.rgba, single.color.rgba);
    }
    EXPECT_EQ(acc.normal_depth.rgba, rendered.normal_depth.rgba);
    EXPECT_EQ(acc.albedo_steps.rgba, rendered.albedo_steps.rgba);
  }
  destroyContext(context);
  EXPECT_EQ(validationMessageCount(), 0);
}

}  // namespace
}  // namespace sdfc
