// sdSceneMaterial, the (distance, material) evaluation the kernel's normal loop
// makes at its 4 gradient taps and at the point it reads the material from,
// must give sdScene's distance bit for bit: then the normals, the taps' mean
// (which picks the material point) and so the material of every hit are what
// they were with separate sdScene and sdMaterialId calls. Checked on the device
// at 4096 points around every example scene: everywhere without bounding
// volumes; with them, wherever the distance is below the smallest margin past
// which the bounded sdScene may return a child's box distance (the taps sit
// within a hit band of a surface). Its material must be sdMaterialId's.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "driver/compile.h"
#include "gpu_points.h"
#include "vulkan_context.h"

namespace sdfc {
namespace {

// The point from the pixel as gpu_points.h makes it; outputs: 0 = (sdScene,
// sdSceneMaterial, whether their bits match), 2 = sdMaterialId.
const char* const kMain = R"(
void main() {
  uvec2 pixel = uvec2(gl_FragCoord.xy);
  uvec4 h = pcg4d(uvec4(pixel, frame.seed, 0x5eed1234u));
  vec3 u = vec3(h.xyz >> 8u) * (1.0 / 16777216.0);
  vec3 p = frame.cam_origin.xyz + frame.cam_right.xyz * (2.0 * u - 1.0);
  float d = sdScene(p);
  vec2 dm = sdSceneMaterial(p);
  out_color = vec4(d, dm.x, dm.y, floatBitsToUint(d) == floatBitsToUint(dm.x) ? 1.0 : 0.0);
  out_normal_depth = vec4(0.0);
  out_albedo_steps = vec4(float(sdMaterialId(p)), 0.0, 0.0, 0.0);
}
)";

// As gpu_equivalence_test.cpp: the smallest "if (bN > margin" of the emitted code.
double smallestBoundMargin(const std::string& glsl) {
  double smallest = INFINITY;
  const std::regex pattern(R"(if \(b[0-9]+ > ([-+0-9.eE]+))");
  for (auto it = std::sregex_iterator(glsl.begin(), glsl.end(), pattern); it != std::sregex_iterator(); ++it)
    smallest = std::min(smallest, std::stod((*it)[1].str()));
  return smallest;
}

TEST(SceneMaterial, DistanceIsSdSceneBitForBitAndMaterialIsSdMaterialId) {
  VulkanContext context;
  createContext(context);
  const std::filesystem::path dir = std::filesystem::path(SDFC_SOURCE_DIR) / "examples";
  int scenes = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".sdf") continue;
    std::ifstream file(entry.path());
    std::stringstream text;
    text << file.rdbuf();
    for (const bool bounds : {false, true}) {
      SCOPED_TRACE(entry.path().filename().string() + (bounds ? " bounded" : " unbounded"));
      CompileOptions options;
      options.emit.bounding_volumes = bounds;
      options.emit.with_kernel = false;
      options.produce_spirv = false;
      Diagnostics diags;
      const CompiledScene compiled = compileSource(entry.path().string(), text.str(), options, diags);
      ASSERT_TRUE(compiled.ok) << diags.format();
      std::string source = test::pointShaderSource(compiled.emitted);
      source = source.substr(0, source.size() - std::strlen(test::kPointMain)) + kMain;
      const SpirvResult spirv = glslToSpirv(source, ShaderStage::Fragment, "scene_material.frag");
      ASSERT_TRUE(spirv.ok()) << spirv.log;
      const double margin = bounds ? smallestBoundMargin(compiled.emitted.glsl) : INFINITY;
      // Around the scene's finite bounds (the ground planes are not marched).
      Aabb box;
      for (const ir::NodeRef& c : compiled.scene.root->children)
        if (c && c->bounds.finite()) box = box.unite(c->bounds);
      if (compiled.scene.root->bounds.finite()) box = compiled.scene.root->bounds;
      const glm::dvec3 centre = box.finite() ? box.center() : glm::dvec3(0);
      const glm::dvec3 half = box.finite() ? box.halfSize() * 1.1 + 0.1 : glm::dvec3(3);

      Renderer renderer(context, spirv.words, compiled.emitted.scene_data);
      gpu::FrameParams params{};
      params.cam_origin = glm::vec4(glm::vec3(centre), 0);
      params.cam_right = glm::vec4(glm::vec3(half), 0);
      params.cam_forward = glm::vec4(0, 0, 1, 0.7f);
      params.width = params.height = test::kPointGridSide;
      params.sample_count = 1;
      params.seed = 7;
      FloatImage a, b, c;
      renderer.renderPass(params, 60, a, b, c);
      int compared = 0;
      for (uint32_t y = 0; y < test::kPointGridSide; ++y)
        for (uint32_t x = 0; x < test::kPointGridSide; ++x) {
          const float* r = a.at(x, y);
          ASSERT_EQ(int(r[2]), int(c.at(x, y)[0])) << x << "," << y;  // the same material id
          if (!(std::fabs(r[0]) < margin)) continue;
          ++compared;
          ASSERT_EQ(r[3], 1.0f) << x << "," << y << ": sdScene " << r[0] << " sdSceneMaterial " << r[1];
        }
      EXPECT_GT(compared, bounds ? 0 : int(test::kPointGridSide * test::kPointGridSide) - 1);
    }
    ++scenes;
  }
  EXPECT_GE(scenes, 10);
  destroyContext(context);
  EXPECT_EQ(validationMessageCount(), 0);
}

}  // namespace
}  // namespace sdfc
