// The runtime driving the real path-tracing kernel (tests/kernel_harness.h):
// a white-furnace sphere, so the expected pixels are known in closed form.
#include <gtest/gtest.h>

#include "kernel_harness.h"
#include "loop_budget.h"
#include "renderer.h"
#include "vulkan_context.h"

namespace sdfc {
namespace {

TEST(RuntimeKernel, WhiteFurnaceSphereThroughPasses) {
  const SpirvResult spirv =
      test::compileKernel(test::kernelScene("sphere_white_sky.glsl"), {"SDFC_HAS_DIFFUSE"});
  ASSERT_TRUE(spirv.ok()) << spirv.log;
  VulkanContext context;
  createContext(context);
  {
    Renderer renderer(context, spirv.words);
    RenderSettings settings;
    settings.width = 48;
    settings.height = 32;
    settings.spp = 8;
    settings.max_bounces = 3;
    settings.max_samples_per_pass = 3;  // several passes, uneven last one
    settings.loop_iterations_per_sample = loopIterationsPerSample(128, 3, 1, 0);
    settings.loop_iterations_per_pass = loopIterationsPerPassOverhead(128, 0);
    CameraDesc camera;
    camera.position = {0, 0, 4};
    const RenderOutput out = renderer.render(camera, settings);
    EXPECT_EQ(out.samples_done, 8u);
    EXPECT_EQ(out.passes, 3u);
    // Convex sphere under a sky of 1: one diffuse bounce always escapes -> albedo 0.8.
    const float* centre = out.color.at(24, 16);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(centre[c], 0.8f, 1e-3f);
    EXPECT_NEAR(out.color.at(0, 0)[0], 1.0f, 1e-4f);          // sky
    EXPECT_NEAR(out.normal_depth.at(24, 16)[3], 3.0f, 0.02f);  // hit at distance 3
    EXPECT_NEAR(out.normal_depth.at(24, 16)[2], 1.0f, 0.02f);  // normal faces the camera
    EXPECT_LT(out.normal_depth.at(0, 0)[3], 0.0f);             // miss
  }
  destroyContext(context);
  EXPECT_EQ(validationMessageCount(), 0);
}

}  // namespace
}  // namespace sdfc
