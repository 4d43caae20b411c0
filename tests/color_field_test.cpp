// Colour fields (docs/language.md, "Colour fields"): each equals its closed
// form at sample points in float64 (eval/color_field.cpp), and the emitted
// sdMaterialAt equals the float64 field on the Vulkan device at 4096 points;
// a scene without fields emits no field code; bad fields get errors.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <regex>

#include "driver/compile.h"
#include "eval/color_field.h"
#include "eval/evaluator.h"
#include "eval/noise.h"
#include "gpu_points.h"
#include "image_io.h"
#include "vulkan_context.h"

namespace sdfc {
namespace {

using glm::dvec3;

CompiledScene checkText(const std::string& text, Diagnostics& diags) {
  CompileOptions options;
  return checkSource("field.sdf", text, options, diags);
}

// The field of the scene's first material.
ir::ColorField fieldOf(const std::string& material_text) {
  Diagnostics diags;
  const CompiledScene c = checkText("let m = " + material_text + "\nscene { sphere(radius: 1, material: m) }", diags);
  EXPECT_FALSE(diags.hasErrors()) << diags.format();
  if (c.scene.materials.empty() || !c.scene.materials[0].field) {
    ADD_FAILURE() << "no field in " << material_text;
    return {};
  }
  return *c.scene.materials[0].field;
}

const dvec3 kA(0.9, 0.8, 0.7), kB(0.1, 0.2, 0.3);

void expectColour(const ir::ColorField& f, dvec3 p, double t, double time = 0) {
  const dvec3 c = fieldColor(f, p, dvec3(0, 1, 0), time);
  const dvec3 want = kA + (kB - kA) * t;
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(c[i], want[i], 1e-14) << "at " << p.x << " " << p.y << " " << p.z;
}

TEST(ColorField, CheckerAlternatesCubesOfItsSize) {
  const ir::ColorField f = fieldOf("diffuse(albedo: checker([0.9, 0.8, 0.7], [0.1, 0.2, 0.3], size: 0.5))");
  expectColour(f, {0.25, 0.25, 0.25}, 0);
  expectColour(f, {0.75, 0.25, 0.25}, 1);
  expectColour(f, {0.75, 0.75, 0.25}, 0);
  expectColour(f, {0.75, 0.75, 0.75}, 1);
  expectColour(f, {-0.25, 0.25, 0.25}, 1);   // cell -1
  expectColour(f, {-0.25, -0.25, 0.25}, 0);  // cells -1, -1
  expectColour(f, {-0.75, 0.1, 3.1}, 0);     // -2 + 0 + 6
}

// A face on a step of the field (issue 47 item 15): read inside the surface,
// one colour on both sides of the face's exact position.
TEST(ColorField, StepsAreReadInsideTheSurface) {
  const ir::ColorField f = fieldOf("diffuse(albedo: checker([1, 0, 0], [0, 0, 1], size: 1))");
  const dvec3 up(0, 1, 0);
  for (double x : {0.25, 1.5, -2.75})
    for (double dy : {1e-12, -1e-12, 1e-6, -1e-6}) {
      // Below y = 0 the cell of (x, -, 0.5) is the one floor(x) + (-1) + 0 says.
      const double below = std::fmod(std::fabs(std::floor(x) - 1), 2.0);
      EXPECT_EQ(fieldColor(f, dvec3(x, dy, 0.5), up, 0), below == 0 ? dvec3(1, 0, 0) : dvec3(0, 0, 1)) << x << " " << dy;
    }
  // A ceiling (normal down) at y = 0 takes the cell above.
  EXPECT_EQ(fieldColor(f, dvec3(0.25, -1e-9, 0.5), -up, 0), dvec3(1, 0, 0));
  // Stripes across x on a wall at x = 0 facing +x: the stripe behind it.
  const ir::ColorField s = fieldOf("diffuse(albedo: stripes([1, 0, 0], [0, 0, 1]))");
  EXPECT_EQ(fieldColor(s, dvec3(1e-12, 0.3, 0.2), dvec3(1, 0, 0), 0), dvec3(0, 0, 1));
  EXPECT_EQ(fieldColor(s, dvec3(-1e-12, 0.3, 0.2), dvec3(1, 0, 0), 0), dvec3(0, 0, 1));
}

TEST(ColorField, StripesAlongTheirAxis) {
  const ir::ColorField f =
      fieldOf("diffuse(albedo: stripes([0.9, 0.8, 0.7], [0.1, 0.2, 0.3], axis: [0, 2, 0], period: 0.5))");
  expectColour(f, {5, 0.1, -3}, 0);
  expectColour(f, {5, 0.3, -3}, 1);
  expectColour(f, {0, 0.6, 0}, 0);
  expectColour(f, {0, -0.1, 0}, 1);  // fract(-0.2) = 0.8
  expectColour(f, {0, -0.3, 0}, 0);  // fract(-0.6) = 0.4
  // The default axis is x.
  const ir::ColorField g = fieldOf("diffuse(albedo: stripes([0.9, 0.8, 0.7], [0.1, 0.2, 0.3]))");
  expectColour(g, {0.25, 7, 7}, 0);
  expectColour(g, {0.75, 7, 7}, 1);
}

TEST(ColorField, GradientIsLinearAndClamped) {
  const ir::ColorField f =
      fieldOf("diffuse(albedo: gradient([0.9, 0.8, 0.7], [0.1, 0.2, 0.3], axis: [1, 1, 0], from: 1, to: 3))");
  expectColour(f, {1, 1, 0}, (std::sqrt(2.0) - 1) / 2);
  expectColour(f, {2, 1, 9}, (3 / std::sqrt(2.0) - 1) / 2);
  expectColour(f, {0, 0, 0}, 0);  // below from
  expectColour(f, {5, 5, 0}, 1);  // above to
  // Reversed ends run the other way.
  const ir::ColorField g = fieldOf("diffuse(albedo: gradient([0.9, 0.8, 0.7], [0.1, 0.2, 0.3], from: 2, to: 0))");
  expectColour(g, {0, 0.5, 0}, 0.75);
}

TEST(ColorField, ParametersMayDependOnTime) {
  const ir::ColorField f =
      fieldOf("diffuse(albedo: stripes([0.9, 0.8, 0.7], [0.1, 0.2, 0.3], period: 1 + time))");
  expectColour(f, {0.6, 0, 0}, 1, 0);    // period 1: fract 0.6
  expectColour(f, {0.6, 0, 0}, 0, 0.5);  // period 1.5: fract 0.4
  const ir::ColorField g = fieldOf("diffuse(albedo: gradient([0, 0, 0], [time, 1, 1]))");
  const dvec3 c = fieldColor(g, {0, 0.5, 0}, {0, 1, 0}, 0.8);
  EXPECT_NEAR(c.x, 0.4, 1e-15);
  EXPECT_NEAR(c.y, 0.5, 1e-15);
}

// The definition in eval/noise.h written out independently: the sum over the
// 8 corners of weight * dot(gradient, offset).
double naiveNoise(dvec3 p) {
  static const int g[12][3] = {{1, 1, 0}, {-1, 1, 0}, {1, -1, 0}, {-1, -1, 0}, {1, 0, 1}, {-1, 0, 1},
                               {1, 0, -1}, {-1, 0, -1}, {0, 1, 1}, {0, -1, 1}, {0, 1, -1}, {0, -1, -1}};
  auto h = [](uint32_t x) {
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
  };
  auto fade = [](double t) { return 6 * std::pow(t, 5) - 15 * std::pow(t, 4) + 10 * std::pow(t, 3); };
  const dvec3 c = glm::floor(p);
  double sum = 0;
  for (int dx = 0; dx < 2; ++dx)
    for (int dy = 0; dy < 2; ++dy)
      for (int dz = 0; dz < 2; ++dz) {
        const int x = int(c.x) + dx, y = int(c.y) + dy, z = int(c.z) + dz;
        const uint32_t k = h(uint32_t(x) ^ h(uint32_t(y) ^ h(uint32_t(z)))) % 12u;
        const dvec3 d = p - dvec3(x, y, z);
        double w = 1;
        for (int i = 0; i < 3; ++i) {
          const double f = fade(p[i] - c[i]);
          w *= (i == 0 ? dx : i == 1 ? dy : dz) ? f : 1 - f;
        }
        sum += w * (g[k][0] * d.x + g[k][1] * d.y + g[k][2] * d.z);
      }
  return sum;
}

TEST(ColorField, NoiseIsTheDocumentedGradientNoise) {
  const ir::ColorField f = fieldOf("diffuse(albedo: noise([0.9, 0.8, 0.7], [0.1, 0.2, 0.3], scale: 2, octaves: 3))");
  EXPECT_EQ(f.octaves, 3);
  // 0 on the lattice (every octave's lattice holds p * scale's): t = 1/2.
  expectColour(f, {0.5, -1.5, 3}, 0.5);
  uint32_t state = 12345;
  auto next = [&] { return (state = state * 1664525u + 1013904223u) / 4294967296.0; };
  double lo = 0, hi = 0, mean = 0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const dvec3 p(next() * 40 - 20, next() * 40 - 20, next() * 40 - 20);
    const double v = gradientNoise(p);
    ASSERT_NEAR(v, naiveNoise(p), 1e-12);
    lo = std::min(lo, v);
    hi = std::max(hi, v);
    mean += v / n;
    const double fbm = (naiveNoise(2.0 * p) + 0.5 * naiveNoise(4.0 * p) + 0.25 * naiveNoise(8.0 * p)) / 1.75;
    expectColour(f, p, std::clamp(0.5 + 0.5 * fbm, 0.0, 1.0));
  }
  EXPECT_GT(lo, -1.1);
  EXPECT_LT(hi, 1.1);
  EXPECT_LT(lo, -0.6);  // it uses its range
  EXPECT_GT(hi, 0.6);
  EXPECT_NEAR(mean, 0, 0.02);
}

TEST(ColorField, EmitterFieldsScaleWithStrength) {
  Diagnostics diags;
  const CompiledScene c = checkText(
      "let lamp = emissive(color: gradient([0, 0, 0], [1, 0.5, 0.25]), strength: 4)\n"
      "scene { sphere(radius: 1, material: lamp) }", diags);
  ASSERT_FALSE(diags.hasErrors()) << diags.format();
  const dvec3 e = materialColor(c.scene.materials[0], {0, 0.5, 0}, {0, 1, 0}, 0);
  EXPECT_NEAR(e.x, 2, 1e-15);
  EXPECT_NEAR(e.y, 1, 1e-15);
  EXPECT_NEAR(e.z, 0.5, 1e-15);
}

// A 4 x 2 EXR whose texel (i, j from the top) is (i, j, i + 10 j) / 16, written
// to the test's temporary folder; the scene refers to it by a relative path.
std::filesystem::path writeTestTexture() {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "sdfc color_field_test";
  std::filesystem::create_directories(dir);
  FloatImage image{4, 2};
  for (uint32_t j = 0; j < 2; ++j)
    for (uint32_t i = 0; i < 4; ++i) {
      float* t = image.at(i, j);
      t[0] = i / 16.0f;
      t[1] = j / 16.0f;
      t[2] = (i + 10.0f * j) / 16.0f;
      t[3] = 1;
    }
  writeImage((dir / "ramp.exr").string(), image);
  return dir;
}

ir::ColorField textureField(const std::string& args) {
  const std::filesystem::path dir = writeTestTexture();
  Diagnostics diags;
  CompileOptions options;
  const CompiledScene c =
      checkSource((dir / "scene.sdf").string(),
                  "let m = diffuse(albedo: texture(" + args + "))\nscene { sphere(radius: 1, material: m) }", options,
                  diags);
  EXPECT_FALSE(diags.hasErrors()) << diags.format();
  if (c.scene.materials.empty() || !c.scene.materials[0].field) return {};
  return *c.scene.materials[0].field;
}

TEST(ColorField, TextureIsBilinearBetweenTexelCentresAndRepeats) {
  const ir::ColorField f = textureField("file: \"ramp.exr\", projection: triplanar, size: 2");
  ASSERT_TRUE(f.image);
  ASSERT_EQ(f.image->width, 4);
  ASSERT_EQ(f.image->height, 2);
  auto texel = [](double i, double j) { return dvec3(i, j, i + 10 * j) / 16.0; };
  auto expectNear = [](dvec3 got, dvec3 want) {
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(got[k], want[k], 1e-7);
  };
  // Texel (i, j) has its centre at u = (i + 0.5) / 4, v = 1 - (j + 0.5) / 2.
  expectNear(textureBilinear(*f.image, 1.5 / 4, 0.75), texel(1, 0));
  expectNear(textureBilinear(*f.image, 2.5 / 4, 0.25), texel(2, 1));
  // Halfway between two texels: their mean; a whole repeat further: the same.
  expectNear(textureBilinear(*f.image, 2.0 / 4, 0.75), (texel(1, 0) + texel(2, 0)) / 2.0);
  expectNear(textureBilinear(*f.image, 2.0 / 4 - 3, 0.75 + 5), (texel(1, 0) + texel(2, 0)) / 2.0);
  // Past the last column it wraps to the first.
  expectNear(textureBilinear(*f.image, 0.0, 0.5), (texel(3, 0) + texel(0, 0) + texel(3, 1) + texel(0, 1)) / 4.0);
  // Triplanar on a face looking along z: uv = (x, y) / size.
  expectNear(fieldColor(f, {2.5 / 4 * 2, 0.25 * 2, 7}, {0, 0, -1}, 0), texel(2, 1));
  // Along x: uv = (z, y) / size; along y: (x, z) / size.
  expectNear(fieldColor(f, {9, 0.25 * 2, 2.5 / 4 * 2}, {1, 0, 0}, 0), texel(2, 1));
  expectNear(fieldColor(f, {2.5 / 4 * 2, -3, 0.25 * 2}, {0, 1, 0}, 0), texel(2, 1));
  // Between two faces: weights n^4 normalised.
  const dvec3 p(2.5 / 4 * 2, 0.25 * 2, 1.5 / 4 * 2);
  const dvec3 n = glm::normalize(dvec3(1, 0, 2));
  const double wx = std::pow(n.x, 4), wz = std::pow(n.z, 4);
  expectNear(fieldColor(f, p, n, 0), (textureBilinear(*f.image, p.z / 2, p.y / 2) * wx + texel(2, 1) * wz) / (wx + wz));
}

TEST(ColorField, PngTexturesAreDecodedFromSrgb) {
  Diagnostics diags;
  CompileOptions options;
  const CompiledScene c = checkSource(
      std::string(SDFC_SOURCE_DIR) + "/examples/scene.sdf",
      "let m = diffuse(albedo: texture(\"textures/tiles.png\"))\nscene { sphere(radius: 1, material: m) }", options,
      diags);
  ASSERT_FALSE(diags.hasErrors()) << diags.format();
  const ir::TextureImage& image = *c.scene.materials[0].field->image;
  ASSERT_EQ(image.width, 64);
  // Texel (0, 0) is mortar, sRGB (200, 196, 186).
  EXPECT_NEAR(image.rgb[0], std::pow((200 / 255.0 + 0.055) / 1.055, 2.4), 1e-6);
  EXPECT_NEAR(image.rgb[2], std::pow((186 / 255.0 + 0.055) / 1.055, 2.4), 1e-6);
}

TEST(ColorField, BadFieldsAreErrors) {
  struct Case {
    const char* text;
    const char* message;
  };
  const Case cases[] = {
      {"let m = diffuse(albedo: noise([1, 1, 1], 0, octaves: 9))", "'octaves' of 'noise' must be a whole number from 1 to 8, got 9"},
      {"let m = diffuse(albedo: noise(0, 1, octaves: 2.5))", "whole number from 1 to 8, got 2.5"},
      {"let m = diffuse(albedo: gradient(0, 1, from: 2, to: 2))", "'from' and 'to' of 'gradient' must differ"},
      {"let m = diffuse(albedo: checker(0, 1, size: 0))", "'size' of 'checker' must be positive, got 0"},
      {"let m = diffuse(albedo: stripes(0, 1, axis: [0, 0, 0]))", "'axis' of 'stripes' must not be the zero vector"},
      {"let m = diffuse(albedo: checker(0))", "'checker' needs 'b'"},
      {"let m = diffuse(albedo: checker([0, -1, 0], 1))", "must not be negative"},
      {"let m = diffuse(albedo: stripes(0, 1, axis: [time, 1, 0]))", "'axis' of 'stripes' must be a constant"},
      {"let m = diffuse(albedo: checker(0, 1) { sphere(radius: 1) })", "'checker' is a colour field and takes no block"},
      {"sky(color: checker(0, 1))\nlet m = diffuse()", "not a colour field"},
      {"let m = diffuse(albedo: checker(0, 1) * 2)", "cannot apply '*' to a colour field"},
      {"let m = diffuse(albedo: 1)\nlet checker = 2", "'checker' is a built-in name"},
      {"let m = diffuse(albedo: texture())", "'texture' needs 'file'"},
      {"let m = diffuse(albedo: texture(file: 3))", "'file' of 'texture' must be a string naming a PNG or EXR image"},
      {"let m = diffuse(albedo: texture(file: \"none.png\"))", "cannot read 'none.png': no such file (looked for '"},
      {"let m = diffuse(albedo: texture(file: \"none.png\", projection: planar))",
       "'projection' of 'texture' must be 'triplanar'"},
      {"let m = diffuse(albedo: texture(file: \"none.png\", sise: 2))", "has no parameter 'sise'; did you mean 'size'?"},
      {"let m = diffuse(albedo: texture(file: \"none.png\", size: -1))", "'size' of 'texture' must be positive"},
  };
  for (const Case& k : cases) {
    SCOPED_TRACE(k.text);
    Diagnostics diags;  // its diagnostics point into the scene's source: keep it
    const CompiledScene c = checkText(std::string(k.text) + "\nscene { sphere(radius: 1, material: m) }", diags);
    EXPECT_TRUE(diags.hasErrors());
    EXPECT_NE(diags.format().find(k.message), std::string::npos) << diags.format();
  }
  // Above 1 is the usual energy warning, not an error.
  Diagnostics diags;
  const CompiledScene c =
      checkText("let m = diffuse(albedo: checker([2, 0, 0], 1))\nscene { sphere(radius: 1, material: m) }", diags);
  EXPECT_FALSE(diags.hasErrors()) << diags.format();
  EXPECT_NE(diags.format().find("above 1"), std::string::npos) << diags.format();
}

TEST(ColorField, OnlyUsedFieldsAreEmitted) {
  CompileOptions options;
  options.produce_spirv = false;
  auto glsl = [&](const std::string& text) {
    Diagnostics diags;
    const CompiledScene c = compileSource("field.sdf", text, options, diags);
    EXPECT_TRUE(c.ok) << diags.format();
    return c.emitted.glsl;
  };
  const std::string plain = glsl("let m = diffuse(albedo: [0.5, 0.5, 0.5])\nscene { sphere(radius: 1, material: m) }");
  EXPECT_EQ(plain.find("sdMaterialAt"), std::string::npos);
  EXPECT_EQ(plain.find("sdGradientNoise"), std::string::npos);
  // A field no shape uses: no field code either.
  const std::string unused = glsl(
      "let m = diffuse(albedo: [0.5, 0.5, 0.5])\nlet n = diffuse(albedo: noise(0, 1))\n"
      "scene { sphere(radius: 1, material: m) }");
  EXPECT_EQ(unused.find("sdMaterialAt"), std::string::npos);
  EXPECT_EQ(unused.find("sdGradientNoise"), std::string::npos);
  // A checker: sdMaterialAt without the noise.
  const std::string checker = glsl("let m = diffuse(albedo: checker(0, 1))\nscene { sphere(radius: 1, material: m) }");
  EXPECT_NE(checker.find("Material sdMaterialAt("), std::string::npos);
  EXPECT_EQ(checker.find("sdGradientNoise"), std::string::npos);
  const std::string noise = glsl("let m = diffuse(albedo: noise(0, 1))\nscene { sphere(radius: 1, material: m) }");
  EXPECT_NE(noise.find("float sdGradientNoise("), std::string::npos);
}

// ---- on the device ---------------------------------------------------------

// The point test's main with the albedo of sdMaterialAt as the third output.
const char* kFieldMain = R"(
void main() {
  uvec2 pixel = uvec2(gl_FragCoord.xy);
  uvec4 h = pcg4d(uvec4(pixel, frame.seed, 0x5eed1234u));
  vec3 u = vec3(h.xyz >> 8u) * (1.0 / 16777216.0);
  vec3 p = frame.cam_origin.xyz + frame.cam_right.xyz * (2.0 * u - 1.0);
  vec3 n = normalize(p - frame.cam_origin.xyz + vec3(1e-3));
  Material m = sdMaterialAt(sdMaterialId(p), p, n);
  out_color = vec4(p, 0.0);
  out_normal_depth = vec4(m.emission, 0.0);
  out_albedo_steps = vec4(m.albedo, 0.0);
}
)";

class ColorFieldGpu : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    context_ = new VulkanContext;
    createContext(*context_);
  }
  static void TearDownTestSuite() {
    destroyContext(*context_);
    delete context_;
    context_ = nullptr;
    EXPECT_EQ(validationMessageCount(), 0);
  }

  // Runs the scene's sdMaterialAt at 4096 points in a 4-unit cube at `time`
  // and compares with the float64 colour at the float32 point read back.
  // Points within `edge` of a jump (checker, stripes) are skipped: float32
  // rounding may put them on either side.
  void check(const std::string& text, double tolerance, float time = 0.7f, const std::string& path = "field.sdf") {
    SCOPED_TRACE(text);
    CompileOptions options;
    options.emit.with_kernel = false;
    options.produce_spirv = false;
    Diagnostics diags;
    const CompiledScene c = compileSource(path, text, options, diags);
    ASSERT_TRUE(c.ok) << diags.format();
    std::string source = test::pointShaderSource(c.emitted);
    source = source.substr(0, source.find("\nvoid main()")) + kFieldMain;
    const SpirvResult spirv = glslToSpirv(source, ShaderStage::Fragment, "field.points.frag");
    ASSERT_TRUE(spirv.ok()) << spirv.log << "\n" << source;

    Renderer renderer(*context_, spirv.words, c.emitted.scene_data);
    gpu::FrameParams params{};
    params.cam_origin = glm::vec4(0.3f, -0.2f, 0.1f, 0);
    params.cam_right = glm::vec4(2, 2, 2, 0);
    params.cam_forward = glm::vec4(0, 0, 1, time);
    params.width = params.height = test::kPointGridSide;
    params.sample_count = 1;
    params.seed = 7;
    FloatImage pos, emission, albedo;
    renderer.renderPass(params, 60, pos, emission, albedo);
    const ir::Material& m = c.scene.materials[0];
    const ir::ColorField& f = *m.field;
    double worst = 0;
    int compared = 0;
    for (uint32_t y = 0; y < test::kPointGridSide; ++y)
      for (uint32_t x = 0; x < test::kPointGridSide; ++x) {
        const float* q = pos.at(x, y);
        const dvec3 p(q[0], q[1], q[2]);
        if (nearJump(f, p, time)) continue;
        const dvec3 n = glm::normalize(p - dvec3(glm::vec3(0.3f, -0.2f, 0.1f)) + dvec3(1e-3));
        const dvec3 want = materialColor(m, p, n, time);
        const float* got = m.model == ir::MaterialModel::Emissive ? emission.at(x, y) : albedo.at(x, y);
        for (int i = 0; i < 3; ++i) worst = std::max(worst, std::fabs(got[i] - want[i]));
        ++compared;
      }
    EXPECT_GT(compared, 3500);
    EXPECT_LE(worst, tolerance);
    std::printf("  %s: %d points, worst |gpu - cpu| %.3g\n", ir::fieldKindName(f.kind), compared, worst);
  }

  static bool nearJump(const ir::ColorField& f, const dvec3& p, double time) {
    const double edge = 1e-4;
    auto nearWhole = [&](double u) { return std::fabs(u - std::round(u)) < edge; };
    const double size = f.size.at(time);
    switch (f.kind) {
      case ir::FieldKind::Checker:
        return nearWhole(p.x / size) || nearWhole(p.y / size) || nearWhole(p.z / size);
      case ir::FieldKind::Stripes: {
        const double u = glm::dot(p, f.axis) / size;
        return nearWhole(u) || nearWhole(u - 0.5);
      }
      default: return false;
    }
  }

  static VulkanContext* context_;
};

VulkanContext* ColorFieldGpu::context_ = nullptr;

TEST_F(ColorFieldGpu, EachFieldMatchesTheFloat64Field) {
  const std::string shape = "\nscene { sphere(radius: 1, material: m) }";
  check("let m = diffuse(albedo: checker([0.9, 0.8, 0.7], [0.1, 0.2, 0.3], size: 0.37))" + shape, 1e-7);
  check("let m = mirror(tint: stripes([0.9, 0.8, 0.7], [0.1, 0.2, 0.3], axis: [1, 2, -1], period: 0.3 + time))" + shape, 1e-7);
  check("let m = metal(albedo: gradient([0.9, 0.8, 0.7], [0.1, 0.2, 0.3], axis: [0, 1, 1], from: -1, to: 1.5))" + shape,
        2e-6);
  check("let m = diffuse(albedo: noise([0.9, 0.8, 0.7], [0.1, 0.2, 0.3], scale: 2.5, octaves: 5))" + shape, 2e-5);
  check("let m = emissive(color: noise([1, 0.5, 0], [0, 0.5, 1], scale: 1 + time, octaves: 1), strength: 3)" + shape,
        6e-5);
  const std::filesystem::path dir = writeTestTexture();
  check("let m = diffuse(albedo: texture(file: \"ramp.exr\", size: 0.7 + time))" + shape, 2e-5, 0.7f,
        (dir / "scene.sdf").string());
}

}  // namespace
}  // namespace sdfc
