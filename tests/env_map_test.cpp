// The environment light sky(map: ...) (docs/lighting.md): the map's sampling
// against its pdf by a chi-square test on the kernel's CPU twin
// (eval/env_map.h), its pdf integrating to 1 and matching the sampled
// direction's, bad maps refused with their reasons, and the kernel's map code
// emitted only for scenes that have one.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <random>

#include "driver/compile.h"
#include "eval/env_map.h"
#include "eval/shared_exponent.h"
#include "image_io.h"

namespace sdfc {
namespace {

namespace fs = std::filesystem;

// A map with a bright lobe, a dim gradient and a black band: every case
// the distribution has to get right (peaks, smooth parts, zero weight).
ir::TextureImage testMap(int w) {
  ir::TextureImage m;
  m.width = w;
  m.height = w / 2;
  m.rgb.resize(size_t(m.width) * m.height * 3);
  for (int y = 0; y < m.height; ++y)
    for (int x = 0; x < m.width; ++x) {
      const double u = (x + 0.5) / m.width, v = (y + 0.5) / m.height;
      const double phi = 2 * M_PI * u, theta = M_PI * v;
      const glm::dvec3 d(std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi));
      const bool band = v > 0.55 && v < 0.7;  // black, the lobe's tail too
      const double lobe = band ? 0.0 : 50 * std::exp(20 * (glm::dot(d, glm::normalize(glm::dvec3(0.5, 0.6, 0.3))) - 1));
      const double base = band ? 0.0 : 0.2 + 0.3 * u;
      float* c = &m.rgb[(size_t(y) * m.width + x) * 3];
      c[0] = float(base + lobe);
      c[1] = float(0.5 * base + 0.8 * lobe);
      c[2] = float(0.2 * base + 0.5 * lobe);
    }
  return m;
}

// Upper tail of chi-square with k degrees of freedom at probability 1e-3
// (Wilson and Hilferty 1931, z = 3.09).
double chiSquareLimit(int k) {
  const double a = 2.0 / (9.0 * k), z = 3.09;
  return k * std::pow(1 - a + z * std::sqrt(a), 3);
}

// Samples of the CPU twin's sampling against the pdf of its sampling grid.
void expectSamplesFollowThePdf(const EnvMapData& map) {
  // Bins in (cos theta, phi), not the map's cells: the test checks where in
  // a cell a sample lands (uniformly in u and v) and the direction it maps
  // to. A bin's expected share is exact: each grid cell's probability (from
  // the CDFs) spread uniformly over its rectangle in (u, v), times its
  // overlap with the bin's rectangle there.
  const int kCos = 16, kPhi = 32;
  std::vector<double> expected(kCos * kPhi, 0.0), observed(kCos * kPhi, 0.0);
  auto overlap = [](double a0, double a1, double b0, double b1) { return std::max(0.0, std::min(a1, b1) - std::max(a0, b0)); };
  for (int y = 0; y < map.grid_y; ++y) {
    const double p_row = map.row_cdf[y] - (y > 0 ? map.row_cdf[y - 1] : 0.0f);
    for (int x = 0; x < map.grid_x; ++x) {
      const float* row = &map.column_cdf[size_t(y) * map.grid_x];
      const double p = p_row * (row[x] - (x > 0 ? row[x - 1] : 0.0f));
      if (p <= 0) continue;
      const double v0 = double(y) / map.grid_y, v1 = double(y + 1) / map.grid_y;
      const double u0 = double(x) / map.grid_x, u1 = double(x + 1) / map.grid_x;
      for (int i = 0; i < kCos; ++i) {
        // cos theta from -1 + 2 i / kCos up: v from acos(c1) / pi to acos(c0) / pi.
        const double bv0 = std::acos(-1 + 2.0 * (i + 1) / kCos) / M_PI, bv1 = std::acos(-1 + 2.0 * i / kCos) / M_PI;
        const double fv = overlap(v0, v1, bv0, bv1) / (v1 - v0);
        if (fv <= 0) continue;
        for (int j = int(u0 * kPhi); j < std::min(kPhi, int(u1 * kPhi) + 1); ++j)
          expected[i * kPhi + j] += p * fv * overlap(u0, u1, double(j) / kPhi, double(j + 1) / kPhi) / (u1 - u0);
      }
    }
  }
  // The pdf integrates to 1 over the sphere: midpoint rule in (u, v), where
  // d omega = 2 pi^2 sin(theta) du dv and the pdf is constant in a cell.
  double total = 0;
  for (int y = 0; y < map.grid_y; ++y)
    for (int x = 0; x < map.grid_x; ++x) {
      const double u = (x + 0.5) / map.grid_x, v = (y + 0.37) / map.grid_y;  // off-centre: no pole at v = 0.5
      const double phi = 2 * M_PI * u, theta = M_PI * v;
      const glm::vec3 d(float(std::sin(theta) * std::sin(phi)), float(std::cos(theta)), float(-std::sin(theta) * std::cos(phi)));
      total += envMapPdf(map, d) * 2 * M_PI * M_PI * std::sin(theta) / (double(map.grid_x) * map.grid_y);
    }
  // (The sin(theta) of the point, not the cell's mean: 1e-3 at 31 rows.)
  EXPECT_NEAR(total, 1.0, 3e-3) << "the pdf does not integrate to 1 over the sphere";
  const int n = 400000;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> uniform(0.0f, std::nextafter(1.0f, 0.0f));
  int failed = 0;
  double worst_mismatch = 0;
  for (int k = 0; k < n; ++k) {
    glm::vec3 d;
    float pdf;
    if (!sampleEnvMap(map, {uniform(rng), uniform(rng)}, d, pdf)) {
      ++failed;
      continue;
    }
    const int i = std::min(int((d.y + 1) / 2 * kCos), kCos - 1);
    double phi = std::atan2(d.x, -d.z);
    if (phi < 0) phi += 2 * M_PI;
    const int j = std::min(int(phi / (2 * M_PI) * kPhi), kPhi - 1);
    observed[i * kPhi + j] += 1;
    worst_mismatch = std::max(worst_mismatch, double(std::abs(envMapPdf(map, d) / pdf - 1)));
  }
  EXPECT_LT(failed, n / 10000) << "samples that drew nothing";
  // A sample's own pdf is the pdf of its direction (away from cell edges,
  // where float rounding may put the direction in the neighbour cell).
  EXPECT_LT(worst_mismatch, 1.0) << "a sample's pdf differs from envMapPdf at its direction";
  // Pool the bins expected to hold fewer than 5 samples (the black band).
  double chi2 = 0, pooled_e = 0, pooled_o = 0;
  int dof = -1;
  for (size_t b = 0; b < expected.size(); ++b) {
    const double e = expected[b] * n;
    if (e < 5) {
      pooled_e += e;
      pooled_o += observed[b];
      EXPECT_TRUE(e > 0 || observed[b] == 0) << "samples in bin " << b << " whose pdf is 0";
      continue;
    }
    chi2 += (observed[b] - e) * (observed[b] - e) / e;
    ++dof;
  }
  if (pooled_e >= 5) {
    chi2 += (pooled_o - pooled_e) * (pooled_o - pooled_e) / pooled_e;
    ++dof;
  }
  ASSERT_GT(dof, 100);
  EXPECT_LT(chi2, chiSquareLimit(dof)) << "chi-square " << chi2 << " with " << dof << " degrees of freedom";
}

TEST(EnvMap, SamplesFollowThePdfChiSquare) {
  // 63 x 31 texel cells: the grid is the texel cells.
  const EnvMapData map = buildEnvMap(testMap(64));
  ASSERT_EQ(map.grid_x, map.cells_x);
  expectSamplesFollowThePdf(map);
}

TEST(EnvMap, CoarseGridSamplesFollowThePdfChiSquare) {
  // 1099 x 549 texel cells on a 512 x 256 grid: grid cells cover parts of
  // texel cells (2.15 x 2.14 of them), the case a 4k map is.
  const EnvMapData map = buildEnvMap(testMap(1100));
  ASSERT_EQ(map.grid_x, kEnvGridMaxX);
  ASSERT_EQ(map.grid_y, kEnvGridMaxY);
  EXPECT_EQ(map.column_cdf.size(), size_t(kEnvGridMaxX) * kEnvGridMaxY);
  expectSamplesFollowThePdf(map);
}

TEST(EnvMap, CoarseGridCellIsPositiveWhereTheRadianceIs) {
  // A black map but for one texel: the bilinear radiance is positive in the
  // four texel cells around it, and so must the pdf be there; elsewhere 0.
  ir::TextureImage m;
  m.width = 1100;
  m.height = 550;
  m.rgb.assign(size_t(m.width) * m.height * 3, 0.0f);
  const int tx = 701, ty = 300;
  m.rgb[(size_t(ty) * m.width + tx) * 3 + 1] = 5.0f;
  const EnvMapData map = buildEnvMap(m);
  auto dirAt = [&](double i, double j) {  // texel coordinates
    const double phi = 2 * M_PI * i / map.cells_x, theta = M_PI * j / map.cells_y;
    return glm::vec3(float(std::sin(theta) * std::sin(phi)), float(std::cos(theta)), float(-std::sin(theta) * std::cos(phi)));
  };
  for (double di : {-0.9, -0.1, 0.1, 0.9})
    for (double dj : {-0.9, -0.1, 0.1, 0.9}) {
      const glm::vec3 d = dirAt(tx + di, ty + dj);
      EXPECT_GT(envMapRadiance(map, d).g, 0.0f);
      EXPECT_GT(envMapPdf(map, d), 0.0f) << "no pdf at texel offset " << di << ", " << dj;
    }
  EXPECT_EQ(envMapPdf(map, dirAt(tx + 8, ty)), 0.0f);
  // Every sample lands in the grid cells around the texel, within a cell of it.
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> uniform(0.0f, std::nextafter(1.0f, 0.0f));
  for (int k = 0; k < 2000; ++k) {
    glm::vec3 d;
    float pdf;
    ASSERT_TRUE(sampleEnvMap(map, {uniform(rng), uniform(rng)}, d, pdf));
    double u = std::atan2(d.x, -d.z) / (2 * M_PI);
    u -= std::floor(u);
    const double v = std::acos(d.y) / M_PI;
    EXPECT_LT(std::abs(u * map.cells_x - tx), 1.0 + double(map.cells_x) / map.grid_x);
    EXPECT_LT(std::abs(v * map.cells_y - ty), 1.0 + double(map.cells_y) / map.grid_y);
  }
}

TEST(EnvMap, SampledPdfMatchesPdfOfDirection) {
  const EnvMapData map = buildEnvMap(testMap(32));
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> uniform(0.0f, std::nextafter(1.0f, 0.0f));
  int close = 0, total = 0;
  for (int k = 0; k < 20000; ++k) {
    glm::vec3 d;
    float pdf;
    if (!sampleEnvMap(map, {uniform(rng), uniform(rng)}, d, pdf)) continue;
    ++total;
    if (std::abs(envMapPdf(map, d) / pdf - 1) < 1e-3) ++close;
  }
  // All but the few drawn within float rounding of a cell's edge.
  EXPECT_GT(close, total - total / 200) << close << " of " << total;
}

TEST(EnvMap, ConstantMapIsUniformOverTheSphere) {
  ir::TextureImage m;
  m.width = 16;
  m.height = 8;
  m.rgb.assign(16 * 8 * 3, 1.0f);
  const EnvMapData map = buildEnvMap(m);
  // Weighted by sin(theta) at texel centres: 1 / 4 pi up to the midpoint
  // rule's error over a row (a few % at the poles of an 8-row map).
  EXPECT_NEAR(envMapPdf(map, {1, 0, 0}) * 4 * M_PI, 1.0, 0.02);
  EXPECT_NEAR(envMapRadiance(map, glm::normalize(glm::vec3(0.3, 0.9, -0.2))).g, 1.0f, 1e-6);
}

TEST(EnvMap, SharedExponentTexelsAreExactToHalfAStep) {
  // Colours over 2^-15 .. 2^15, channels 1 to 10^6 apart: each channel
  // within half a step of the largest's 9 bits, and no word a NaN or an
  // infinity as the float the scene data carry it in.
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> expo(-15.0f, 14.99f), spread(0.0f, 6.0f);
  double worst = 0;
  for (int k = 0; k < 200000; ++k) {
    const float top = std::exp2(expo(rng));
    const glm::vec3 c(top, top * std::pow(10.0f, -spread(rng)), top * std::pow(10.0f, -spread(rng)));
    const uint32_t w = packSharedExponent(c);
    float f;
    std::memcpy(&f, &w, sizeof f);
    ASSERT_TRUE(std::isfinite(f)) << std::hex << w;
    const glm::vec3 d = unpackSharedExponent(w);
    for (int i = 0; i < 3; ++i) worst = std::max(worst, double(std::abs(d[i] - c[i]) / top));
  }
  EXPECT_LE(worst, std::ldexp(1.0, -9) * 1.001) << "largest error relative to the largest channel";
  // The layout the kernel decodes (kernel/envmap.glsl): b's high bits on top.
  EXPECT_EQ(packSharedExponent({1.0f, 0.5f, 1.0f}), (256u) | (128u << 9) | (0u << 18) | (16u << 23) | (8u << 28));
  EXPECT_EQ(unpackSharedExponent(packSharedExponent({3.0f, 0.0f, 2.0f})), glm::vec3(3.0f, 0.0f, 2.0f));
  EXPECT_EQ(packSharedExponent({0.0f, 0.0f, 0.0f}), 0u);
}

TEST(EnvMap, BrightMapsAreStoredScaled) {
  ir::TextureImage m = testMap(16);
  m.rgb[5] = 1e6f;  // a sun texel beyond the shared exponent's range
  const EnvMapData map = buildEnvMap(m);
  EXPECT_FLOAT_EQ(map.scale, 1e6f / kSharedExponentMax);  // the peak stored at the largest value
  EXPECT_NEAR(envMapTexel(map, 1, 0).b * map.scale, 1e6f, 1e6f * 1e-3f);
}

// Maps written to a temporary folder with a space in its name.
fs::path writeMap(const std::string& name, int w, int h, float value, int bad_texel = -1, float bad = 0) {
  const fs::path dir = fs::temp_directory_path() / "sdfc env_map_test";
  fs::create_directories(dir);
  FloatImage image(uint32_t(w), uint32_t(h), value);
  if (bad_texel >= 0) image.rgba[size_t(bad_texel) * 4 + 1] = bad;
  writeImage((dir / name).string(), image);
  return dir;
}

std::string diagnosticsOf(const std::string& sky) {
  const fs::path dir = writeMap("ok.exr", 8, 4, 1.0f);
  writeMap("square.exr", 8, 8, 1.0f);
  writeMap("nan.exr", 8, 4, 1.0f, 13, std::nanf(""));
  writeMap("negative.exr", 8, 4, 1.0f, 2, -0.5f);
  writeMap("ldr.png", 8, 4, 0.5f);
  Diagnostics diags;
  CompileOptions options;
  // The diagnostics point into the compiled scene's source: keep it.
  const CompiledScene c = checkSource((dir / "scene.sdf").string(), sky + "\nscene { sphere(radius: 1) }", options, diags);
  return diags.format();
}

TEST(EnvMap, BadMapsAreErrors) {
  struct Case {
    const char* text;
    const char* message;
  };
  const Case cases[] = {
      {"sky(map: \"none.exr\")", "cannot use 'none.exr' as an environment map: no such file (looked for '"},
      {"sky(map: \"square.exr\")", "it is 8 x 8 texels, not 2:1"},
      {"sky(map: \"nan.exr\")", "texel (5, 1) has G = nan; a radiance must be finite and non-negative (1 value is not)"},
      {"sky(map: \"negative.exr\")", "texel (2, 0) has G = -0.5"},
      {"sky(map: \"ldr.png\")", "an environment map is an HDR image: an .exr or .hdr file"},
      {"sky(map: 3)", "'map' of 'sky' must be a string naming an EXR or Radiance HDR image"},
      {"sky(map: \"ok.exr\", color: [1, 1, 1])", "'sky' takes 'map', or colours"},
      {"sky(rotation: 30)", "'rotation' of 'sky' applies to a map"},
      {"sky(map: \"ok.exr\", strength: -1)", "'strength' of 'sky' must not be negative"},
      {"sky(map: \"ok.exr\", map: \"ok.exr\")", "'map' is given twice"},
      {"sky(mapp: \"ok.exr\")", "'sky' has no parameter 'mapp'; did you mean 'map'?"},
  };
  for (const Case& k : cases) {
    SCOPED_TRACE(k.text);
    const std::string out = diagnosticsOf(k.text);
    EXPECT_NE(out.find(k.message), std::string::npos) << out;
    EXPECT_NE(out.find("error:"), std::string::npos) << out;
  }
  const std::string ok = diagnosticsOf("sky(map: \"ok.exr\", rotation: 30, strength: 2)");
  EXPECT_EQ(ok.find("error"), std::string::npos) << ok;
}

TEST(EnvMap, EmittedOnlyWhenUsed) {
  const fs::path dir = writeMap("ok.exr", 8, 4, 1.0f);
  CompileOptions options;
  options.produce_spirv = false;
  auto compile = [&](const std::string& sky) {
    Diagnostics diags;
    CompiledScene c = compileSource((dir / "scene.sdf").string(),
                                    sky + "\nscene { sphere(radius: 1, material: diffuse()) }", options, diags);
    EXPECT_TRUE(c.ok) << diags.format();
    return c;
  };
  const CompiledScene plain = compile("sky(color: [1, 1, 1])");
  EXPECT_EQ(plain.emitted.glsl.find("kEnv"), std::string::npos);
  EXPECT_TRUE(plain.emitted.scene_data.empty());
  const CompiledScene lit = compile("sky(map: \"ok.exr\", rotation: 90)");
  EXPECT_NE(lit.emitted.glsl.find("sampleEnvLight"), std::string::npos);
  EXPECT_NE(lit.emitted.glsl.find("SDFC_HAS_ENVMAP"), std::string::npos);
  // One shared-exponent word a texel, the CDF of the 7 x 3 cells between
  // texel centres and of their 3 rows (a vec4's multiple already).
  EXPECT_EQ(lit.emitted.scene_data.size(), size_t(8 * 4 + 7 * 3 + 3));
}

}  // namespace
}  // namespace sdfc
