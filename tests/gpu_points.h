// Runs a scene's generated distance code on the Vulkan device at 64 x 64 =
// 4096 pseudo-random points and reads back the points and the distances, for
// comparison with the float64 evaluator (gpu_equivalence_test.cpp).
//
// The points come from a hash of the pixel (pcg4d, Jarzynski & Olano 2020) that
// the prelude already has; pcg4d() below is its bit-exact C++ twin, so tests can
// prove the GPU evaluated exactly the points the CPU thinks it did.
// Header-only because the test CMakeLists globs *_test.cpp only.
#pragma once
#include <glm/glm.hpp>

#include <array>
#include <cstdint>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "emit/embedded_sources.h"
#include "emit/feature_filter.h"
#include "emit/glsl_emitter.h"
#include "renderer.h"
#include "shader_interface.h"
#include "spirv/glsl_to_spirv.h"

namespace sdfc::test {

constexpr uint32_t kPointGridSide = 64;
constexpr uint32_t kPointSalt = 0x5eed1234u;

// pcg4d on uint32 lanes, as in compiler/emit/kernel/prelude.glsl.
inline std::array<uint32_t, 4> pcg4d(std::array<uint32_t, 4> v) {
  for (uint32_t& x : v) x = x * 1664525u + 1013904223u;
  auto mix = [&] {
    v[0] += v[1] * v[3];
    v[1] += v[2] * v[0];
    v[2] += v[0] * v[1];
    v[3] += v[1] * v[2];
  };
  mix();
  for (uint32_t& x : v) x ^= x >> 16u;
  mix();
  return v;
}

// The 24-bit lattice coordinates of pixel (x, y)'s point for `seed`.
inline glm::uvec3 pointBits(uint32_t x, uint32_t y, uint32_t seed) {
  const std::array<uint32_t, 4> h = pcg4d({x, y, seed, kPointSalt});
  return {h[0] >> 8u, h[1] >> 8u, h[2] >> 8u};
}

// The test's main(): point from the pixel, then sdScene. Outputs: 0 = (p, d),
// 1 = the 24-bit hash values as exact floats, 2 = material id.
inline const char* kPointMain = R"(
void main() {
  uvec2 pixel = uvec2(gl_FragCoord.xy);
  uvec4 h = pcg4d(uvec4(pixel, frame.seed, 0x5eed1234u));
  uvec3 bits = h.xyz >> 8u;
  vec3 u = vec3(bits) * (1.0 / 16777216.0);
  vec3 p = frame.cam_origin.xyz + frame.cam_right.xyz * (2.0 * u - 1.0);
  out_color = vec4(p, sdScene(p));
  out_normal_depth = vec4(vec3(bits), 0.0);
  out_albedo_steps = vec4(float(sdMaterialId(p)), 0.0, 0.0, 0.0);
}
)";

// #version, the shared interface, the real (feature-filtered) prelude, the
// scene code the emitter wrote with with_kernel = false, and kPointMain.
inline std::string pointShaderSource(const EmitResult& emitted) {
  // The emitted header (#version, #extension lines, comments) goes first;
  // #extension must precede all code.
  std::string scene = emitted.glsl, extensions;
  while (scene.rfind("#version", 0) == 0 || scene.rfind("#extension", 0) == 0 ||
         scene.rfind("//", 0) == 0) {
    const size_t eol = scene.find('\n');
    if (scene.rfind("#extension", 0) == 0) extensions += scene.substr(0, eol + 1);
    scene = scene.substr(eol + 1);
  }
  std::string source = "#version 450\n" + extensions;
  source += filterFeatures(embeddedSource("shader_interface.h"), emitted.stats.features);
  source += "\n" + filterFeatures(embeddedSource("kernel/prelude.glsl"), emitted.stats.features);
  source += "\n" + scene + "\n" + kPointMain;
  return source;
}

struct GpuPoints {
  std::vector<glm::vec3> points;
  std::vector<float> distances;
  std::vector<int> materials;
  std::vector<glm::uvec3> bits;  // what the shader's hash gave, per point
};

// Evaluates at centre + half * (2u - 1), u from the hash, at time `time`.
inline GpuPoints runPoints(const VulkanContext& context, const std::vector<uint32_t>& spirv,
                           glm::vec3 centre, glm::vec3 half, uint32_t seed, float time,
                           const std::vector<float>& scene_data = {}) {
  Renderer renderer(context, spirv, scene_data);
  gpu::FrameParams params{};
  params.cam_origin = glm::vec4(centre, 0);
  params.cam_right = glm::vec4(half, 0);
  params.cam_forward = glm::vec4(0, 0, 1, time);
  params.width = params.height = kPointGridSide;
  params.sample_count = 1;
  params.seed = seed;
  FloatImage a, b, c;
  renderer.renderPass(params, 60, a, b, c);
  GpuPoints out;
  for (uint32_t y = 0; y < kPointGridSide; ++y)
    for (uint32_t x = 0; x < kPointGridSide; ++x) {
      const float* pd = a.at(x, y);
      const float* h = b.at(x, y);
      out.points.push_back({pd[0], pd[1], pd[2]});
      out.distances.push_back(pd[3]);
      out.bits.push_back({uint32_t(h[0]), uint32_t(h[1]), uint32_t(h[2])});
      out.materials.push_back(static_cast<int>(c.at(x, y)[0]));
    }
  return out;
}

}  // namespace sdfc::test
