// Issue 49: rays that graze a silhouette. A ray passing a surface within the
// hit band is a near miss (pathtrace.glsl); past it, the ray must still find
// what lies behind, even when the grazing ate most of its step budget. Every
// subject below stands in a hollow sphere (a room), so every primary ray ends
// on a surface: a pixel drawn as sky where the float64 march finds one is a
// hole. A hit must lie on the float64 surface within the pixel's footprint
// (no real miss turned into a hit off the surface).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

#include "camera.h"
#include "driver/compile.h"
#include "eval/evaluator.h"
#include "mesh_soup.h"
#include "scene_render.h"
#include "vulkan_context.h"

namespace sdfc {
namespace {

using glm::dvec3;

// A torus of `major` and `minor` radii in the xz plane as a closed, outward
// triangle mesh of `around` x `across` quads split in two.
test::Soup torusMesh(double major, double minor, int around, int across) {
  test::Soup s;
  const double pi = std::acos(-1.0);
  for (int i = 0; i < around; ++i)
    for (int j = 0; j < across; ++j) {
      const double u = 2 * pi * i / around, v = 2 * pi * j / across;
      const double r = major + minor * std::cos(v);
      s.v.push_back({r * std::cos(u), minor * std::sin(v), r * std::sin(u)});
    }
  auto at = [&](int i, int j) { return unsigned((i % around) * across + j % across); };
  for (int i = 0; i < around; ++i)
    for (int j = 0; j < across; ++j) {
      const unsigned a = at(i, j), b = at(i + 1, j), c = at(i + 1, j + 1), d = at(i, j + 1);
      s.f.push_back({a, d, c});
      s.f.push_back({a, c, b});
    }
  return s;
}

std::string scratchDir() {
  static const std::string dir = [] {
    std::string d = std::filesystem::temp_directory_path() / ("sdfc_grazing_" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir;
}

struct Subject {
  std::string name, shape;
  MeshMode mesh_mode = MeshMode::Auto;
};

// Every primitive kind (a plane as the cut of a sphere: alone it is analytic,
// not marched), two profiles, a torus mesh in both shader modes, and an
// instance group, each about a unit in size at the origin.
std::vector<Subject> subjects() {
  std::vector<Subject> s = {
      {"sphere", "sphere(radius: 0.9)"},
      {"box", "rotate(euler: [20, 35, 10]) { box(size: [1.2, 0.9, 1.1]) }"},
      {"rounded box", "rotate(euler: [10, 25, 0]) { box(size: [1.3, 1, 1], rounding: 0.2) }"},
      {"torus", "rotate(euler: [60, 10, 0]) { torus(major: 0.8, minor: 0.25) }"},
      {"cylinder", "rotate(euler: [15, 0, 25]) { cylinder(radius: 0.6, height: 1.4) }"},
      {"cone", "translate([0, -0.6, 0]) { cone(radius: 0.7, height: 1.3) }"},
      {"capsule", "rotate(euler: [0, 0, 70]) { capsule(radius: 0.4, height: 1.2) }"},
      {"prism", "rotate(euler: [0, 30, 0]) { prism(size: 1.5, depth: 1) }"},
      {"hexprism", "rotate(euler: [20, 40, 0]) { hexprism(radius: 0.6, depth: 1.1) }"},
      {"menger", "rotate(euler: [0, 20, 0]) { menger(level: 2, size: 1.5) }"},
      {"octahedron", "octahedron(radius: 1)"},
      {"pyramid", "translate([0, -0.6, 0]) { pyramid(size: 1.3, height: 1.2) }"},
      {"round_cone", "translate([0, -0.5, 0]) { round_cone(bottom: 0.5, top: 0.2, height: 1) }"},
      {"ellipsoid", "ellipsoid(radii: [1, 0.6, 0.8])"},
      {"plane cut", "intersect { sphere(radius: 1) plane(normal: [0.3, 1, 0.2], offset: 0.2) }"},
      {"revolve", "revolve(offset: 0.6) { circle(radius: 0.3) }"},
      {"extrude", "extrude(depth: 0.8) { polygon(points: [[-0.8, -0.6], [0.9, -0.5], [0.1, 0.8]]) }"},
      {"instances",
       "instances(positions: [[-0.7, 0, 0], [0.7, 0.1, 0], [0, 0.6, 0.3], [0, -0.6, -0.3], [0.2, 0, 0.8]]) {"
       " sphere(radius: 0.35) box(size: [0.5, 0.2, 0.5]) }"},
  };
  const std::string torus = scratchDir() + "/torus.obj";
  std::ofstream(torus, std::ios::binary) << test::obj(torusMesh(0.8, 0.3, 72, 36));
  s.push_back({"torus mesh (exact)", "mesh(file: \"" + torus + "\")", MeshMode::Exact});
  s.push_back({"torus mesh (grid)", "mesh(file: \"" + torus + "\")", MeshMode::Grid});
  return s;
}

class GrazingGpu : public ::testing::Test {
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
  static VulkanContext* context_;

  struct Verdict {
    int pixels = 0, sky = 0, off = 0, out_of_steps = 0;
    // Hits whose float64 field is beyond the hit band (a quarter pixel), and of
    // those the ones the float64 march passes (a false hit at a silhouette).
    int beyond_band = 0, false_hits = 0;
    double worst = 0, worst_band = 0;
  };

  // The subject in the room, seen from `cameras` at w x h; every pixel
  // checked against the float64 march.
  static Verdict check(const Subject& subject, const std::vector<dvec3>& cameras, uint32_t w, uint32_t h) {
    const std::string text = "camera(position: [3, 1, 3], target: [0, 0, 0], fov: 40)\nscene {\n  union {\n    " +
                             subject.shape +
                             "\n    subtract { sphere(radius: 9) sphere(radius: 8) }\n  }\n}\n";
    CompileOptions options;
    options.emit.march.image_height = h;
    options.check.mesh_mode = subject.mesh_mode;
    Diagnostics diags;
    const CompiledScene c = compileSource(scratchDir() + "/grazing.sdf", text, options, diags);
    EXPECT_TRUE(c.ok) << subject.name << "\n" << diags.format();
    Verdict v;
    if (!c.ok) return v;
    const Evaluator eval(c.scene);
    Renderer r(*context_, c);
    RenderOverrides o;
    o.width = int(w);
    o.height = int(h);
    o.spp = 1;
    o.view = gpu::kViewDepth;
    const RenderSettings settings = renderSettingsFor(c, o);
    for (const dvec3& position : cameras) {
      CameraDesc camera = cameraFor(c.scene);
      camera.position = glm::vec3(position);
      const RenderOutput out = r.render(camera, settings);
      const gpu::FrameParams f = makeFrameParams(camera, w, h, 0);
      const dvec3 ro(f.cam_origin), right(f.cam_right), up(f.cam_up), forward(f.cam_forward);
      const double tan_half = f.cam_origin.w, aspect = double(w) / h;
      auto footprint = [&](double t) { return std::max(t, 1e-3) * 2 * tan_half / h; };
      for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
          const double nx = 2.0 * (x + 0.5) / w - 1, ny = 1 - 2.0 * (y + 0.5) / h;
          const dvec3 rd = glm::normalize(forward + (nx * aspect * tan_half) * right + (ny * tan_half) * up);
          // The float64 march (many_parts_test.cpp): a stop within a quarter
          // footprint is a hit when the ray goes clearly inside within 4
          // footprints, else a near miss passed by half a footprint.
          double t64 = 0;
          bool hit64 = false;
          for (int i = 0; i < 20000 && t64 < 20 && !hit64; ++i) {
            const double d = eval.distance(ro + rd * t64), fp = footprint(t64);
            if (d >= 0.25 * fp) {
              t64 += d;
              continue;
            }
            for (int j = 0; j <= 8 && !hit64; ++j) hit64 = eval.distance(ro + rd * (t64 + 0.5 * j * fp)) < -0.5 * fp;
            if (!hit64) t64 += std::max(d, 0.5 * fp);
          }
          ++v.pixels;
          v.out_of_steps += out.albedo_steps.at(x, y)[3] >= c.emitted.limits.max_steps;
          const double depth = out.normal_depth.at(x, y)[3];
          if (depth < 0) {
            if (hit64) {
              if (v.sky < 3 && std::getenv("SDFC_DEBUG_PIXELS"))
                std::printf("sky pixel %u,%u of %s: float64 hit at %g, steps %g\n", x, y, subject.name.c_str(), t64,
                            out.albedo_steps.at(x, y)[3]);
              ++v.sky;
            }
            continue;
          }
          const double fp = footprint(depth), field = std::fabs(eval.distance(ro + rd * depth));
          v.worst = std::max(v.worst, field / fp);
          v.off += field > fp;
          const double band = 0.25 * fp;
          v.worst_band = std::max(v.worst_band, field / band);
          if (field > band) {
            ++v.beyond_band;
            const bool passed = !hit64 || t64 > depth + fp;
            v.false_hits += passed;
            if (v.beyond_band <= 3 && std::getenv("SDFC_DEBUG_PIXELS"))
              std::printf("beyond the band: pixel %u,%u of %s: depth %.6g field %.3g (%.3g bands), float64 %s at %.6g\n",
                          x, y, subject.name.c_str(), depth, field, field / band, hit64 ? "hit" : "miss", t64);
          }
        }
    }
    std::printf("[ grazing  ] %s at %ux%u: %d pixels, %d sky where float64 hits, %d off the surface (worst %.3g "
                "footprints), %d beyond the hit band (worst %.3g bands), %d false hits, %d out of steps (budget %d)\n",
                subject.name.c_str(), w, h, v.pixels, v.sky, v.off, v.worst, v.beyond_band, v.worst_band,
                v.false_hits, v.out_of_steps, int(c.emitted.limits.max_steps));
    return v;
  }
};

VulkanContext* GrazingGpu::context_ = nullptr;

const std::vector<dvec3> kCameras = {{3, 1, 3}, {-3.4, 0.4, 1.8}, {0.6, 3.6, 1.4}};

TEST_F(GrazingGpu, NoSkyBehindGrazedSilhouettes) {
  for (const Subject& s : subjects()) {
    const Verdict v = check(s, kCameras, 160, 90);
    EXPECT_EQ(v.sky, 0) << s.name;
    EXPECT_EQ(v.off, 0) << s.name;
  }
}

// The same at 640x360 (a narrower band, a larger budget) for a curved
// primitive, meshes and an instance group, from one camera; the grid mesh
// also level with the torus's plane, through its hole.
TEST_F(GrazingGpu, NoSkyBehindGrazedSilhouettesAt640x360) {
  for (const Subject& s : subjects()) {
    if (s.name != "ellipsoid" && s.name != "capsule" && s.name != "instances" && s.name.find("mesh") == std::string::npos)
      continue;
    std::vector<dvec3> cameras = {kCameras[0]};
    if (s.name == "torus mesh (grid)") cameras.push_back({3.2, 0.05, 0.4});
    const Verdict v = check(s, cameras, 640, 360);
    EXPECT_EQ(v.sky, 0) << s.name;
    EXPECT_EQ(v.off, 0) << s.name;
  }
}

// Issue 49: the exact mesh mode is the nearest triangle's distance, so its
// hits lie within the hit band (a quarter pixel) of the float64 surface, and
// no ray that the float64 march passes by a silhouette hits it. A 5k-triangle
// torus and icosphere at 640x360, from cameras near and far, level with the
// torus's plane and through its hole. On a driver that caps loops the search
// is rationed to a few visits per evaluation (9 here): out of visits it was
// the grid's value, within the grid's bound, and with these cameras and two
// more 76,967 and 8,163 hits lay beyond the band (up to 131 bands); now it is
// a lower bound march() never stops on, and a visit descends to a leaf, so
// the search ends in budget. (The grid mode, within its stated bound, not the
// band, is not tested here: from those 7 cameras 66,558 of its torus hits are
// beyond the band, up to 5.6 bands.)
TEST_F(GrazingGpu, ExactMeshHitsLieWithinTheHitBand) {
  const std::string ico = scratchDir() + "/ico4.stl";
  std::ofstream(ico, std::ios::binary) << test::binaryStl(test::icosphere(4, 0.9));
  const std::string torus = scratchDir() + "/torus.obj";
  std::ofstream(torus, std::ios::binary) << test::obj(torusMesh(0.8, 0.3, 72, 36));
  const std::vector<Subject> meshes = {
      {"torus mesh (exact)", "mesh(file: \"" + torus + "\")", MeshMode::Exact},
      {"icosphere mesh (exact)", "mesh(file: \"" + ico + "\")", MeshMode::Exact},
  };
  const std::vector<dvec3> cameras = {{3, 1, 3}, {3.2, 0.05, 0.4}, {0.3, 2.2, 0.2}, {1.3, 0.31, 0}, {0.2, -1.4, 1.1}};
  const uint32_t w = 640, h = 360;
  for (const Subject& subject : meshes) {
    const std::string text = "camera(position: [3, 1, 3], target: [0, 0, 0], fov: 40)\nscene {\n  union {\n    " +
                             subject.shape + "\n    subtract { sphere(radius: 9) sphere(radius: 8) }\n  }\n}\n";
    CompileOptions options;
    options.emit.march.image_height = h;
    options.check.mesh_mode = subject.mesh_mode;
    Diagnostics diags;
    const CompiledScene c = compileSource(scratchDir() + "/band.sdf", text, options, diags);
    ASSERT_TRUE(c.ok) << subject.name << "\n" << diags.format();
    const Evaluator eval(c.scene);
    Renderer r(*context_, c);
    RenderOverrides o;
    o.width = int(w);
    o.height = int(h);
    o.spp = 1;
    o.view = gpu::kViewDepth;
    const RenderSettings settings = renderSettingsFor(c, o);
    int hits = 0, beyond = 0, false_hits = 0, bound_only_sky = 0;
    double worst = 0;
    for (const dvec3& position : cameras) {
      CameraDesc camera = cameraFor(c.scene);
      camera.position = glm::vec3(position);
      const RenderOutput out = r.render(camera, settings);
      const gpu::FrameParams f = makeFrameParams(camera, w, h, 0);
      const dvec3 ro(f.cam_origin), right(f.cam_right), up(f.cam_up), forward(f.cam_forward);
      const double tan_half = f.cam_origin.w, aspect = double(w) / h;
      for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
          const double nx = 2.0 * (x + 0.5) / w - 1, ny = 1 - 2.0 * (y + 0.5) / h;
          const dvec3 rd = glm::normalize(forward + (nx * aspect * tan_half) * right + (ny * tan_half) * up);
          const double depth = out.normal_depth.at(x, y)[3];
          if (depth < 0) {
            ++bound_only_sky;  // the room is behind every ray
            continue;
          }
          if (glm::length(ro + rd * depth) > 7) continue;  // the room
          ++hits;
          // The kernel's band: a quarter pixel at t (hitEps; float's is far below).
          const double band = depth * c.emitted.limits.pixel_cone, field = std::fabs(eval.distance(ro + rd * depth));
          worst = std::max(worst, field / band);
          if (field <= band) continue;
          ++beyond;
          // A false hit: the float64 march (stop within a band, confirmed by
          // going clearly inside within 8 bands) passes this point.
          double t = 0;
          bool hit = false;
          for (int i = 0; i < 20000 && t < depth + 4 * band && !hit; ++i) {
            const double d = eval.distance(ro + rd * t), b = std::max(t, 1e-3) * c.emitted.limits.pixel_cone;
            if (d >= b) {
              t += d;
              continue;
            }
            for (int j = 0; j <= 16 && !hit; ++j) hit = eval.distance(ro + rd * (t + 0.5 * j * b)) < -b;
            if (!hit) t += std::max(d, b);
          }
          const bool passed = !hit || t > depth + 4 * band;
          false_hits += passed;
          if (beyond <= 4 && std::getenv("SDFC_DEBUG_PIXELS"))
            std::printf("beyond the band: %s from %g %g %g, pixel %u,%u: depth %.6g, field %.3g (%.3g bands), float64 "
                        "%s at %.6g\n",
                        subject.name.c_str(), position.x, position.y, position.z, x, y, depth, field, field / band,
                        hit ? "hit" : "miss", t);
        }
    }
    RenderSettings on_driver = settings;
    on_driver.loop_cap = context_->loop_cap;
    std::printf("[ grazing  ] %s at %ux%u, %zu cameras: %d hits, %d beyond the hit band (worst %.3g bands), %d false "
                "hits, %d sky (visits per evaluation %u)\n",
                subject.name.c_str(), w, h, cameras.size(), hits, beyond, worst, false_hits, bound_only_sky,
                traversalVisitsFor(on_driver, 1));
    EXPECT_GT(hits, 100000) << subject.name;
    EXPECT_EQ(beyond, 0) << subject.name;
    EXPECT_EQ(false_hits, 0) << subject.name;
    EXPECT_EQ(bound_only_sky, 0) << subject.name;
  }
}

// A camera on a box's top face looking along it: rays that leave the face at
// a grazing angle stay in its band for hundreds of steps. The steps a ray
// reports never exceed the budget (they were up to 2 over it: the branch for
// rays leaving their start surface ran on into the refinement's iterations).
TEST_F(GrazingGpu, StepsNeverExceedTheBudget) {
  const std::string text =
      "camera(position: [0, 0.5, 0], target: [10, 0.5, 0.3], fov: 40)\n"
      "scene {\n  box(size: [40, 1, 40])\n  translate([30, 3, 0]) { sphere(radius: 2) }\n}\n";
  CompileOptions options;
  options.emit.march.image_height = 90;
  Diagnostics diags;
  const CompiledScene c = compileSource("leaving.sdf", text, options, diags);
  ASSERT_TRUE(c.ok) << diags.format();
  Renderer r(*context_, c);
  RenderOverrides o;
  o.width = 160;
  o.height = 90;
  o.spp = 1;
  o.view = gpu::kViewDepth;
  const RenderOutput out = r.render(cameraFor(c.scene), renderSettingsFor(c, o));
  float most = 0;
  int at_budget = 0;
  for (uint32_t y = 0; y < 90; ++y)
    for (uint32_t x = 0; x < 160; ++x) {
      most = std::max(most, out.albedo_steps.at(x, y)[3]);
      at_budget += out.albedo_steps.at(x, y)[3] >= c.emitted.limits.max_steps;
    }
  std::printf("[ grazing  ] leaving a face: max steps %g (budget %d), %d rays at the budget\n", most,
              int(c.emitted.limits.max_steps), at_budget);
  EXPECT_GT(at_budget, 0) << "the scene no longer exhausts the budget: the test tests nothing";
  EXPECT_LE(most, float(c.emitted.limits.max_steps));
}

}  // namespace
}  // namespace sdfc
