// The per-frame camera-inside decision (runtime/camera_inside.h) against the
// kernel's own per-ray test: cameras inside, outside, on and within float error
// of a surface give the same depth image with a pinhole kernel (reads
// frame.camera_inside) as with a thin-lens kernel (tests sdScene(ro) itself).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "camera.h"
#include "camera_inside.h"
#include "driver/compile.h"
#include "renderer.h"
#include "spirv/glsl_to_spirv.h"
#include "vk_check.h"
#include "vulkan_context.h"

namespace sdfc {
namespace {

class CameraInside : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { createContext(context_); }
  static void TearDownTestSuite() {
    destroyContext(context_);
    EXPECT_EQ(validationMessageCount(), 0);
  }
  void TearDown() override { EXPECT_EQ(validationMessageCount(), 0); }

  static std::vector<uint32_t> kernel(const ir::Scene& scene) {
    EmitOptions options;
    const EmitResult emitted = emitGlsl(scene, options);
    SpirvResult spv = glslToSpirv(emitted.glsl, ShaderStage::Fragment, "camera_inside.frag");
    EXPECT_TRUE(spv.ok()) << spv.log;
    return spv.words;
  }

  // The depth (hit distance, -1 if missed) of a 1x1 depth image looking along -z.
  static float depth(Renderer& renderer, const glm::vec3& eye, float time, bool inside) {
    CameraDesc camera;
    camera.position = eye;
    camera.target = eye + glm::vec3(0, 0, -1);
    gpu::FrameParams p = makeFrameParams(camera, 1, 1, time);
    p.view = gpu::kViewDepth;
    p.camera_inside = inside ? 1u : 0u;
    FloatImage color, normal_depth, albedo_steps;
    renderer.renderPass(p, 120.0, color, normal_depth, albedo_steps);
    return normal_depth.rgba[3];
  }

  static VulkanContext context_;
};
VulkanContext CameraInside::context_;

TEST_F(CameraInside, PerFrameDecisionEqualsTheKernelsTest) {
  Diagnostics diags;
  // A moving sphere: time changes the answer at a fixed camera.
  CompiledScene compiled = compileSource(
      "t.sdf", "scene { translate([0, 0, 2 * time]) { sphere(radius: 1) } }", {}, diags);
  ASSERT_TRUE(compiled.ok);
  const std::vector<uint32_t> pinhole = kernel(compiled.scene);
  ir::Scene lens_scene = compiled.scene;
  lens_scene.camera.aperture = 0.1;  // SDFC_HAS_APERTURE: the kernel's own test
  const std::vector<uint32_t> lens = kernel(lens_scene);
  Renderer pinhole_renderer(context_, pinhole);
  Renderer lens_renderer(context_, lens);
  const MarchLimits& limits = compiled.emitted.limits;
  const float eps = float(limits.hit_epsilon);
  const float z_surface = 1.0f;  // the sphere's front at time 0
  const std::vector<float> offsets = {-0.5f, -4 * eps, -1.5f * eps, -eps, -0.5f * eps, 0,
                                      0.5f * eps, eps, 1.5f * eps, 4 * eps, 0.5f};
  int inside_count = 0, outside_count = 0;
  for (float time : {0.0f, 0.5f}) {
    for (float dz : offsets) {
      const glm::vec3 eye(0, 0, z_surface + dz);
      const bool inside = cameraInside(compiled.scene, limits, eye, time);
      (inside ? inside_count : outside_count)++;
      const float want = depth(lens_renderer, eye, time, false);
      const float got = depth(pinhole_renderer, eye, time, inside);
      EXPECT_EQ(got, want) << "z " << eye.z << " time " << time << " inside " << inside;
      // At time 0.5 the sphere is centred at z = 1: every camera here is inside it.
      if (time == 0.5f) {
        EXPECT_TRUE(inside) << eye.z;
      }
    }
  }
  // The flag matters: deep inside, the pinhole kernel sees the sphere's inside only with it.
  EXPECT_NE(depth(pinhole_renderer, {0, 0, 0.5f}, 0, true),
            depth(pinhole_renderer, {0, 0, 0.5f}, 0, false));
  EXPECT_GT(inside_count, 0);
  EXPECT_GT(outside_count, 0);
  EXPECT_FALSE(cameraInside(compiled.scene, limits, glm::vec3(0, 0, 1), 0));
  EXPECT_TRUE(cameraInside(compiled.scene, limits, glm::vec3(0, 0, 0.5f), 0));
}

}  // namespace
}  // namespace sdfc
