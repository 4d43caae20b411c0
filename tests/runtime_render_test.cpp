// Headless rendering on the real Vulkan device (lavapipe in CI) with small
// hand-written fragment shaders that output known functions of the pixel,
// the sample index and the push constants.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include "camera.h"
#include "renderer.h"
#include "spirv/glsl_to_spirv.h"
#include "vk_check.h"
#include "vulkan_context.h"

namespace sdfc {
namespace {

std::string shaderInterfaceText() {
  std::ifstream file(std::string(SDFC_SOURCE_DIR) + "/runtime/shader_interface.h");
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

// Pass output: rgb = (x, y, mean sample index), a = mean of a hash of
// (pixel, sample, seed); attachment 1 and 2 echo push constants.
std::string testShader(const std::string& extra_body = "") {
  return "#version 450\n" + shaderInterfaceText() + R"(
layout(push_constant) uniform Push { FrameParams frame; };
layout(location = 0) out vec4 out_color;
layout(location = 1) out vec4 out_normal_depth;
layout(location = 2) out vec4 out_albedo_steps;
uint hash(uint v) {  // a small integer hash; any mixing function works here
  v ^= v >> 16; v *= 0x7feb352du; v ^= v >> 15; v *= 0x846ca68bu; v ^= v >> 16;
  return v;
}
void main() {
  uvec2 pixel = uvec2(gl_FragCoord.xy);
  float sum_index = 0.0, sum_hash = 0.0;
  for (uint i = 0u; i < frame.sample_count; ++i) {
    uint s = frame.sample_base + i;
    sum_index += float(s);
    uint h = hash(pixel.x + 4096u * pixel.y + 0x9e3779b9u * s + hash(frame.seed));
    sum_hash += float(h >> 8) / 16777216.0;
  }
  float n = float(frame.sample_count);
  out_color = vec4(float(pixel.x), float(pixel.y), sum_index / n, sum_hash / n);
  out_normal_depth = vec4(float(pixel.x) * 0.5, float(pixel.y) * 0.25, float(frame.view),
                          float(frame.seed));
  out_albedo_steps = vec4(float(frame.width), float(frame.height), float(frame.max_bounces),
                          float(frame.light_samples));
)" + extra_body + "}\n";
}

std::vector<uint32_t> compileFragment(const std::string& source) {
  SpirvResult result = glslToSpirv(source, ShaderStage::Fragment, "runtime_test.frag");
  EXPECT_TRUE(result.ok()) << result.log;
  return result.words;
}

class RuntimeRender : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    createContext(context_);
    renderer_ = new Renderer(context_, compileFragment(testShader()));
  }
  static void TearDownTestSuite() {
    delete renderer_;
    renderer_ = nullptr;
    destroyContext(context_);
    EXPECT_EQ(validationMessageCount(), 0);
  }
  void TearDown() override { EXPECT_EQ(validationMessageCount(), 0); }

  static RenderSettings smallSettings() {
    RenderSettings settings;
    settings.width = 37;  // odd sizes catch row-pitch mistakes
    settings.height = 23;
    return settings;
  }

  static VulkanContext context_;
  static Renderer* renderer_;
};
VulkanContext RuntimeRender::context_;
Renderer* RuntimeRender::renderer_ = nullptr;

TEST_F(RuntimeRender, ValidationIsOnUnderCtest) {
  if (!ContextOptions::validationRequestedByEnv()) GTEST_SKIP() << "SDFC_VALIDATION not set";
  EXPECT_TRUE(context_.validation_enabled);
}

TEST_F(RuntimeRender, ReadsBackAllThreeAttachments) {
  gpu::FrameParams params = makeFrameParams(CameraDesc{}, 37, 23, 0.0f);
  params.sample_base = 5;
  params.sample_count = 3;
  params.view = gpu::kViewDepth;
  params.seed = 77;
  params.max_bounces = 6;
  params.light_samples = 2;
  FloatImage color, normal_depth, albedo_steps;
  renderer_->renderPass(params, 30.0, color, normal_depth, albedo_steps);
  ASSERT_EQ(color.width, 37u);
  ASSERT_EQ(color.height, 23u);
  for (uint32_t y = 0; y < 23; ++y)
    for (uint32_t x = 0; x < 37; ++x) {
      const float* c = color.at(x, y);
      ASSERT_EQ(c[0], float(x));
      ASSERT_EQ(c[1], float(y));
      ASSERT_EQ(c[2], 6.0f);  // mean of 5, 6, 7
      ASSERT_GE(c[3], 0.0f);
      ASSERT_LT(c[3], 1.0f);
      const float* nd = normal_depth.at(x, y);
      ASSERT_EQ(nd[0], x * 0.5f);
      ASSERT_EQ(nd[1], y * 0.25f);
      ASSERT_EQ(nd[2], float(gpu::kViewDepth));
      ASSERT_EQ(nd[3], 77.0f);
      const float* as = albedo_steps.at(x, y);
      ASSERT_EQ(as[0], 37.0f);
      ASSERT_EQ(as[1], 23.0f);
      ASSERT_EQ(as[2], 6.0f);
      ASSERT_EQ(as[3], 2.0f);
    }
}

TEST_F(RuntimeRender, AccumulatesPassesToTheAnalyticMean) {
  RenderSettings settings = smallSettings();
  settings.spp = 10;
  settings.max_samples_per_pass = 3;  // passes of 3, 3, 3, 1
  int calls = 0;
  RenderOutput out = renderer_->render(CameraDesc{}, settings,
                                       [&](const ProgressInfo&) { ++calls; });
  EXPECT_EQ(out.samples_done, 10u);
  EXPECT_EQ(out.passes, 4u);
  EXPECT_EQ(calls, 4);
  EXPECT_FALSE(out.interrupted);
  double hash_mean = 0;
  for (uint32_t y = 0; y < settings.height; ++y)
    for (uint32_t x = 0; x < settings.width; ++x) {
      const float* c = out.color.at(x, y);
      ASSERT_EQ(c[0], float(x));
      ASSERT_EQ(c[1], float(y));
      ASSERT_NEAR(c[2], 4.5f, 1e-6f);  // mean of 0..9
      hash_mean += c[3];
    }
  // Uniform hash values: mean 1/2, standard error ~ 0.29 / sqrt(8510).
  hash_mean /= double(settings.width) * settings.height;
  EXPECT_NEAR(hash_mean, 0.5, 0.02);
}

TEST_F(RuntimeRender, SameSeedIsBitIdenticalOtherSeedDiffers) {
  RenderSettings settings = smallSettings();
  settings.spp = 8;
  settings.max_samples_per_pass = 3;
  settings.seed = 12;
  const RenderOutput a = renderer_->render(CameraDesc{}, settings);
  const RenderOutput b = renderer_->render(CameraDesc{}, settings);
  EXPECT_EQ(a.color.rgba, b.color.rgba);
  EXPECT_EQ(a.normal_depth.rgba, b.normal_depth.rgba);
  settings.seed = 13;
  const RenderOutput c = renderer_->render(CameraDesc{}, settings);
  EXPECT_NE(a.color.rgba, c.color.rgba);
}

TEST_F(RuntimeRender, SplitRendersMergeToTheFullRender) {
  RenderSettings settings = smallSettings();
  settings.spp = 16;
  settings.max_samples_per_pass = 8;
  settings.keep_sums = true;
  const RenderOutput full = renderer_->render(CameraDesc{}, settings);
  EXPECT_EQ(full.passes, 2u);

  settings.spp = 8;
  const RenderOutput first = renderer_->render(CameraDesc{}, settings);
  settings.first_sample = 8;
  const RenderOutput second = renderer_->render(CameraDesc{}, settings);
  const RenderOutput merged = mergeRenders(first, second);
  EXPECT_EQ(merged.samples_done, 16u);
  EXPECT_EQ(merged.color.rgba, full.color.rgba);  // exact, see mergeRenders

  // Any other split differs only by float rounding of the per-pass means.
  settings.spp = 16;
  settings.first_sample = 0;
  settings.max_samples_per_pass = 5;
  const RenderOutput uneven = renderer_->render(CameraDesc{}, settings);
  for (size_t i = 0; i < full.color.rgba.size(); ++i)
    ASSERT_NEAR(uneven.color.rgba[i], full.color.rgba[i],
                1e-6f * std::fmax(1.0f, std::fabs(full.color.rgba[i])));
}

TEST_F(RuntimeRender, InterruptStopsAfterTheCurrentPass) {
  RenderSettings settings = smallSettings();
  settings.spp = 12;
  settings.max_samples_per_pass = 2;
  std::atomic<bool> stop{false};
  bool saw_finished = false;
  RenderOutput out = renderer_->render(
      CameraDesc{}, settings,
      [&](const ProgressInfo& info) {
        if (info.samples_done >= 4) stop = true;
        saw_finished |= info.finished;
      },
      &stop);
  EXPECT_TRUE(out.interrupted);
  EXPECT_TRUE(saw_finished);
  EXPECT_EQ(out.samples_done, 4u);
  EXPECT_NEAR(out.color.at(3, 4)[2], 1.5f, 1e-6f);  // mean of 0..3: still a valid image
}

TEST_F(RuntimeRender, DebugViewsRenderOneSample) {
  RenderSettings settings = smallSettings();
  settings.spp = 64;
  settings.view = gpu::kViewNormal;
  RenderOutput out = renderer_->render(CameraDesc{}, settings);
  EXPECT_EQ(out.samples_done, 1u);
  EXPECT_EQ(out.passes, 1u);
  EXPECT_EQ(out.normal_depth.at(0, 0)[2], float(gpu::kViewNormal));
}

TEST(RuntimeSamplesPerPass, RespectsTheLoopBudget) {
  RenderSettings settings;
  settings.width = 64;
  settings.height = 64;
  settings.spp = 1000;
  settings.loop_iterations_per_sample = 10000;
  EXPECT_EQ(chooseSamplesPerPass(settings), 6u);  // 6 * 10000 < 65535 <= 7 * 10000
  settings.loop_iterations_per_pass = 5535;
  EXPECT_EQ(chooseSamplesPerPass(settings), 5u);  // 5535 + 6 * 10000 would hit the cap
  settings.loop_iterations_per_pass = 0;
  settings.loop_iterations_per_sample = 100000;
  EXPECT_EQ(chooseSamplesPerPass(settings), 1u);  // cannot do better than one sample
  settings.loop_iterations_per_sample = 0;
  EXPECT_EQ(chooseSamplesPerPass(settings), kAutoMaxSamplesPerPass);
  settings.max_samples_per_pass = 5;
  EXPECT_EQ(chooseSamplesPerPass(settings), 5u);
  settings.spp = 3;
  EXPECT_EQ(chooseSamplesPerPass(settings), 3u);
  settings.width = 1920;
  settings.height = 1080;
  settings.max_samples_per_pass = 0;
  settings.spp = 100;
  EXPECT_EQ(chooseSamplesPerPass(settings), 1u);  // 2 Mpixel > the auto budget
}

TEST(RuntimeFence, TimeoutIsAnErrorNotAHang) {
  VulkanContext context;
  createContext(context);
  {
    // ~4000 loop iterations per pixel: far longer than the 0-second timeout.
    const std::string heavy = testShader(R"(
  float acc = 0.0;
  for (int i = 0; i < 4000; ++i) acc = fract(acc * 1.37 + sin(float(i) + gl_FragCoord.x));
  out_color.a += acc * 1e-30;
)");
    Renderer renderer(context, compileFragment(heavy));
    RenderSettings settings;
    settings.width = 128;
    settings.height = 128;
    settings.spp = 1;
    settings.pass_timeout_seconds = 0.0;
    try {
      renderer.render(CameraDesc{}, settings);
      ADD_FAILURE() << "expected a timeout";
    } catch (const RuntimeError& error) {
      EXPECT_NE(std::string(error.what()).find("did not finish"), std::string::npos);
    }
    // The renderer stays usable: the next render waits for the stuck pass first.
    settings.pass_timeout_seconds = 60.0;  // same size: same target, still pending
    const RenderOutput out = renderer.render(CameraDesc{}, settings);
    EXPECT_EQ(out.samples_done, 1u);
  }  // destruction waits for the device, so no validation errors follow
  destroyContext(context);
  EXPECT_EQ(validationMessageCount(), 0);
}

TEST(RuntimeCamera, BasisIsOrthonormal) {
  CameraDesc camera;
  camera.position = {1, 2, 3};
  camera.target = {0, 0.5f, -1};
  camera.fov_degrees = 60;
  const gpu::FrameParams p = makeFrameParams(camera, 640, 360, 2.5f);
  const glm::vec3 r(p.cam_right), u(p.cam_up), f(p.cam_forward);
  EXPECT_NEAR(glm::length(r), 1, 1e-6);
  EXPECT_NEAR(glm::length(u), 1, 1e-6);
  EXPECT_NEAR(glm::length(f), 1, 1e-6);
  EXPECT_NEAR(glm::dot(r, u), 0, 1e-6);
  EXPECT_NEAR(glm::dot(r, f), 0, 1e-6);
  EXPECT_NEAR(glm::dot(u, f), 0, 1e-6);
  EXPECT_GT(u.y, 0);                                  // up stays up
  EXPECT_NEAR(p.cam_origin.w, std::tan(glm::radians(30.0f)), 1e-6);
  EXPECT_NEAR(p.cam_up.w, glm::length(camera.target - camera.position), 1e-5);  // focus
  EXPECT_EQ(p.cam_forward.w, 2.5f);
  camera.position = {0, 5, 0};
  camera.target = {0, 0, 0};  // looking straight down along -up
  const gpu::FrameParams q = makeFrameParams(camera, 8, 8, 0);
  EXPECT_NEAR(glm::length(glm::vec3(q.cam_right)), 1, 1e-6);
  EXPECT_FALSE(std::isnan(q.cam_up.x));
}

TEST(RuntimeVkCheck, ThrowsWithResultName) {
  try {
    VK_CHECK(VK_ERROR_DEVICE_LOST);
    FAIL();
  } catch (const RuntimeError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("VK_ERROR_DEVICE_LOST"), std::string::npos) << message;
    EXPECT_NE(message.find("runtime_render_test.cpp:"), std::string::npos) << message;
  }
}

}  // namespace
}  // namespace sdfc
