// One test per optimization of the back end, each proving that it happened
// (in the IR, the emitted text or the counted work) and that the image does
// not change beyond Monte Carlo noise.
#include <gtest/gtest.h>

#include <regex>

#include "driver/compile.h"
#include "image_io.h"
#include "scene_render.h"
#include "vulkan_context.h"

namespace sdfc {
namespace {

CompiledScene compileText(const std::string& text, CompileOptions options = {}) {
  Diagnostics diags;
  CompiledScene c = compileSource("t.sdf", text, options, diags);
  EXPECT_TRUE(c.ok) << diags.format();
  return c;
}

size_t count(const std::string& haystack, const std::string& needle) {
  size_t n = 0;
  for (size_t at = haystack.find(needle); at != std::string::npos; at = haystack.find(needle, at + 1)) ++n;
  return n;
}

// The body of one emitted function, for checks on what it evaluates.
std::string functionBody(const std::string& glsl, const std::string& signature) {
  const size_t start = glsl.find(signature);
  if (start == std::string::npos) return "";
  return glsl.substr(start, glsl.find("\n}\n", start) - start);
}

const char* kCsgScene = R"(
camera(position: [0, 2, 6], target: [0, 0.5, 0])
sky(color: [0.7, 0.8, 0.9])
scene {
  plane(normal: [0, 1, 0])
  translate([1.5, 0.5, 0]) { rotate(axis: [0, 1, 0], degrees: 30) { scale(0.5) { box(size: [1, 1, 1]) } } }
  translate([-1.5, 0.6, 0]) {
    union { sphere(radius: 0.5) translate([0, 0.6, 0]) { sphere(radius: 0.3) } torus(major: 0.6, minor: 0.1) }
  }
}
)";

TEST(Optimizations, TransformChainsFuseIntoOneAffineMap) {
  CompileOptions fused, unfused;
  unfused.fuse_transforms = false;
  const std::string ir = ir::dump(compileText(kCsgScene, fused).scene);
  const std::string raw = ir::dump(compileText(kCsgScene, unfused).scene);
  // translate -> rotate -> scale is one affine node with the scale folded in.
  EXPECT_NE(ir.find("affine linear="), std::string::npos) << ir;
  EXPECT_NE(ir.find("scale=0.5"), std::string::npos) << ir;
  EXPECT_EQ(count(ir, "rotate"), 0u) << ir;
  EXPECT_EQ(count(raw, "rotate"), 1u) << raw;
  EXPECT_LT(count(ir, "\n"), count(raw, "\n"));
}

TEST(Optimizations, IdentityTransformsVanish) {
  const std::string ir =
      ir::dump(compileText("scene { translate([0, 0, 0]) { rotate(axis: [1, 0, 0], degrees: 0) { sphere(radius: 1) } } }").scene);
  EXPECT_EQ(count(ir, "affine"), 0u) << ir;
  EXPECT_EQ(count(ir, "translate"), 0u) << ir;
}

TEST(Optimizations, OnlyUsedPrimitivesAndMaterialModelsAreEmitted) {
  const std::string glsl = compileText(kCsgScene).emitted.glsl;
  EXPECT_NE(glsl.find("float sdBox("), std::string::npos);
  EXPECT_EQ(glsl.find("float sdCone("), std::string::npos);
  EXPECT_EQ(glsl.find("sdMenger"), std::string::npos);
  // No glass, mirror or metal: none of their code, no refraction at all.
  EXPECT_EQ(glsl.find("refract("), std::string::npos);
  EXPECT_EQ(glsl.find("fresnelDielectric"), std::string::npos);
  EXPECT_EQ(glsl.find("MAT_GLASS)"), std::string::npos);
  EXPECT_EQ(glsl.find("ggx"), std::string::npos);
  EXPECT_EQ(glsl.find("Ggx"), std::string::npos);
  // A static scene never reads the time; no sun means no sun code.
  EXPECT_EQ(glsl.find("cam_forward.w"), std::string::npos);
  EXPECT_EQ(glsl.find("kSunDir"), std::string::npos);
  EXPECT_EQ(glsl.find("#ifdef SDFC_"), std::string::npos) << "feature blocks must be resolved";

  const std::string glass = compileText(
      "sun(direction: [0, 1, 0])\nscene { sphere(radius: 1, material: glass(ior: 1.5)) "
      "translate([0, sin(time), 0]) { box(size: [1, 1, 1]) } }").emitted.glsl;
  EXPECT_NE(glass.find("refract("), std::string::npos);
  EXPECT_NE(glass.find("cam_forward.w"), std::string::npos);
  EXPECT_NE(glass.find("kSunDir"), std::string::npos);
  EXPECT_GT(glass.size(), glsl.size());
}

TEST(Optimizations, PlanesAreIntersectedAnalyticallyNotMarched) {
  const std::string glsl = compileText(kCsgScene).emitted.glsl;
  EXPECT_NE(glsl.find("float sdPlanesHit("), std::string::npos);
  EXPECT_EQ(functionBody(glsl, "float sdScene(vec3 p)").find("sdPlane("), std::string::npos);
  CompileOptions marched;
  marched.emit.analytic_planes = false;
  const std::string plain = compileText(kCsgScene, marched).emitted.glsl;
  EXPECT_NE(functionBody(plain, "float sdScene(vec3 p)").find("sdPlane("), std::string::npos);
}

// With every child a plane, sdScene keeps a far placeholder; nodes the
// compiler makes have no source line, and their comments must stay comments.
TEST(Optimizations, APlaneOnlySceneStillCompiles) {
  const CompiledScene c = compileText("scene { plane(normal: [0, 1, 0]) }");
  EXPECT_FALSE(c.spirv.empty());
  EXPECT_NE(c.emitted.glsl.find("float sdPlanesHit("), std::string::npos);
}

TEST(Optimizations, MengerIsUnrolledToItsLevel) {
  const std::string glsl = compileText("scene { menger(level: 3, size: 1) }").emitted.glsl;
  const std::string body = functionBody(glsl, "float sdMenger3(");
  ASSERT_FALSE(body.empty());
  EXPECT_EQ(body.find("for ("), std::string::npos);  // a loop would count against lavapipe's cap
  EXPECT_EQ(count(body, "cell /= 3.0"), 2u);
}

TEST(Optimizations, NamedShapesBecomeOneFunctionCalledAtEachUse) {
  const std::string glsl = compileText(
      "let post = union { box(size: [0.2, 2, 0.2]) translate([0, 1, 0]) { sphere(radius: 0.2) } }\n"
      "scene { translate([1, 0, 0]) { post } translate([-1, 0, 0]) { post } }").emitted.glsl;
  EXPECT_EQ(count(glsl, "float sd_post(vec3 p)"), 1u);
  EXPECT_EQ(count(functionBody(glsl, "float sdScene(vec3 p)"), "sd_post("), 2u);
}

// Bounding volumes: the emitted checks exist, the counted primitive
// evaluations per pixel fall, and the image is unchanged beyond noise.
TEST(Optimizations, BoundingVolumesSkipWorkWithoutChangingTheImage) {
  const std::string scene = std::string(R"(
camera(position: [0, 3, 9], target: [0, 0.5, 0], fov: 40)
sky(color: [0.8, 0.85, 0.9])
sun(direction: [0.3, 1, 0.4])
let tower = union { cylinder(radius: 0.4, height: 2) translate([0, 1.3, 0]) { cone(radius: 0.5, height: 0.8) }
                    translate([0, 0.8, 0]) { torus(major: 0.45, minor: 0.08) } }
scene {
  plane(normal: [0, 1, 0])
  translate([-2, 1, 0]) { tower } translate([0, 1, 0]) { tower } translate([2, 1, 0]) { tower }
  translate([0, 0.5, 3]) { union { sphere(radius: 0.5) box(size: [2, 0.2, 0.2]) box(size: [0.2, 0.2, 2]) } }
}
)");
  CompileOptions bounded, unbounded;
  unbounded.emit.bounding_volumes = false;
  bounded.emit.count_evaluations = unbounded.emit.count_evaluations = true;
  bounded.emit.march.image_height = unbounded.emit.march.image_height = 48;
  const CompiledScene with = compileText(scene, bounded);
  const CompiledScene without = compileText(scene, unbounded);
  EXPECT_GE(with.emitted.stats.bounded_subtrees, 3);
  EXPECT_NE(with.emitted.glsl.find("sdBound("), std::string::npos);
  EXPECT_EQ(without.emitted.glsl.find("sdBound("), std::string::npos);

  VulkanContext context;
  createContext(context);
  RenderOverrides o;
  o.width = 64;
  o.height = 48;
  auto work = [&](const CompiledScene& c) {
    Renderer renderer(context, c);
    RenderOverrides v = o;
    v.view = gpu::kViewIterations;
    v.spp = 1;
    v.bounces = 0;
    const FloatImage it = renderer.render(cameraFor(c.scene), renderSettingsFor(c, v)).color;
    double sum = 0;
    for (uint32_t i = 0; i < it.width * it.height; ++i) sum += it.rgba[i * 4];
    return sum / (it.width * it.height);
  };
  const double work_with = work(with), work_without = work(without);
  EXPECT_LT(work_with, 0.5 * work_without) << "loop iterations + primitive evaluations per pixel";
  std::printf("[ bounds   ] counted work per pixel: %.1f with bounds, %.1f without (%.2fx)\n", work_with,
              work_without, work_with / work_without);

  // Same image: the difference is below the noise between two seeds.
  auto image = [&](const CompiledScene& c, uint32_t seed) {
    Renderer renderer(context, c);
    RenderOverrides v = o;
    v.spp = 16;
    v.seed = seed;
    return renderer.render(cameraFor(c.scene), renderSettingsFor(c, v)).color;
  };
  CompileOptions plain_bounded, plain_unbounded;
  plain_unbounded.emit.bounding_volumes = false;
  plain_bounded.emit.march.image_height = plain_unbounded.emit.march.image_height = 48;
  const CompiledScene a = compileText(scene, plain_bounded), b = compileText(scene, plain_unbounded);
  const FloatImage ia = image(a, 0), ib = image(b, 0), ib2 = image(b, 1);
  EXPECT_LE(relMse(ia, ib), 0.5 * relMse(ib2, ib)) << "bounds changed the image beyond noise";
  destroyContext(context);
  EXPECT_EQ(validationMessageCount(), 0);
}

// The scene box: rays march only inside the box around the marched part, so
// rays that miss the scene take no steps; the image does not change.
TEST(Optimizations, SceneBoxCutsStepsWithoutChangingTheImage) {
  const std::string scene = R"(
camera(position: [0, 2, 9], target: [0, 0.5, 0], fov: 40)
sky(color: [0.8, 0.85, 0.9])
scene {
  plane(normal: [0, 1, 0])
  translate([-1, 0.6, 0]) { sphere(radius: 0.6) }
  translate([1, 0.5, 0]) { box(size: 1) }
}
)";
  CompileOptions boxed, unboxed;
  unboxed.emit.scene_box = false;
  boxed.emit.march.image_height = unboxed.emit.march.image_height = 48;
  const CompiledScene with = compileText(scene, boxed), without = compileText(scene, unboxed);
  EXPECT_NE(with.emitted.glsl.find("kSceneBoxLo"), std::string::npos);
  EXPECT_EQ(without.emitted.glsl.find("kSceneBoxLo"), std::string::npos);
  // An unbounded part (a repetition without limits) gets no box.
  EXPECT_EQ(compileText("scene { repeat(cell: [2, 0, 2]) { sphere(radius: 0.5) } }")
                .emitted.glsl.find("kSceneBoxLo"),
            std::string::npos);

  VulkanContext context;
  createContext(context);
  RenderOverrides o;
  o.width = 64;
  o.height = 48;
  auto iterations = [&](const CompiledScene& c) {
    Renderer renderer(context, c);
    RenderOverrides v = o;
    v.view = gpu::kViewIterations;
    v.spp = 1;
    v.bounces = 1;
    const FloatImage it = renderer.render(cameraFor(c.scene), renderSettingsFor(c, v)).color;
    double sum = 0;
    for (uint32_t i = 0; i < it.width * it.height; ++i) sum += it.rgba[i * 4];
    return sum / (it.width * it.height);
  };
  const double work_with = iterations(with), work_without = iterations(without);
  EXPECT_LT(work_with, 0.7 * work_without) << "loop iterations per pixel";
  std::printf("[ box      ] loop iterations per pixel: %.1f with the scene box, %.1f without\n", work_with,
              work_without);
  auto image = [&](const CompiledScene& c, uint32_t seed) {
    Renderer renderer(context, c);
    RenderOverrides v = o;
    v.spp = 16;
    v.seed = seed;
    return renderer.render(cameraFor(c.scene), renderSettingsFor(c, v)).color;
  };
  const FloatImage ia = image(with, 0), ib = image(without, 0), ib2 = image(without, 1);
  EXPECT_LE(relMse(ia, ib), 0.5 * relMse(ib2, ib)) << "the scene box changed the image beyond noise";
  destroyContext(context);
  EXPECT_EQ(validationMessageCount(), 0);
}


// Spheres directly in the scene (bare or under a rigid transform and uniform
// scale) are intersected in closed form like planes: sdScene leaves them out,
// emissive spheres and any sphere in a scene with glass stay marched, the loop
// work falls, and the image
// and its depth/normal AOVs match the marched ones (tests/accuracy_test.cpp
// checks them against an exact ray caster).
TEST(Optimizations, SpheresAreIntersectedAnalyticallyNotMarched) {
  const std::string scene = R"(
camera(position: [0, 2, 9], target: [0, 0.5, 0], fov: 40)
sky(color: [0.8, 0.85, 0.9])
scene {
  plane(normal: [0, 1, 0])
  translate([-1, 0.6, 0]) { sphere(radius: 0.6, material: metal(albedo: [0.9, 0.8, 0.6], roughness: 0.3)) }
  translate([1.2, 0.5, 0]) { rotate(axis: [0, 1, 1], degrees: 40) { scale(0.5) { sphere(radius: 1) } } }
  translate([0, 0.3, 1.5]) { box(size: 0.6) }
}
)";
  CompileOptions analytic, marched;
  marched.emit.analytic_spheres = false;
  analytic.emit.march.image_height = marched.emit.march.image_height = 48;
  const CompiledScene with = compileText(scene, analytic), without = compileText(scene, marched);
  EXPECT_EQ(functionBody(with.emitted.glsl, "float sdScene(vec3 p)").find("sdSphere("), std::string::npos);
  EXPECT_NE(functionBody(without.emitted.glsl, "float sdScene(vec3 p)").find("sdSphere("), std::string::npos);
  EXPECT_NE(functionBody(with.emitted.glsl, "float sdScene(vec3 p)").find("sdBox("), std::string::npos);
  for (const char* kept : {"scene { sphere(radius: 1, material: glass(ior: 1.5)) }",
                           "scene { sphere(radius: 1, material: emissive(color: [1, 1, 1], strength: 2)) }",
                           "scene { scale([1, 2, 1]) { sphere(radius: 1) } }",
                           "scene { sphere(radius: 1) translate([0, 1.5, 0]) { box(size: 1, material: glass(ior: 1.5)) } }",
                           "scene { union { sphere(radius: 1) box(size: 1) } }"})
    EXPECT_NE(functionBody(compileText(kept).emitted.glsl, "float sdScene(vec3 p)").find("sdSphere("),
              std::string::npos)
        << kept;

  VulkanContext context;
  createContext(context);
  RenderOverrides o;
  o.width = 64;
  o.height = 48;
  auto render = [&](const CompiledScene& c, int view, uint32_t spp, uint32_t seed) {
    Renderer renderer(context, c);
    RenderOverrides v = o;
    v.view = view;
    v.spp = spp;
    v.seed = seed;
    v.bounces = view == gpu::kViewIterations ? 1 : 3;
    return renderer.render(cameraFor(c.scene), renderSettingsFor(c, v));
  };
  auto mean = [](const FloatImage& img) {
    double sum = 0;
    for (uint32_t i = 0; i < img.width * img.height; ++i) sum += img.rgba[i * 4];
    return sum / (img.width * img.height);
  };
  const double work_with = mean(render(with, gpu::kViewIterations, 1, 0).color);
  const double work_without = mean(render(without, gpu::kViewIterations, 1, 0).color);
  std::printf("[ spheres  ] loop iterations per pixel: %.1f analytic, %.1f marched\n", work_with, work_without);
  EXPECT_LT(work_with, work_without) << "loop iterations per pixel";
  const RenderOutput a = render(with, gpu::kViewBeauty, 16, 0), b = render(without, gpu::kViewBeauty, 16, 0);
  const FloatImage b2 = render(without, gpu::kViewBeauty, 16, 1).color;
  EXPECT_LE(relMse(a.color, b.color), 0.5 * relMse(b2, b.color)) << "analytic spheres changed the image";
  // First-hit AOVs: the same surface at each pixel, to the march's hit band.
  int depth_off = 0, normal_off = 0, hits = 0;
  for (uint32_t i = 0; i < a.normal_depth.width * a.normal_depth.height; ++i) {
    const float* na = &a.normal_depth.rgba[i * 4];
    const float* nb = &b.normal_depth.rgba[i * 4];
    if (na[3] < 0 || nb[3] < 0) {
      depth_off += (na[3] < 0) != (nb[3] < 0);
      continue;
    }
    ++hits;
    depth_off += std::fabs(na[3] - nb[3]) > 1e-3f * std::max(1.0f, nb[3]);
    normal_off += na[0] * nb[0] + na[1] * nb[1] + na[2] * nb[2] < std::cos(glm::radians(2.0f));
  }
  std::printf("[ spheres  ] %d first hits: depth off %d, normal off by > 2 deg %d\n", hits, depth_off, normal_off);
  EXPECT_GT(hits, 0);
  EXPECT_LE(depth_off, hits / 200) << "first-hit depth differs from the marched sphere";
  EXPECT_LE(normal_off, hits / 200) << "first-hit normal differs from the marched sphere";
  destroyContext(context);
  EXPECT_EQ(validationMessageCount(), 0);
}

}  // namespace
}  // namespace sdfc
