// The path-tracing kernel on the real device (lavapipe): furnace tests with
// analytic answers, NEE/MIS against pure BSDF sampling, pass-split invariance,
// the AOV views, and the loop-iteration bound (runtime/loop_budget.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "camera.h"
#include "kernel_harness.h"
#include "renderer.h"
#include "runtime/loop_budget.h"
#include "vulkan_context.h"

namespace sdfc {
namespace {

struct Images {
  FloatImage color, normal_depth, albedo_steps;
};

class KernelRender : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { createContext(context_); }
  static void TearDownTestSuite() {
    destroyContext(context_);
    EXPECT_EQ(validationMessageCount(), 0);
  }
  void TearDown() override { EXPECT_EQ(validationMessageCount(), 0); }

  static std::unique_ptr<Renderer> makeRenderer(const std::string& scene,
                                                const std::vector<std::string>& defines) {
    SpirvResult spirv = test::compileKernel(test::kernelScene(scene), defines, scene);
    EXPECT_TRUE(spirv.ok()) << spirv.log;
    if (!spirv.ok()) return nullptr;
    auto renderer = std::make_unique<Renderer>(context_, spirv.words);
    std::printf("[ kernel   ] %s: %zu SPIR-V bytes, pipeline %.2f s\n", scene.c_str(),
                spirv.words.size() * 4, renderer->pipelineSeconds());
    return renderer;
  }

  static gpu::FrameParams params(uint32_t size, glm::vec3 eye, float fov = 40.0f) {
    CameraDesc camera;
    camera.position = eye;
    camera.target = {0, 0, 0};
    camera.fov_degrees = fov;
    gpu::FrameParams p = makeFrameParams(camera, size, size, 0.0f);
    p.sample_base = 0;
    p.sample_count = 1;
    p.seed = 1;
    p.view = gpu::kViewBeauty;
    p.max_bounces = 4;
    p.light_samples = 0;
    return p;
  }

  static Images render(Renderer& renderer, const gpu::FrameParams& p) {
    Images out;
    renderer.renderPass(p, 120.0, out.color, out.normal_depth, out.albedo_steps);
    return out;
  }

  // `total` samples in passes that stay under the loop cap; colour is their mean.
  static Images renderSamples(Renderer& renderer, gpu::FrameParams p, uint32_t total,
                              uint32_t max_steps, uint32_t sphere_lights) {
    const uint32_t per_pass =
        samplesPerPassWithinCap(max_steps, p.max_bounces, p.light_samples, sphere_lights);
    EXPECT_GT(per_pass, 0u);
    Images sum;
    std::vector<double> acc;
    for (uint32_t done = 0; done < total;) {
      p.sample_base = done;
      p.sample_count = std::min(per_pass, total - done);
      Images pass = render(renderer, p);
      if (acc.empty()) acc.assign(pass.color.rgba.size(), 0.0);
      for (size_t i = 0; i < acc.size(); ++i) acc[i] += double(pass.color.rgba[i]) * p.sample_count;
      done += p.sample_count;
      sum = std::move(pass);
    }
    for (size_t i = 0; i < acc.size(); ++i) sum.color.rgba[i] = float(acc[i] / total);
    return sum;
  }

  static VulkanContext context_;
};
VulkanContext KernelRender::context_;

// Pixels whose whole footprint sees the object: the AOV ray and its 8 neighbours hit.
std::vector<std::pair<uint32_t, uint32_t>> interiorPixels(const Images& im) {
  std::vector<std::pair<uint32_t, uint32_t>> out;
  for (uint32_t y = 1; y + 1 < im.color.height; ++y)
    for (uint32_t x = 1; x + 1 < im.color.width; ++x) {
      bool all = true;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) all = all && im.normal_depth.at(x + dx, y + dy)[3] > 0;
      if (all) out.push_back({x, y});
    }
  return out;
}

constexpr uint32_t kSize = 48;
const glm::vec3 kEye{0, 0, 3.5f};

// Diffuse albedo 0.8 in a white sky: a convex object is left after one bounce, so
// every sample of an interior pixel is exactly 0.8 (and 0 with no bounce at all).
TEST_F(KernelRender, DiffuseWhiteFurnace) {
  for (const char* sampler : {"SDFC_HAS_DIFFUSE", "SDFC_SAMPLER_SOBOL"}) {
    std::vector<std::string> defines = {"SDFC_HAS_DIFFUSE"};
    if (std::string(sampler) == "SDFC_SAMPLER_SOBOL") defines.push_back(sampler);
    auto renderer = makeRenderer("sphere_white_sky.glsl", defines);
    ASSERT_TRUE(renderer);
    for (uint32_t bounces : {0u, 1u, 4u}) {
      gpu::FrameParams p = params(kSize, kEye);
      p.max_bounces = bounces;
      p.sample_count = 16;
      Images im = render(*renderer, p);
      const auto interior = interiorPixels(im);
      ASSERT_GT(interior.size(), kSize * kSize / 8);
      const float expected = bounces == 0 ? 0.0f : 0.8f;
      for (auto [x, y] : interior)
        for (int c = 0; c < 3; ++c)
          ASSERT_NEAR(im.color.at(x, y)[c], expected, 1e-4) << x << "," << y << " B=" << bounces;
      EXPECT_NEAR(im.color.at(0, 0)[0], 1.0f, 1e-6);  // sky
    }
  }
}

// Inside a closed sphere that emits e and reflects a (diffuse): with B bounces the
// radiance is e * sum_{k=0..B} a^k. Russian roulette must not bias it.
TEST_F(KernelRender, HollowSphereGeometricSeries) {
  auto renderer = makeRenderer("hollow_sphere.glsl", {"SDFC_HAS_DIFFUSE"});
  ASSERT_TRUE(renderer);
  for (uint32_t bounces : {0u, 1u, 3u, 8u}) {
    gpu::FrameParams p = params(kSize, {0, 0, 0.01f}, 90.0f);
    p.max_bounces = bounces;
    p.sample_count = 16;
    Images im = render(*renderer, p);
    double expected = 0, term = 0.25;
    for (uint32_t k = 0; k <= bounces; ++k, term *= 0.8) expected += term;
    // Every pixel sees the same statistics: the pixel means are i.i.d.
    double sum = 0, sum2 = 0;
    const double n = kSize * kSize;
    for (uint32_t y = 0; y < kSize; ++y)
      for (uint32_t x = 0; x < kSize; ++x) {
        const double v = im.color.at(x, y)[1];
        sum += v;
        sum2 += v * v;
      }
    const double mean = sum / n;
    const double standard_error = std::sqrt(std::max(0.0, sum2 / n - mean * mean) / n);
    std::printf("[ furnace  ] hollow sphere B=%u: mean %.5f expected %.5f (se %.5f)\n", bounces,
                mean, expected, standard_error);
    EXPECT_NEAR(mean, expected, 5 * standard_error + 1e-5) << "B=" << bounces;
  }
}

// Mirror and glass with white tint conserve energy: radiance 1 in a white sky.
TEST_F(KernelRender, MirrorAndGlassWhiteFurnace) {
  struct Case { const char* feature; const char* material; uint32_t bounces; double tol; };
  for (const Case& c : {Case{"SDFC_HAS_MIRROR", "Material(MAT_MIRROR,vec3(1),vec3(0),1.0,0.0)", 2, 1e-4},
                        Case{"SDFC_HAS_GLASS", "Material(MAT_GLASS,vec3(1),vec3(0),1.5,0.0)", 16, 2e-3}}) {
    auto renderer = makeRenderer("sphere_white_sky.glsl",
                                 {c.feature, std::string("TEST_MATERIAL ") + c.material});
    ASSERT_TRUE(renderer);
    gpu::FrameParams p = params(kSize, kEye);
    p.max_bounces = c.bounces;
    p.sample_count = 16;
    Images im = render(*renderer, p);
    const auto interior = interiorPixels(im);
    ASSERT_GT(interior.size(), kSize * kSize / 8);
    double sum = 0;
    float max_value = 0;
    for (auto [x, y] : interior) {
      sum += im.color.at(x, y)[0];
      for (int ch = 0; ch < 3; ++ch) max_value = std::max(max_value, im.color.at(x, y)[ch]);
    }
    const double mean = sum / interior.size();
    std::printf("[ furnace  ] %s: mean %.6f over %zu pixels, max %.6f\n", c.feature, mean,
                interior.size(), max_value);
    EXPECT_NEAR(mean, 1.0, c.tol) << c.feature;
    EXPECT_LE(max_value, 1.0f + 1e-4f) << c.feature;  // never creates energy
  }
}

// Directional albedo of GGX with F = 1 (the energy single scattering keeps), by
// quadrature over the outgoing hemisphere: integral of D G2 / (4 cos_o) dw_i,
// with height-correlated Smith G2 (Heitz 2014). Independent of the shader code.
double ggxAlbedo(double cos_o, double alpha, bool masking = true) {
  const double pi = 3.14159265358979323846;
  auto lambda = [&](double c) {
    const double t2 = (1 - c * c) / (c * c);
    return 0.5 * (std::sqrt(1 + alpha * alpha * t2) - 1);
  };
  const double sin_o = std::sqrt(std::max(0.0, 1 - cos_o * cos_o));
  const int n_theta = 400, n_phi = 400;
  double sum = 0;
  for (int i = 0; i < n_theta; ++i) {
    const double theta = (i + 0.5) * (pi / 2) / n_theta;
    const double ci = std::cos(theta), si = std::sin(theta);
    for (int j = 0; j < n_phi; ++j) {
      const double phi = (j + 0.5) * 2 * pi / n_phi;
      // wo = (sin_o, 0, cos_o), wi = (si cos phi, si sin phi, ci)
      double hx = sin_o + si * std::cos(phi), hy = si * std::sin(phi), hz = cos_o + ci;
      const double hl = std::sqrt(hx * hx + hy * hy + hz * hz);
      hz /= hl;
      const double a2 = alpha * alpha;
      const double d = a2 / (pi * std::pow(hz * hz * (a2 - 1) + 1, 2));
      const double g2 = masking ? 1 / (1 + lambda(cos_o) + lambda(ci)) : 1.0;
      sum += d * g2 / (4 * cos_o) * si;
    }
  }
  return sum * (pi / 2 / n_theta) * (2 * pi / n_phi);
}

// GGX metal with F0 = 1 keeps exactly its directional albedo (energy lost to
// single-scattering masking), and no sample exceeds 1 (F G2 / G1 <= 1).
TEST_F(KernelRender, MetalWhiteFurnace) {
  const double alpha = 0.2;
  auto renderer = makeRenderer("sphere_white_sky.glsl",
                               {"SDFC_HAS_METAL", "TEST_MATERIAL Material(MAT_METAL,vec3(1),vec3(0),1.0,0.2)"});
  ASSERT_TRUE(renderer);
  // The quadrature itself: head-on and without masking, the reflected directions
  // above the horizon are the normals within 45 degrees, 1 / (1 + alpha^2) of
  // the projected GGX mass (its CDF in tan^2 is t / (alpha^2 + t)).
  EXPECT_NEAR(ggxAlbedo(1.0, alpha, false), 1.0 / (1.0 + alpha * alpha), 1e-3);
  gpu::FrameParams p = params(kSize, kEye);
  p.max_bounces = 2;
  p.sample_count = 32;
  Images im = render(*renderer, p);
  const auto interior = interiorPixels(im);
  // The expected value per pixel from its AOV normal; the unit sphere is at the
  // origin, so the hit point is the normal. Tabulate the albedo over cos_o.
  std::vector<double> table(65);
  for (size_t i = 0; i < table.size(); ++i) table[i] = ggxAlbedo(std::max(0.02, i / 64.0), alpha);
  double sum = 0, expected = 0, diff2 = 0;
  float max_value = 0;
  for (auto [x, y] : interior) {
    const glm::vec3 n(im.normal_depth.at(x, y)[0], im.normal_depth.at(x, y)[1],
                      im.normal_depth.at(x, y)[2]);
    const double cos_o = std::clamp(double(glm::dot(n, glm::normalize(kEye - n))), 0.0, 1.0);
    const double f = cos_o * 64, w = f - std::floor(f);
    const size_t i = std::min<size_t>(size_t(f), 63);
    const double e = table[i] * (1 - w) + table[i + 1] * w;
    const double v = im.color.at(x, y)[0];
    sum += v;
    expected += e;
    diff2 += (v - e) * (v - e);
    max_value = std::max(max_value, im.color.at(x, y)[0]);
  }
  const double n = interior.size();
  const double se = std::sqrt(diff2) / n;
  std::printf("[ furnace  ] metal alpha %.1f: mean %.5f, expected %.5f (se %.5f), max %.5f\n", alpha,
              sum / n, expected / n, se, max_value);
  // Jittered samples against the centre-ray normal: allow a little geometry error.
  EXPECT_NEAR(sum / n, expected / n, 5 * se + 2e-3);
  EXPECT_LE(max_value, 1.0f + 1e-4f);
}

// Next-event estimation with MIS must converge to the same image as pure BSDF
// sampling (light_samples = 0 finds lights only by hitting them).
TEST_F(KernelRender, NextEventEstimationMatchesBsdfSampling) {
  const uint32_t kMisSize = 48, kBsdfSpp = 256;  // se ~0.2%: finds biases >1%
  for (const char* metal : {"Material(MAT_DIFFUSE,vec3(0.5,0.6,0.7),vec3(0),1.0,0.0)",
                            "Material(MAT_METAL,vec3(0.9,0.7,0.5),vec3(0),1.0,0.3)"}) {
    auto renderer = makeRenderer("lights.glsl",
                                 {"SDFC_HAS_DIFFUSE", "SDFC_HAS_METAL", "SDFC_HAS_SUN",
                                  "SDFC_HAS_SPHERE_LIGHTS", std::string("TEST_MATERIAL_B ") + metal});
    ASSERT_TRUE(renderer);
    for (uint32_t bounces : {1u, 3u}) {
      std::vector<double> means;
      std::vector<Images> images;
      for (uint32_t light_samples : {0u, 1u, 2u}) {
        gpu::FrameParams p = params(kMisSize, {0, 1.5f, 5.0f}, 50.0f);
        p.max_bounces = bounces;
        p.light_samples = light_samples;
        p.seed = 11 + light_samples;
        images.push_back(renderSamples(*renderer, p, light_samples == 0 ? kBsdfSpp : kBsdfSpp / 4,
                                       96, 2));
      }
      // Pixels are independent, so the variance of the image-mean difference is the
      // sum of the per-pixel squared differences over n^2 (a conservative estimate).
      for (int k : {1, 2}) {
        double diff = 0, diff2 = 0;
        const double n = kMisSize * kMisSize * 3;
        for (size_t i = 0; i < images[0].color.rgba.size(); ++i) {
          if (i % 4 == 3) continue;
          const double d = double(images[k].color.rgba[i]) - images[0].color.rgba[i];
          diff += d;
          diff2 += d * d;
        }
        double base = 0;
        for (size_t i = 0; i < images[0].color.rgba.size(); ++i)
          if (i % 4 != 3) base += images[0].color.rgba[i];
        const double se = std::sqrt(diff2) / n;
        std::printf("[ mis      ] B=%u L=%d: mean %.4f, NEE - BSDF = %.5f (se %.5f)\n", bounces, k,
                    base / n, diff / n, se);
        EXPECT_LT(std::abs(diff / n), 4.5 * se) << metal << " B=" << bounces << " L=" << k;
      }
    }
  }
}

// Splitting samples into passes gives the same image: samples depend only on
// (pixel, sample index, seed).
TEST_F(KernelRender, PassSplitGivesTheSameImage) {
  for (bool sobol : {false, true}) {
    std::vector<std::string> defines = {"SDFC_HAS_DIFFUSE", "SDFC_HAS_METAL", "SDFC_HAS_SUN",
                                        "SDFC_HAS_SPHERE_LIGHTS", "SDFC_HAS_APERTURE"};
    if (sobol) defines.push_back("SDFC_SAMPLER_SOBOL");
    auto renderer = makeRenderer("lights.glsl", defines);
    ASSERT_TRUE(renderer);
    gpu::FrameParams p = params(24, {0, 1.5f, 5.0f}, 50.0f);
    p.cam_right.w = 0.1f;  // aperture
    p.cam_up.w = 5.0f;     // focus distance
    p.light_samples = 1;
    p.sample_count = 8;
    Images whole = render(*renderer, p);
    p.sample_count = 3;
    Images first = render(*renderer, p);
    p.sample_base = 3;
    p.sample_count = 5;
    Images second = render(*renderer, p);
    for (size_t i = 0; i < whole.color.rgba.size(); ++i) {
      const double merged = (3.0 * first.color.rgba[i] + 5.0 * second.color.rgba[i]) / 8.0;
      ASSERT_NEAR(merged, whole.color.rgba[i], 1e-5 * (1.0 + std::abs(merged))) << i;
      // The AOVs come from an unjittered ray: identical in every pass.
      ASSERT_EQ(first.normal_depth.rgba[i], second.normal_depth.rgba[i]) << i;
      ASSERT_EQ(first.albedo_steps.rgba[i], second.albedo_steps.rgba[i]) << i;
    }
  }
}

TEST_F(KernelRender, DebugViewsAndAovs) {
  auto renderer = makeRenderer("sphere_white_sky.glsl", {"SDFC_HAS_DIFFUSE"});
  ASSERT_TRUE(renderer);
  const uint32_t size = 33;  // odd: the centre pixel looks straight at the sphere
  gpu::FrameParams p = params(size, kEye);
  p.view = gpu::kViewNormal;
  Images im = render(*renderer, p);
  const uint32_t c = size / 2;
  EXPECT_NEAR(im.normal_depth.at(c, c)[2], 1.0f, 1e-3);
  EXPECT_NEAR(im.normal_depth.at(c, c)[3], 2.5f, 1e-3);  // eye at z = 3.5, radius 1
  EXPECT_NEAR(im.color.at(c, c)[2], 1.0f, 1e-3);         // n * 0.5 + 0.5
  EXPECT_NEAR(im.albedo_steps.at(c, c)[0], 0.8f, 1e-6);
  EXPECT_GT(im.albedo_steps.at(c, c)[3], 1.0f);
  // Image rows go top to bottom: above the centre the normal points up.
  EXPECT_GT(im.normal_depth.at(c, c - 4)[1], 0.2f);
  EXPECT_LT(im.normal_depth.at(c, c + 4)[1], -0.2f);
  EXPECT_GT(im.normal_depth.at(c + 4, c)[0], 0.2f);  // right is +x
  EXPECT_EQ(im.normal_depth.at(0, 0)[3], -1.0f);     // miss
  p.view = gpu::kViewDepth;
  im = render(*renderer, p);
  EXPECT_NEAR(im.color.at(c, c)[0], 2.5f, 1e-3);
  p.view = gpu::kViewAlbedo;
  im = render(*renderer, p);
  EXPECT_NEAR(im.color.at(c, c)[1], 0.8f, 1e-6);
  p.view = gpu::kViewSteps;
  im = render(*renderer, p);
  EXPECT_GE(im.color.at(c, c)[0], 1.0f);  // the raw step count, as attachment 2's w
  EXPECT_EQ(im.color.at(c, c)[0], im.albedo_steps.at(c, c)[3]);
  // With no samples, the iteration count is exact: s loop 1 + bounce 1 + primary
  // march steps + (on a hit) the refinement steps and the normal's loop (4 taps
  // and the material).
  p.view = gpu::kViewIterations;
  p.sample_count = 0;
  im = render(*renderer, p);
  for (uint32_t y = 0; y < size; ++y)
    for (uint32_t x = 0; x < size; ++x) {
      const float steps = im.albedo_steps.at(x, y)[3];
      const float hit = im.normal_depth.at(x, y)[3] > 0 ? float(kNormalLoopIterations + kRefineSteps) : 0.0f;
      ASSERT_EQ(im.color.at(x, y)[0], 2.0f + steps + hit) << x << "," << y;
    }
}

// No pixel may reach lavapipe's loop cap, and the counted iterations stay within
// the proven per-pass bound, for the biggest pass the budget allows.
TEST_F(KernelRender, LoopIterationsStayWithinTheBudget) {
  const std::vector<std::string> all = {
      "SDFC_HAS_DIFFUSE", "SDFC_HAS_MIRROR", "SDFC_HAS_GLASS", "SDFC_HAS_METAL",
      "SDFC_HAS_EMISSIVE", "SDFC_HAS_SUN", "SDFC_HAS_SPHERE_LIGHTS", "SDFC_USES_TIME",
      "SDFC_HAS_APERTURE"};
  auto renderer = makeRenderer("mixed.glsl", all);
  ASSERT_TRUE(renderer);
  const uint32_t steps = 128, bounces = 5, lights = 2, spheres = 1;
  const uint32_t count = samplesPerPassWithinCap(steps, bounces, lights, spheres);
  ASSERT_GT(count, 0u);
  const uint64_t bound = loopIterationsPerPass(steps, bounces, lights, count, spheres);
  gpu::FrameParams p = params(32, {0, 2.0f, 6.0f}, 60.0f);
  p.view = gpu::kViewIterations;
  p.max_bounces = bounces;
  p.light_samples = lights;
  p.sample_count = count;
  p.cam_right.w = 0.05f;
  p.cam_up.w = 6.0f;
  const auto start = std::chrono::steady_clock::now();
  Images im = render(*renderer, p);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  float max_iterations = 0;
  double sum = 0;
  for (uint32_t y = 0; y < 32; ++y)
    for (uint32_t x = 0; x < 32; ++x) {
      max_iterations = std::max(max_iterations, im.color.at(x, y)[0]);
      sum += im.color.at(x, y)[0];
    }
  std::printf("[ loops    ] %u samples/pass: max %.0f, mean %.0f iterations; bound %llu; %.2f s\n",
              count, max_iterations, sum / (32 * 32), (unsigned long long)bound, seconds);
  EXPECT_LT(max_iterations, float(gpu::kLavapipeLoopCap));
  EXPECT_LE(max_iterations, float(bound));
  EXPECT_GT(max_iterations, 0.0f);
}

}  // namespace
}  // namespace sdfc
