// Facts about the Vulkan driver that the renderer's design rests on, measured
// rather than assumed, so a driver upgrade shows at once whether they still hold:
// CI runs this binary on the default (bundled Mesa 25.0.7) and SDFC_DRIVER=system.
#include <gtest/gtest.h>

#include <cstdio>
#include <algorithm>
#include <string>

#include "emit/embedded_sources.h"
#include "spirv/glsl_to_spirv.h"
#include "renderer.h"
#include "vulkan_context.h"

namespace sdfc {
namespace {

// Counts the iterations a fragment actually runs of a loop asked to run
// frame.seed times: a nested loop (inner 1000) and a flat one, each counted.
const char* kLoopProbe = R"(
layout(push_constant) uniform Push { FrameParams frame; };
layout(location = 0) out vec4 out_color;
layout(location = 1) out vec4 out_normal_depth;
layout(location = 2) out vec4 out_albedo_steps;
void main() {
  uint flat_count = 0u;
  for (uint i = 0u; i < frame.seed; i++) flat_count++;
  out_color = vec4(float(flat_count), 0.0, 0.0, 1.0);
  out_normal_depth = vec4(0.0, 0.0, 0.0, -1.0);
  out_albedo_steps = vec4(0.0);
}
)";

TEST(DriverFacts, LoopCapIsMeasured) {
  VulkanContext context;
  createContext(context);
  const bool lavapipe = context.properties.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
  std::printf("[ driver   ] %s, driver version 0x%x, api %u.%u.%u\n",
              context.properties.deviceName, context.properties.driverVersion,
              VK_API_VERSION_MAJOR(context.properties.apiVersion),
              VK_API_VERSION_MINOR(context.properties.apiVersion),
              VK_API_VERSION_PATCH(context.properties.apiVersion));
  const std::string source = std::string("#version 450\n") +
                             std::string(embeddedSource("shader_interface.h")) + kLoopProbe;
  const SpirvResult spirv = glslToSpirv(source, ShaderStage::Fragment, "loop_probe.glsl");
  ASSERT_TRUE(spirv.ok()) << spirv.log;
  {
    Renderer renderer(context, spirv.words);
    gpu::FrameParams params{};
    params.width = params.height = 4;
    auto ran = [&](uint32_t asked) {
      params.seed = asked;
      FloatImage color, normal_depth, albedo_steps;
      renderer.renderPass(params, 60.0, color, normal_depth, albedo_steps);
      const uint32_t count = uint32_t(color.at(0, 0)[0]);
      std::printf("[ driver   ] loop asked %u iterations, ran %u\n", asked, count);
      return count;
    };
    // Measured: Mesa 22.3.6's lavapipe (Vulkan 1.3) ends loops at the cap; Mesa
    // 25.0.7's (Vulkan 1.4, tools/lavapipe25.sh) runs them to the end. Either
    // way the driver must do one of the two, for every loop length.
    const bool capped = ran(200000u) == gpu::kLavapipeLoopCap;
    std::printf("[ driver   ] loops %s\n", capped ? "end at the cap" : "run to the end");
    // The renderer rations hierarchy visits exactly where loops are capped.
    EXPECT_EQ(context.loop_cap, capped);
    if (lavapipe && VK_API_VERSION_MINOR(context.properties.apiVersion) <= 3) {
      EXPECT_TRUE(capped);
    }
    if (!lavapipe) {
      EXPECT_FALSE(capped);
    }
    for (uint32_t asked : {1000u, 65534u, 65535u, 65536u, 200000u})
      EXPECT_EQ(ran(asked), capped ? std::min(asked, gpu::kLavapipeLoopCap) : asked);
  }
  destroyContext(context);
}

}  // namespace
}  // namespace sdfc
