// The prelude's random numbers and sampling routines, run on the device (lavapipe)
// through a tiny shader (one sample per pixel), checked on the CPU: chi-square
// tests against each routine's density, computed independently in C++, and the
// stratification of the Owen-scrambled Sobol sampler.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "camera.h"
#include "kernel_harness.h"
#include "renderer.h"
#include "vulkan_context.h"

namespace sdfc {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr uint32_t kSide = 256;  // 65,536 samples per draw

// Modes (frame.view): 0 hash pair, 1 Sobol pair, 2 cosine hemisphere about axis,
// 3 uniform cone about axis, 4 GGX VNDF normal for wo = axis (local frame),
// 5 concentric disc. axis = frame.cam_right.xyz; parameters in frame.cam_origin;
// frame.light_samples selects the dimension pair; sample index = pixel index.
const char* kSamplerMain = R"(
void main() {
  uvec2 pixel = uvec2(gl_FragCoord.xy);
  beginSample(uvec2(7u, 11u) + uvec2(frame.max_bounces), pixel.x + pixel.y * frame.width);
  vec3 axis = normalize(frame.cam_right.xyz);
  uint pair = frame.light_samples;
  vec3 v = vec3(0.0);
  if (frame.view == 0u) v = vec3(hashRand2(pair), 0.0);
  if (frame.view == 1u) v = vec3(sobolRand2(pair), 0.0);
  if (frame.view == 2u) v = toWorld(sampleCosineHemisphere(hashRand2(pair)), axis);
  if (frame.view == 3u) v = toWorld(sampleUniformCone(hashRand2(pair), frame.cam_origin.x), axis);
  if (frame.view == 4u) v = sampleGgxVndf(axis, frame.cam_origin.y, hashRand2(pair));
  if (frame.view == 5u) v = vec3(concentricDisk(hashRand2(pair)), 0.0);
  out_color = vec4(v, 1.0);
  out_normal_depth = vec4(0.0);
  out_albedo_steps = vec4(0.0);
}
)";

class KernelSampling : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    createContext(context_);
    std::string source = "#version 450\n";
    for (const char* d : {"SDFC_TRACE", "SDFC_HAS_DIFFUSE", "SDFC_HAS_METAL", "SDFC_HAS_SUN", "SDFC_HAS_APERTURE",
                          "SDFC_SAMPLER_SOBOL"})
      source += std::string("#define ") + d + "\n";
    source += test::readSourceFile("runtime/shader_interface.h");
    source += test::readSourceFile("compiler/emit/kernel/prelude.glsl");
    source += kSamplerMain;
    SpirvResult spirv = glslToSpirv(source, ShaderStage::Fragment, "sampler_test.frag");
    ASSERT_TRUE(spirv.ok()) << spirv.log;
    renderer_ = new Renderer(context_, spirv.words);
  }
  static void TearDownTestSuite() {
    delete renderer_;
    renderer_ = nullptr;
    destroyContext(context_);
    EXPECT_EQ(validationMessageCount(), 0);
  }
  void TearDown() override { EXPECT_EQ(validationMessageCount(), 0); }

  struct Draw {
    uint32_t mode = 0, pair = 0, seed = 1, pixel_offset = 0;
    glm::vec3 axis{0, 0, 1};
    glm::vec4 param{0.0f};
  };

  static std::vector<glm::vec3> samples(const Draw& d, uint32_t side = kSide) {
    gpu::FrameParams p = makeFrameParams(CameraDesc{}, side, side, 0.0f);
    p.view = d.mode;
    p.light_samples = d.pair;
    p.seed = d.seed;
    p.max_bounces = d.pixel_offset;
    p.sample_base = 0;
    p.sample_count = 1;
    p.cam_right = glm::vec4(d.axis, 0.0f);
    p.cam_origin = d.param;
    FloatImage color, nd, as;
    renderer_->renderPass(p, 60.0, color, nd, as);
    std::vector<glm::vec3> out(size_t(side) * side);
    for (size_t i = 0; i < out.size(); ++i)
      out[i] = {color.rgba[i * 4], color.rgba[i * 4 + 1], color.rgba[i * 4 + 2]};
    return out;
  }

  static VulkanContext context_;
  static Renderer* renderer_;
};
VulkanContext KernelSampling::context_;
Renderer* KernelSampling::renderer_ = nullptr;

// Upper quantile of the chi-square distribution at significance 1e-4, by the
// Wilson-Hilferty cube-root normal approximation (z = 3.719).
double chiSquareCritical(int dof) {
  const double k = dof, z = 3.719;
  const double a = 1.0 - 2.0 / (9.0 * k) + z * std::sqrt(2.0 / (9.0 * k));
  return k * a * a * a;
}

// Pearson's test; bins expected to hold < 5 samples are pooled into one.
void expectChiSquare(const std::vector<double>& observed, const std::vector<double>& expected,
                     const std::string& what) {
  double stat = 0, pooled_o = 0, pooled_e = 0, total_e = 0, total_o = 0;
  int bins = 0;
  for (size_t i = 0; i < observed.size(); ++i) {
    total_e += expected[i];
    total_o += observed[i];
    if (expected[i] < 5) {
      pooled_o += observed[i];
      pooled_e += expected[i];
      continue;
    }
    stat += (observed[i] - expected[i]) * (observed[i] - expected[i]) / expected[i];
    ++bins;
  }
  if (pooled_e > 0) {
    stat += (pooled_o - pooled_e) * (pooled_o - pooled_e) / std::max(pooled_e, 1e-9);
    ++bins;
  }
  const double critical = chiSquareCritical(bins - 1);
  std::printf("[ chi2     ] %s: %.1f with %d dof (critical %.1f at 1e-4)\n", what.c_str(), stat,
              bins - 1, critical);
  EXPECT_NEAR(total_o, total_e, 1e-4 * total_e + 0.5) << what << ": mass (quadrature)";
  EXPECT_LT(stat, critical) << what;
}

// Spherical coordinates of v about axis in a C++-built frame (not the shader's).
void polarAbout(glm::dvec3 v, glm::dvec3 axis, double& cos_theta, double& phi) {
  const glm::dvec3 helper = std::abs(axis.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
  const glm::dvec3 t1 = glm::normalize(glm::cross(helper, axis));
  const glm::dvec3 t2 = glm::cross(axis, t1);
  cos_theta = glm::dot(v, axis);
  phi = std::atan2(glm::dot(v, t2), glm::dot(v, t1));
  if (phi < 0) phi += 2 * kPi;
}

TEST_F(KernelSampling, HashPairsAreUniform) {
  for (uint32_t pair : {0u, 5u, 9u}) {
    const auto s = samples({0, pair, 3});
    const int n = 32;
    std::vector<double> observed(n * n, 0.0), expected(n * n, double(s.size()) / (n * n));
    for (const auto& v : s) {
      ASSERT_GE(v.x, 0.0f);
      ASSERT_LT(v.x, 1.0f);
      ASSERT_GE(v.y, 0.0f);
      ASSERT_LT(v.y, 1.0f);
      observed[int(v.x * n) * n + int(v.y * n)] += 1;
    }
    expectChiSquare(observed, expected, "hash pair " + std::to_string(pair));
  }
  // Different seeds give different numbers.
  EXPECT_NE(samples({0, 0, 3})[17].x, samples({0, 0, 4})[17].x);
}

// The first 2^m samples of each Owen-scrambled Sobol pair form a (0,m,2)-net:
// every elementary box of area 2^-m holds exactly one point.
TEST_F(KernelSampling, SobolPairsAreStratified) {
  const int m = 12;
  for (uint32_t pair : {0u, 1u, 3u})
    for (uint32_t seed : {1u, 2u}) {
      const auto s = samples({1, pair, seed, 17 * pair}, 64);  // indices 0 .. 4095
      for (int a = 0; a <= m; ++a) {
        const int nx = 1 << a, ny = 1 << (m - a);
        std::vector<int> cells(size_t(nx) * ny, 0);
        for (const auto& v : s) {
          ASSERT_GE(v.x, 0.0f);
          ASSERT_LT(v.x, 1.0f);
          ASSERT_GE(v.y, 0.0f);
          ASSERT_LT(v.y, 1.0f);
          cells[size_t(int(v.x * nx)) * ny + int(v.y * ny)] += 1;
        }
        const int worst = *std::max_element(cells.begin(), cells.end());
        ASSERT_EQ(worst, 1) << "pair " << pair << " seed " << seed << " boxes " << nx << "x" << ny;
      }
    }
  // Scrambling differs between pixels and pairs.
  EXPECT_NE(samples({1, 0, 1, 0}, 64)[5].x, samples({1, 0, 1, 1}, 64)[5].x);
  EXPECT_NE(samples({1, 0, 1, 0}, 64)[5].x, samples({1, 1, 1, 0}, 64)[5].x);
}

// Cosine hemisphere: density cos(theta) / pi; bins in (cos theta, phi) get
// N (mu1^2 - mu0^2) / 2 * dphi / pi.
TEST_F(KernelSampling, CosineHemisphereMatchesItsDensity) {
  for (glm::vec3 axis : {glm::vec3(0, 0, 1), glm::vec3(0.3f, -0.8f, 0.52f), glm::vec3(0, 0, -1)}) {
    const glm::dvec3 a = glm::normalize(glm::dvec3(axis));
    const auto s = samples({2, 0, 5, 0, axis});
    const int nm = 16, np = 16;
    std::vector<double> observed(nm * np, 0.0), expected(nm * np, 0.0);
    for (int i = 0; i < nm; ++i)
      for (int j = 0; j < np; ++j) {
        const double m0 = double(i) / nm, m1 = double(i + 1) / nm;
        expected[i * np + j] = s.size() * (m1 * m1 - m0 * m0) / 2 * (2 * kPi / np) / kPi;
      }
    for (const auto& v : s) {
      ASSERT_NEAR(glm::length(v), 1.0f, 1e-4);
      double mu, phi;
      polarAbout(glm::dvec3(v), a, mu, phi);
      ASSERT_GE(mu, -1e-6);
      observed[std::clamp(int(mu * nm), 0, nm - 1) * np + std::min(int(phi / (2 * kPi) * np), np - 1)] += 1;
    }
    expectChiSquare(observed, expected, "cosine hemisphere");
  }
}

// Uniform cone of 1 - cos(theta_max) = c: uniform in (cos theta, phi) on [1 - c, 1].
TEST_F(KernelSampling, UniformConeMatchesItsDensity) {
  for (float c : {0.5f, 0.02f, 4e-5f}) {  // wide, a sphere light, the sun
    const glm::vec3 axis = glm::normalize(glm::vec3(-0.2f, 0.9f, 0.3f));
    const glm::dvec3 a(axis);
    const auto s = samples({3, 0, 6, 0, axis, glm::vec4(c, 0, 0, 0)});
    const int nm = 16, np = 16;
    std::vector<double> observed(nm * np, 0.0), expected(nm * np, double(s.size()) / (nm * np));
    for (const auto& v : s) {
      ASSERT_NEAR(glm::length(v), 1.0f, 1e-4);
      double mu, phi;
      polarAbout(glm::dvec3(v), a, mu, phi);
      // 1 - cos from the chord, which keeps precision for tiny cones.
      const double one_minus = 0.5 * glm::dot(glm::dvec3(v) - a, glm::dvec3(v) - a);
      ASSERT_LE(one_minus, c * 1.01 + 1e-7) << "outside the cone";
      const int bin = std::clamp(int((1.0 - one_minus / c) * nm), 0, nm - 1);
      observed[bin * np + std::min(int(phi / (2 * kPi) * np), np - 1)] += 1;
    }
    // The tiny cone is at float resolution: only check its radial histogram loosely.
    if (c < 1e-3) continue;
    expectChiSquare(observed, expected, "uniform cone 1-cos=" + std::to_string(c));
  }
}

// GGX visible normals: density of h is D_wo(h) = G1(wo) max(0, wo.h) D(h) / wo.z
// (Heitz 2014). Bins are equal-mass for D cos (u = tan^2 / (alpha^2 + tan^2)) in
// theta and uniform in phi; expected counts by midpoint quadrature of D_wo.
TEST_F(KernelSampling, GgxVndfMatchesItsDensity) {
  for (double alpha : {0.15, 0.5, 0.9})
    for (double theta_o_deg : {0.0, 45.0, 80.0}) {
      const double to = theta_o_deg * kPi / 180;
      const glm::dvec3 wo(std::sin(to), 0, std::cos(to));
      const auto s = samples({4, 0, 9, 0, glm::vec3(wo), glm::vec4(0, float(alpha), 0, 0)});
      auto lambda = [&](double c) { return 0.5 * (std::sqrt(1 + alpha * alpha * (1 - c * c) / (c * c)) - 1); };
      const double g1 = 1 / (1 + lambda(wo.z));
      auto density = [&](double theta, double phi) {  // per steradian
        const glm::dvec3 h(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
        const double c2 = h.z * h.z, a2 = alpha * alpha;
        const double d = a2 / (kPi * std::pow(c2 * (a2 - 1) + 1, 2));
        return g1 * std::max(0.0, glm::dot(wo, h)) * d / wo.z;
      };
      auto thetaOf = [&](double u) { return u >= 1 ? kPi / 2 : std::atan(alpha * std::sqrt(u / (1 - u))); };
      const int nu = 20, np = 24, sub = 32;
      std::vector<double> observed(nu * np, 0.0), expected(nu * np, 0.0);
      for (int i = 0; i < nu; ++i) {
        const double t0 = thetaOf(double(i) / nu), t1 = thetaOf(double(i + 1) / nu);
        for (int j = 0; j < np; ++j) {
          const double p0 = 2 * kPi * j / np, p1 = 2 * kPi * (j + 1) / np;
          double sum = 0;
          for (int a = 0; a < sub; ++a)
            for (int b = 0; b < sub; ++b) {
              const double th = t0 + (a + 0.5) * (t1 - t0) / sub;
              const double ph = p0 + (b + 0.5) * (p1 - p0) / sub;
              sum += density(th, ph) * std::sin(th);
            }
          expected[i * np + j] = s.size() * sum * (t1 - t0) / sub * (p1 - p0) / sub;
        }
      }
      for (const auto& v : s) {
        ASSERT_NEAR(glm::length(v), 1.0f, 1e-4);
        const glm::dvec3 h(v);
        ASSERT_GT(h.z, 0.0);
        const double t2 = (1 - h.z * h.z) / (h.z * h.z);
        const double u = t2 / (alpha * alpha + t2);
        double phi = std::atan2(h.y, h.x);
        if (phi < 0) phi += 2 * kPi;
        observed[std::min(int(u * nu), nu - 1) * np + std::min(int(phi / (2 * kPi) * np), np - 1)] += 1;
      }
      char what[64];
      std::snprintf(what, sizeof what, "GGX VNDF alpha %.2f theta_o %.0f", alpha, theta_o_deg);
      expectChiSquare(observed, expected, what);
    }
}

// Concentric disc: uniform over the unit disc (bins equal in r^2 and angle).
TEST_F(KernelSampling, ConcentricDiskIsUniform) {
  const auto s = samples({5, 0, 12});
  const int nr = 16, np = 16;
  std::vector<double> observed(nr * np, 0.0), expected(nr * np, double(s.size()) / (nr * np));
  for (const auto& v : s) {
    const double r2 = double(v.x) * v.x + double(v.y) * v.y;
    ASSERT_LE(r2, 1.0 + 1e-5);
    double phi = std::atan2(double(v.y), double(v.x));
    if (phi < 0) phi += 2 * kPi;
    observed[std::min(int(r2 * nr), nr - 1) * np + std::min(int(phi / (2 * kPi) * np), np - 1)] += 1;
  }
  expectChiSquare(observed, expected, "concentric disc");
}

}  // namespace
}  // namespace sdfc
