// The kernel (prelude.glsl + pathtrace.glsl) compiles to valid SPIR-V for every
// feature combination the test scenes use, follows the feature-block rules of
// docs/kernel_contract.md, and still compiles when unused blocks are stripped
// the way the emitter strips them.
#include <gtest/gtest.h>

#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "kernel_harness.h"
#include "runtime/loop_budget.h"

namespace sdfc {
namespace {

using test::assembleKernel;
using test::compileKernel;
using test::kernelScene;
using test::readSourceFile;

struct Combo {
  const char* scene;
  std::vector<std::string> defines;
};

std::vector<Combo> combos() {
  const std::vector<std::string> all = {
      "SDFC_HAS_DIFFUSE", "SDFC_HAS_MIRROR",   "SDFC_HAS_GLASS",         "SDFC_HAS_METAL",
      "SDFC_HAS_EMISSIVE", "SDFC_HAS_SUN",     "SDFC_HAS_SPHERE_LIGHTS", "SDFC_USES_TIME",
      "SDFC_HAS_APERTURE"};
  std::vector<std::string> all_sobol = all;
  all_sobol.push_back("SDFC_SAMPLER_SOBOL");
  return {
      {"mixed.glsl", all},
      {"mixed.glsl", all_sobol},
      {"sphere_white_sky.glsl", {"SDFC_HAS_DIFFUSE"}},
      {"sphere_white_sky.glsl", {"SDFC_HAS_DIFFUSE", "SDFC_SAMPLER_SOBOL"}},
      {"sphere_white_sky.glsl",
       {"SDFC_HAS_MIRROR", "TEST_MATERIAL Material(MAT_MIRROR,vec3(1),vec3(0),1.0,0.0)"}},
      {"sphere_white_sky.glsl",
       {"SDFC_HAS_GLASS", "TEST_MATERIAL Material(MAT_GLASS,vec3(1),vec3(0),1.5,0.0)"}},
      {"sphere_white_sky.glsl",
       {"SDFC_HAS_METAL", "TEST_MATERIAL Material(MAT_METAL,vec3(1),vec3(0),1.0,0.2)"}},
      {"sphere_white_sky.glsl",
       {"SDFC_HAS_EMISSIVE", "TEST_MATERIAL Material(MAT_EMISSIVE,vec3(0),vec3(2),1.0,0.0)"}},
      {"hollow_sphere.glsl", {"SDFC_HAS_DIFFUSE"}},
      {"lights.glsl", {"SDFC_HAS_DIFFUSE", "SDFC_HAS_METAL", "SDFC_HAS_SUN"}},
      {"lights.glsl", {"SDFC_HAS_DIFFUSE", "SDFC_HAS_METAL", "SDFC_HAS_SPHERE_LIGHTS"}},
      {"lights.glsl",
       {"SDFC_HAS_DIFFUSE", "SDFC_HAS_METAL", "SDFC_HAS_SUN", "SDFC_HAS_SPHERE_LIGHTS"}},
      {"lights.glsl",
       {"SDFC_HAS_DIFFUSE", "SDFC_HAS_SUN", "SDFC_HAS_SPHERE_LIGHTS", "SDFC_HAS_APERTURE",
        "TEST_MATERIAL_B Material(MAT_DIFFUSE,vec3(0.5),vec3(0),1.0,0.0)"}},
  };
}

std::string describe(const Combo& c) {
  std::string s = c.scene;
  for (const auto& d : c.defines) s += " " + d;
  return s;
}

TEST(KernelCompile, EveryFeatureCombinationCompilesAndValidates) {
  for (const Combo& c : combos()) {
    SpirvResult result = compileKernel(kernelScene(c.scene), c.defines);
    EXPECT_TRUE(result.ok()) << describe(c) << "\n" << result.log;
  }
}

// A minimal model of the emitter's block resolution: keeps or drops lines inside
// SDFC_ conditionals, passes every other line through. Fails the test on any
// conditional form the contract does not allow.
std::string stripFeatureBlocks(const std::string& text, const std::vector<std::string>& defined) {
  auto is_defined = [&](const std::string& name) {
    for (const auto& d : defined)
      if (d == name) return true;
    return false;
  };
  const std::regex ifdef_re(R"(^\s*#\s*ifdef\s+(SDFC_\w+)\s*$)");
  const std::regex ifndef_re(R"(^\s*#\s*ifndef\s+(SDFC_\w+)\s*$)");
  // A disjunction of two or more defined(SDFC_X) terms.
  const std::regex ifor_re(
      R"(^\s*#\s*if\s+defined\((SDFC_\w+)\)(\s*\|\|\s*defined\(SDFC_\w+\))+\s*$)");
  const std::regex term_re(R"(defined\((SDFC_\w+)\))");
  const std::regex ifand_re(R"(^\s*#\s*if\s+defined\((SDFC_\w+)\)\s*&&\s*defined\((SDFC_\w+)\)\s*$)");
  const std::regex other_if_re(R"(^\s*#\s*(if|ifdef|ifndef|elif)\b.*)");
  const std::regex else_re(R"(^\s*#\s*else\b.*)");
  const std::regex endif_re(R"(^\s*#\s*endif\b.*)");
  struct Frame { bool active; bool cond; };
  std::vector<Frame> stack;
  std::istringstream in(text);
  std::string line, out;
  auto active = [&] { return stack.empty() || stack.back().active; };
  std::smatch m;
  while (std::getline(in, line)) {
    if (std::regex_match(line, m, ifdef_re) || std::regex_match(line, m, ifndef_re) ||
        std::regex_match(line, m, ifor_re)) {
      bool cond = is_defined(m[1]);
      if (line.find("ifndef") != std::string::npos) cond = !cond;
      if (m.size() > 2 && m[2].matched)
        for (std::sregex_iterator t(line.begin(), line.end(), term_re), end; t != end; ++t)
          cond = cond || is_defined((*t)[1]);
      const bool outer = active();
      stack.push_back({outer && cond, cond});
      continue;
    }
    if (std::regex_match(line, m, ifand_re)) {
      ADD_FAILURE() << "'&&' is not an allowed feature-block form: " << line;
      continue;
    }
    if (std::regex_match(line, other_if_re)) {
      ADD_FAILURE() << "conditional other than an SDFC_ feature block in the kernel: " << line;
      continue;
    }
    if (std::regex_match(line, else_re)) {
      if (stack.empty()) {
        ADD_FAILURE() << "#else without #if";
        continue;
      }
      const bool outer = stack.size() < 2 || stack[stack.size() - 2].active;
      stack.back().active = outer && !stack.back().cond;
      continue;
    }
    if (std::regex_match(line, endif_re)) {
      if (stack.empty()) {
        ADD_FAILURE() << "#endif without #if";
      } else {
        stack.pop_back();
      }
      continue;
    }
    if (active()) out += line + "\n";
  }
  EXPECT_TRUE(stack.empty()) << "unterminated feature block";
  return out;
}

TEST(KernelCompile, FeatureBlocksFollowTheContractAndStripCleanly) {
  for (const Combo& c : combos()) {
    std::vector<std::string> features, others;
    for (const auto& d : c.defines) (d.rfind("SDFC_", 0) == 0 ? features : others).push_back(d);
    std::string source = "#version 450\n";
    for (const auto& d : others) source += "#define " + d + "\n";
    source += readSourceFile("runtime/shader_interface.h");
    const std::string prelude =
        stripFeatureBlocks(readSourceFile("compiler/emit/kernel/prelude.glsl"), features);
    const std::string pathtrace =
        stripFeatureBlocks(readSourceFile("compiler/emit/kernel/pathtrace.glsl"), features);
    EXPECT_EQ((prelude + pathtrace).find("#if"), std::string::npos) << describe(c);
    source += prelude;
    // Scene snippets are test code with real #defines, as the emitter would generate them.
    for (const auto& d : features) source += "#define " + d + "\n";
    source += kernelScene(c.scene);
    source += pathtrace;
    SpirvResult result = glslToSpirv(source, ShaderStage::Fragment, "stripped.frag");
    EXPECT_TRUE(result.ok()) << describe(c) << "\n" << result.log;
  }
}

TEST(KernelCompile, TooManySphereLightsIsACompileError) {
  std::string scene = kernelScene("lights.glsl");
  const std::string from = "const int kNumSphereLights = 2;";
  scene.replace(scene.find(from), from.size(), "const int kNumSphereLights = 17;");
  for (const char* array : {"vec4[](", "vec3[]("}) {  // pad both arrays to 17 entries
    const size_t at = scene.find(array) + std::string(array).size();
    std::string pad;
    for (int i = 0; i < 15; ++i) pad += std::string(array).substr(0, 4) + "(0.0), ";
    scene.insert(at, pad);
  }
  SpirvResult result = compileKernel(scene, {"SDFC_HAS_DIFFUSE", "SDFC_HAS_SPHERE_LIGHTS"});
  EXPECT_FALSE(result.ok());
  EXPECT_NE(result.log.find("array size must be a positive integer"), std::string::npos) << result.log;
  // ... and 16 lights are accepted.
  const std::string from17 = "kNumSphereLights = 17;";
  scene.replace(scene.find(from17), from17.size(), "kNumSphereLights = 16;");
  for (const char* array : {"vec4[](", "vec3[]("}) {
    const size_t at = scene.find(array) + std::string(array).size();
    scene.erase(at, std::string(array).substr(0, 4).size() + 7);
  }
  result = compileKernel(scene, {"SDFC_HAS_DIFFUSE", "SDFC_HAS_SPHERE_LIGHTS"});
  EXPECT_TRUE(result.ok()) << result.log;
}

TEST(KernelCompile, WholeShaderStaysSmall) {
  const Combo all = combos()[0];
  SpirvResult result = compileKernel(kernelScene(all.scene), all.defines);
  ASSERT_TRUE(result.ok()) << result.log;
  // sdScene is inlined at three sites (march, normal loop, shadow march) at most;
  // keep the whole module modest so lavapipe's LLVM compile stays quick.
  EXPECT_LT(result.words.size() * 4, 80u * 1024u);
}

TEST(LoopBudget, FormulaMatchesTheKernelLoopStructure) {
  // S = 64 + 2 refinement steps, B = 3, L = 2, N = 1:
  // 1 + (4 + 3 * 2) * (1 + 66 + 2 * 1 + 5): the normal's loop is 4 taps + the material
  static_assert(kRefineSteps == 2 && kNormalLoopIterations == 5);
  EXPECT_EQ(loopIterationsPerSample(64, 3, 2, 1), 1u + 10u * 74u);
  EXPECT_EQ(loopIterationsPerPassOverhead(64, 1), 1u + 74u);
  EXPECT_EQ(loopIterationsPerPass(64, 3, 2, 5, 1), 75u + 5u * loopIterationsPerSample(64, 3, 2, 1));
  // The default assumes the most sphere lights the kernel accepts.
  EXPECT_EQ(loopIterationsPerSample(64, 3, 2), loopIterationsPerSample(64, 3, 2, kMaxSphereLights));
}

TEST(LoopBudget, SamplesPerPassIsTheLargestCountUnderTheCap) {
  for (uint32_t steps : {16u, 64u, 128u, 256u, 512u, 1000u})
    for (uint32_t bounces : {0u, 1u, 3u, 5u, 8u})
      for (uint32_t lights : {0u, 1u, 2u, 4u})
        for (uint32_t spheres : {0u, 2u, 16u}) {
          const uint32_t n = samplesPerPassWithinCap(steps, bounces, lights, spheres);
          if (n > 0) {
            EXPECT_LT(loopIterationsPerPass(steps, bounces, lights, n, spheres), gpu::kLavapipeLoopCap);
          }
          EXPECT_GE(loopIterationsPerPass(steps, bounces, lights, n + 1, spheres), gpu::kLavapipeLoopCap)
              << steps << " " << bounces << " " << lights << " " << spheres;
        }
  EXPECT_EQ(samplesPerPassWithinCap(20000, 8, 4), 0u);  // not even one sample fits
}

}  // namespace
}  // namespace sdfc
