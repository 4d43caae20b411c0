// Features through specular bounces (RenderSettings::specular_aovs,
// gpu::kAovSpecular): where a sample's first hit is specular, the jittered
// AOVs are those of the first non-specular vertex along its path. Checked in
// closed form: through a plane mirror they are the features of the mirrored
// scene seen directly (normal reflected back by the plane, albedo times the
// mirror's tint, distance the path length); the beauty image is unchanged.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "driver/compile.h"
#include "renderer.h"
#include "scene_render.h"
#include "vulkan_context.h"

namespace sdfc {
namespace {

CompiledScene compileText(const std::string& name, const std::string& text) {
  Diagnostics diags;
  CompiledScene compiled = compileSource(name, text, CompileOptions{}, diags);
  EXPECT_TRUE(compiled.ok) << diags.format();
  return compiled;
}

std::string readExample(const std::string& name) {
  std::ifstream file(std::filesystem::path(SDFC_SOURCE_DIR) / "examples" / name);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

// The camera at z = 5 looks down -z at a mirror, the plane z = 0 (tint 0.9,
// 0.8, 0.7); a clay sphere of radius 2.5 behind the camera at z = 8 is seen in it.
// Its mirror image, the sphere at z = -8 seen directly with albedo clay x tint,
// is the reference scene. Both: sun for light, sky behind.
const char* const kMirrorScene = R"(
render(size: [64, 48], spp: 8, bounces: 4)
camera(position: [0, 0, 5], target: [0, 0, 0], fov: 40)
sky(top: [0.45, 0.6, 0.9], bottom: [0.7, 0.7, 0.72])
sun(direction: [0.3, 1, 0.5], angle: 3, strength: 1.2)
scene {
  plane(normal: [0, 0, 1], offset: 0, material: mirror(tint: [0.9, 0.8, 0.7]))
  translate([0.4, 0.2, 8]) { sphere(radius: 2.5, material: diffuse(albedo: [0.6, 0.5, 0.4])) }
}
)";
const char* const kMirroredScene = R"(
render(size: [64, 48], spp: 8, bounces: 4)
camera(position: [0, 0, 5], target: [0, 0, 0], fov: 40)
sky(top: [0.45, 0.6, 0.9], bottom: [0.7, 0.7, 0.72])
sun(direction: [0.3, 1, -0.5], angle: 3, strength: 1.2)
scene {
  translate([0.4, 0.2, -8]) { sphere(radius: 2.5, material: diffuse(albedo: [0.54, 0.4, 0.28])) }
}
)";

RenderOutput renderAovs(const CompiledScene& compiled, bool jittered, bool specular, int spp = 8) {
  VulkanContext context;
  createContext(context);
  RenderOutput out;
  {
    Renderer renderer(context, compiled);
    RenderOverrides o;
    o.spp = spp;
    RenderSettings settings = renderSettingsFor(compiled, o);
    settings.jittered_aovs = jittered;
    settings.specular_aovs = specular;
    out = renderer.render(cameraFor(compiled.scene), settings);
  }
  destroyContext(context);
  return out;
}

TEST(KernelSpecularAovs, ThroughAPlaneMirrorAreTheMirroredScenes) {
  const CompiledScene mirror = compileText("mirror.sdf", kMirrorScene);
  const CompiledScene mirrored = compileText("mirrored.sdf", kMirroredScene);
  ASSERT_TRUE(mirror.ok && mirrored.ok);
  RenderOutput through = renderAovs(mirror, true, true);
  RenderOutput first = renderAovs(mirror, true, false);
  RenderOutput direct = renderAovs(mirrored, true, false);
  const size_t pixels = through.color.pixelCount();
  // Coverage before resolving: the mirror covers every pixel.
  std::vector<float> direct_coverage(pixels);
  for (size_t i = 0; i < pixels; ++i) direct_coverage[i] = direct.color.rgba[i * 4 + 3];
  resolveJitteredAovs(through);
  resolveJitteredAovs(first);
  resolveJitteredAovs(direct);
  size_t sphere = 0, sky = 0;
  for (size_t i = 0; i < pixels; ++i) {
    const float* nd = &through.normal_depth.rgba[i * 4];
    const float* as = &through.albedo_steps.rgba[i * 4];
    const float* nd_first = &first.normal_depth.rgba[i * 4];
    const float* as_first = &first.albedo_steps.rgba[i * 4];
    // Without specular_aovs: the mirror itself, facing the camera, at z = 0.
    ASSERT_NEAR(nd_first[2], 1.0f, 1e-5f) << i;
    ASSERT_NEAR(as_first[0], 0.9f, 1e-6f) << i;
    if (direct_coverage[i] == 1.0f) {
      // Every sample saw the sphere: the mirrored scene's features, its normal
      // reflected back by the plane (z negated).
      const float* nd_direct = &direct.normal_depth.rgba[i * 4];
      const float* as_direct = &direct.albedo_steps.rgba[i * 4];
      EXPECT_NEAR(nd[0], nd_direct[0], 2e-3f) << i;
      EXPECT_NEAR(nd[1], nd_direct[1], 2e-3f) << i;
      EXPECT_NEAR(nd[2], -nd_direct[2], 2e-3f) << i;
      EXPECT_NEAR(nd[3], nd_direct[3], 1e-3f * nd_direct[3]) << i;
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(as[c], as_direct[c], 1e-5f) << i;
      EXPECT_GT(nd[3], 10.5f - 1e-2f);  // the sphere's nearest point: 5 + 8 - 2.5
      ++sphere;
    } else if (direct_coverage[i] == 0.0f) {
      // Every sample's reflection missed: the mirror's own features stay.
      for (int k = 0; k < 4; ++k) EXPECT_EQ(nd[k], nd_first[k]) << i;
      for (int c = 0; c < 3; ++c) EXPECT_EQ(as[c], as_first[c]) << i;
      ++sky;
    }
  }
  EXPECT_GT(sphere, pixels / 20);
  EXPECT_GT(sky, pixels / 4);
  std::printf("through the mirror: %zu sphere pixels as the mirrored scene's, %zu sky pixels as "
              "the mirror's, of %zu\n",
              sphere, sky, pixels);
  EXPECT_EQ(validationMessageCount(), 0);
}

// The features are guides only: the beauty image is bit for bit the one of
// plain jittered AOVs and of no AOVs, on scenes with glass, smooth and rough
// metal; and the features do change where the first hit is specular.
TEST(KernelSpecularAovs, BeautyUnchanged) {
  for (const char* name : {"glass_and_metal.sdf", "glass_menger.sdf"}) {
    SCOPED_TRACE(name);
    std::string text = readExample(name);
    const CompiledScene compiled = compileText(name, text);
    ASSERT_TRUE(compiled.ok);
    VulkanContext context;
    createContext(context);
    {
      Renderer renderer(context, compiled);
      RenderOverrides o;
      o.width = 96;
      o.height = 54;
      o.spp = 6;
      RenderSettings plain = renderSettingsFor(compiled, o);
      RenderSettings jittered = plain;
      jittered.jittered_aovs = true;
      RenderSettings specular = jittered;
      specular.specular_aovs = true;
      RenderSettings split = specular;
      split.max_samples_per_pass = 4;  // passes of 4 and 2 samples
      const CameraDesc camera = cameraFor(compiled.scene);
      const RenderOutput p = renderer.render(camera, plain);
      const RenderOutput j = renderer.render(camera, jittered);
      const RenderOutput s = renderer.render(camera, specular);
      const RenderOutput t = renderer.render(camera, split);
      size_t changed = 0;
      for (size_t i = 0; i < p.color.pixelCount(); ++i) {
        for (int k = 0; k < 3; ++k) {
          ASSERT_EQ(s.color.rgba[i * 4 + k], p.color.rgba[i * 4 + k]) << i;
          ASSERT_EQ(s.color.rgba[i * 4 + k], j.color.rgba[i * 4 + k]) << i;
        }
        ASSERT_EQ(s.color.rgba[i * 4 + 3], j.color.rgba[i * 4 + 3]) << i;  // coverage
        bool differs = false;
        for (int k = 0; k < 4; ++k) {
          // Pass split independent up to float rounding.
          ASSERT_NEAR(t.normal_depth.rgba[i * 4 + k], s.normal_depth.rgba[i * 4 + k],
                      1e-4f * (1.0f + std::fabs(s.normal_depth.rgba[i * 4 + k])))
              << i;
          differs = differs || s.normal_depth.rgba[i * 4 + k] != j.normal_depth.rgba[i * 4 + k] ||
                    s.albedo_steps.rgba[i * 4 + k] != j.albedo_steps.rgba[i * 4 + k];
        }
        changed += differs;
      }
      EXPECT_GT(changed, p.color.pixelCount() / 50);
      std::printf("%s: features changed in %zu of %zu pixels, beauty identical\n", name, changed,
                  p.color.pixelCount());
    }
    destroyContext(context);
  }
  EXPECT_EQ(validationMessageCount(), 0);
}

// A kernel without specular materials ignores the request: plain jittered AOVs.
TEST(KernelSpecularAovs, NoSpecularMaterialsPlainJittered) {
  const CompiledScene compiled = compileText("diffuse_sphere.sdf", readExample("diffuse_sphere.sdf"));
  ASSERT_TRUE(compiled.ok);
  EXPECT_EQ(compiled.emitted.glsl.find("kAovSpecular"), std::string::npos);
  const RenderOutput j = renderAovs(compiled, true, false, 4);
  const RenderOutput s = renderAovs(compiled, true, true, 4);
  EXPECT_EQ(s.color.rgba, j.color.rgba);
  EXPECT_EQ(s.normal_depth.rgba, j.normal_depth.rgba);
  EXPECT_EQ(s.albedo_steps.rgba, j.albedo_steps.rgba);
  EXPECT_EQ(validationMessageCount(), 0);
}

}  // namespace
}  // namespace sdfc
