// The camera's frame (passes/rebase.cpp): a scene far from the origin seen
// from near by is moved by -origin before its constants are emitted. The
// moved scene at p - origin must be the world scene at p (float64 evaluator,
// every kind of node the move passes through or stops at, at several times);
// its camera and lights move with it, the sun and sky do not; check, eval and
// mesh (checkSource) keep world coordinates.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "driver/compile.h"
#include "eval/evaluator.h"
#include "passes/passes.h"

namespace sdfc {
namespace {

using glm::dvec3;

// Everything the move meets, about (1e5, 0, 1e5), the camera 6 away.
std::string farScene() {
  std::ostringstream s;
  s << "camera(position: [100003, 2, 100005], target: [100000, 0.5, 100000], fov: 40)\n"
       "sun(direction: [0.4, 1, 0.3])\nlight(position: [100001, 3, 100002], radius: 0.2)\n"
       "let clay = diffuse(albedo: [0.8, 0.3, 0.25])\n"
       "let post = union { cylinder(radius: 0.1, height: 1) translate([0, 0.6, 0]) { sphere(radius: 0.15) } }\n"
       "scene {\n  plane(normal: [0, 1, 0.1], offset: -0.3)\n"
       "  repeat(cell: [3, 0, 3]) { translate([0, -0.2, 0]) { box(size: [0.5, 0.2, 0.5]) } }\n"
       "  translate([100000, 0, 100000]) {\n"
       "    translate([sin(time), 0.5, 0]) { sphere(radius: 0.4, material: clay) }\n"
       "    rotate(axis: [0, 1, 0], degrees: 20 * time) { translate([1.5, 0.3, 0]) { box(size: [0.4, 0.6, 0.2]) } }\n"
       "    reflect(normal: [1, 0, 0], offset: 0.2) { translate([2, 0, 1]) { post } }\n"
       "    translate([-1, 0, -1]) { post }\n"
       "    translate([0, 0, 2]) { elongate(amount: [0.5, 0, 0]) { sphere(radius: 0.2) } }\n"
       "    translate([0, 1, -2]) { scale([2, 1, 1]) { sphere(radius: 0.3) } }\n"
       "    translate([-2, 0.5, 1]) { repeat(cell: [0.5, 0, 0], count: [3, 0, 0]) { sphere(radius: 0.1) } }\n"
       "    subtract(smooth: 0.05) { box(size: [1, 1, 1]) sphere(radius: 0.6) }\n"
       "    morph(t: 0.5 + 0.5 * sin(time)) { translate([0, 2, 0]) { box(size: [0.3, 0.3, 0.3]) } sphere(radius: 0.2) }\n"
       "  }\n  instances(positions: [";
  for (int i = 0; i < 40; ++i) s << "[" << 100000 + (i % 8) * 0.7 - 2.5 << ", 1.5, " << 100000 + (i / 8) * 0.7 - 1.5 << "], ";
  s << "[0, 0, 0]]) { box(size: [0.2, 0.2, 0.2]) }\n}\n";
  return s.str();
}

CompiledScene checked(const std::string& text) {
  Diagnostics diags;
  CompiledScene c = checkSource("far.sdf", text, {}, diags);
  EXPECT_TRUE(c.ok) << diags.format();
  return c;
}

TEST(Rebase, TheMovedSceneIsTheWorldSceneAtEveryTime) {
  const CompiledScene world = checked(farScene());
  CompiledScene moved = checked(farScene());
  ASSERT_TRUE(wantsCameraFrame(moved.scene));
  Diagnostics diags;
  rebaseToCamera(moved.scene, diags);
  EXPECT_FALSE(diags.hasErrors()) << diags.format();
  const dvec3 origin(100003, 2, 100005);
  EXPECT_EQ(moved.scene.origin, origin);
  EXPECT_EQ(moved.scene.camera.position, dvec3(0));
  EXPECT_EQ(moved.scene.camera.target, dvec3(-3, -1.5, -5));
  ASSERT_EQ(moved.scene.lights.size(), 1u);
  EXPECT_EQ(moved.scene.lights[0].position, dvec3(-2, 1, -3));
  EXPECT_EQ(moved.scene.sun->direction, world.scene.sun->direction);
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(-4, 4);
  int near = 0;
  for (double time : {0.0, 0.7, 2.5}) {
    const Evaluator a(world.scene, time), b(moved.scene, time);
    for (int i = 0; i < 3000; ++i) {
      const dvec3 p = dvec3(1e5, 0.8, 1e5) + dvec3(u(rng), u(rng) * 0.5, u(rng));
      const EvalResult wa = a.at(p), wb = b.at(p - origin);
      // float64 resolves 1e5 to 1.5e-11: the two frames round differently.
      ASSERT_NEAR(wa.distance, wb.distance, 1e-9) << "t " << time << " at " << p.x << " " << p.y << " " << p.z;
      if (std::fabs(wa.distance) > 1e-6) {
        EXPECT_EQ(wa.material, wb.material);
      }
      near += std::fabs(wa.distance) < 0.1;
    }
  }
  EXPECT_GT(near, 150);  // the points probe the surfaces (191 of 9,000 within 0.1)
}

TEST(Rebase, ScenesNearTheOriginKeepTheWorldFrame) {
  // The castle's camera: 22 from the origin, about 16 from the castle.
  const CompiledScene c = checked("camera(position: [8, 8, 22], target: [0, 2.4, 0])\nscene { sphere(radius: 1) }\n");
  EXPECT_FALSE(wantsCameraFrame(c.scene));
  CompileOptions options;
  options.produce_spirv = false;
  Diagnostics diags;
  EXPECT_EQ(compileSource("near.sdf", "camera(position: [8, 8, 22], target: [0, 2.4, 0])\nscene { sphere(radius: 1) }\n",
                          options, diags).scene.origin,
            dvec3(0));
}

// Issue 47 item 12: the scene's distance from the camera decides, not the
// target's: a target 1e9 ahead kept a scene 6 away in world coordinates.
TEST(Rebase, TheSceneNotTheTargetDecides) {
  const std::string far_scene = "scene { translate([1e6, 0, 1e6]) { sphere(radius: 1) box(size: [8, 4, 0.5]) } }\n";
  for (const char* target : {"[1000000, 0, 1000000]", "[1000000, 0, -999000000]"}) {
    const CompiledScene c =
        checked(std::string("camera(position: [1000000, 1, 1000006], target: ") + target + ")\n" + far_scene);
    EXPECT_NEAR(sceneDistanceFromCamera(c.scene), 5.1, 0.1) << target;
    EXPECT_TRUE(wantsCameraFrame(c.scene)) << target;
  }
  // Far from the origin but farther from the scene: nothing to gain.
  const CompiledScene away = checked("camera(position: [1e6, 0, 0], target: [1e6, 0, -1e9])\nscene { sphere(radius: 1) }\n");
  EXPECT_FALSE(wantsCameraFrame(away.scene));
  // A camera just above an endless floor near the origin looks at the parts
  // around the origin: the floor alone does not move the scene.
  const CompiledScene floor = checked(
      "camera(position: [0, 0.3, 10], target: [0, 0.3, -1e9])\nscene { plane(normal: [0, 1, 0]) sphere(radius: 1) }\n");
  EXPECT_NEAR(sceneDistanceFromCamera(floor.scene), 9.0, 0.1);
  EXPECT_FALSE(wantsCameraFrame(floor.scene));
}

TEST(Rebase, CompileMovesTheSceneAndCheckDoesNot) {
  CompileOptions options;
  options.produce_spirv = false;
  Diagnostics diags;
  const CompiledScene compiled = compileSource("far.sdf", farScene(), options, diags);
  ASSERT_TRUE(compiled.ok) << diags.format();
  EXPECT_EQ(compiled.scene.origin, dvec3(100003, 2, 100005));
  EXPECT_NE(ir::dump(compiled.scene).find("origin [100003, 2, 100005]"), std::string::npos);
  // The far placements became small offsets (the copy at the world origin is
  // code of its own, not in the set's data).
  float largest = 0;
  for (float v : compiled.emitted.scene_data) largest = std::max(largest, std::fabs(v));
  EXPECT_GT(largest, 0.0f);
  EXPECT_LT(largest, 1e3f);
  const CompiledScene world = checked(farScene());
  EXPECT_EQ(world.scene.origin, dvec3(0));
  EXPECT_NEAR(Evaluator(world.scene).distance(dvec3(1e5, 0.5, 1e5)), -0.4, 1e-9);
  options.camera_frame = false;
  EXPECT_EQ(compileSource("far.sdf", farScene(), options, diags).scene.origin, dvec3(0));
}

}  // namespace
}  // namespace sdfc
