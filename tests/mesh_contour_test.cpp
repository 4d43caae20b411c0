// Dual contouring: closed manifold meshes with outward winding, vertices on
// the surface, volumes near the closed forms, sharp box corners.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "driver/compile.h"
#include "mesh_quality.h"
#include "mesher.h"
#include "qef.h"

namespace sdfc {
namespace {

CompiledScene sceneFrom(const std::string& text) {
  Diagnostics diags;
  CompiledScene c = checkSource("t.sdf", text, CompileOptions{}, diags);
  EXPECT_FALSE(diags.hasErrors()) << diags.format();
  return c;
}

struct Meshed {
  CompiledScene compiled;
  MeshResult result;
};

Meshed meshOf(const std::string& text, int resolution, double voxel = 0, bool split = true) {
  Meshed m{sceneFrom(text), {}};
  MeshOptions o;
  o.resolution = resolution;
  o.voxel_size = voxel;
  o.split_patches = split;
  m.result = meshScene(m.compiled.scene, o);
  EXPECT_EQ(m.result.error, "");
  return m;
}

constexpr double kPi = std::numbers::pi;
const char* kSphere = "scene { sphere(radius: 1) }";
const char* kBox = "scene { box(size: [2, 1.5, 1]) }";
const char* kTorus = "scene { torus(major: 1, minor: 0.35) }";
const char* kBoxMinusSphere = "scene { subtract { box(size: [2, 2, 2]) sphere(radius: 1.2) } }";

// Closed, manifold, consistently wound, and wound outward (positive volume).
void expectClosedManifold(const Meshed& m, long euler) {
  const MeshTopology t = checkTopology(m.result.mesh);
  EXPECT_GT(m.result.mesh.triangles.size(), 100u);
  EXPECT_EQ(t.boundary_edges, 0u);
  EXPECT_EQ(t.non_manifold_edges, 0u);
  EXPECT_EQ(t.inconsistent_edges, 0u);
  EXPECT_EQ(t.non_manifold_vertices, 0u);
  EXPECT_EQ(t.euler, euler);  // 2 - 2 * genus
  EXPECT_GT(meshVolume(m.result.mesh), 0);
}

TEST(MeshContour, SphereIsClosedManifoldGenus0) { expectClosedManifold(meshOf(kSphere, 40), 2); }
TEST(MeshContour, BoxIsClosedManifoldGenus0) { expectClosedManifold(meshOf(kBox, 40), 2); }
TEST(MeshContour, TorusIsClosedManifoldGenus1) { expectClosedManifold(meshOf(kTorus, 48), 0); }
// A 2-cube minus a 1.2-sphere: a frame with a hole in each face, genus 5.
TEST(MeshContour, CsgFrameIsClosedManifoldGenus5) { expectClosedManifold(meshOf(kBoxMinusSphere, 48), -8); }

// Faces exactly on grid planes (resolution divides the box) must not break anything.
TEST(MeshContour, SurfaceOnGridSamplesStaysClosed) {
  expectClosedManifold(meshOf("scene { box(size: [1, 1, 1]) }", 20), 2);
}

// Stated bounds: with the Newton projection every vertex is within 1e-6
// voxel of the surface; plain DC placement (QEF minimum clamped to its
// cell) within 0.1 voxel (its error is about voxel^2 / radius).
TEST(MeshContour, VerticesLieOnTheSurface) {
  for (const char* text : {kSphere, kBox, kTorus, kBoxMinusSphere}) {
    Meshed m = meshOf(text, 40);
    const Evaluator eval(m.compiled.scene);
    EXPECT_LT(maxVertexError(eval, m.result.mesh), 1e-6 * m.result.plan.voxel) << text;
    MeshOptions plain;
    plain.resolution = 40;
    plain.project_steps = 0;
    const MeshResult r = meshScene(m.compiled.scene, plain);
    EXPECT_LT(maxVertexError(eval, r.mesh), 0.1 * r.plan.voxel) << text;
  }
}

TEST(MeshContour, VolumesMatchClosedForms) {
  struct Case {
    const char* text;
    double exact, tolerance;  // relative
  } cases[] = {{kSphere, 4.0 / 3.0 * kPi, 2e-3},
               {kBox, 2 * 1.5 * 1, 1e-9},
               {kTorus, 2 * kPi * kPi * 1 * 0.35 * 0.35, 5e-3}};
  for (const Case& c : cases) {
    Meshed m = meshOf(c.text, 48);
    const double v = meshVolume(m.result.mesh);
    EXPECT_NEAR(v / c.exact - 1, 0, c.tolerance) << c.text << ": volume " << v << " vs " << c.exact;
  }
}

// Corners off the lattice: the QEF of the three faces puts a vertex on the corner.
TEST(MeshContour, BoxCornersStaySharp) {
  Meshed m = meshOf("scene { translate([0.013, -0.021, 0.007]) { box(size: [1, 0.8, 0.6]) } }", 0, 1 / 21.3);
  const double voxel = m.result.plan.voxel;
  for (int n = 0; n < 8; ++n) {
    const glm::dvec3 corner = glm::dvec3(0.013, -0.021, 0.007) +
                              glm::dvec3(n & 1 ? 0.5 : -0.5, n & 2 ? 0.4 : -0.4, n & 4 ? 0.3 : -0.3);
    double nearest = 1e9;
    for (const glm::dvec3& p : m.result.mesh.positions) nearest = std::min(nearest, glm::distance(p, corner));
    EXPECT_LT(nearest, 1e-3 * voxel) << "corner " << n;
  }
}

// Spheres touching diagonally across cells make faces with four crossings
// (ambiguous cells). Plain DC, one vertex per cell, pinches them into
// non-manifold vertices; one vertex per patch must keep every mesh manifold.
TEST(MeshContour, SplitPatchesKeepAmbiguousCellsManifold) {
  size_t split_cells = 0, plain_bad_vertices = 0, plain_bad_edges = 0;
  for (int n = 0; n < 6; ++n) {
    const double d = 0.71 + 0.013 * n;
    const std::string text = "scene { union { sphere(radius: 0.5) translate([" + std::to_string(d) + ", " +
                             std::to_string(d) + ", " + std::to_string(0.02 * n) +
                             "]) { sphere(radius: 0.5) } } }";
    Meshed split = meshOf(text, 17 + n);
    const MeshTopology t = checkTopology(split.result.mesh);
    EXPECT_TRUE(t.closedManifold()) << text << ": " << t.non_manifold_edges << " non-manifold edges, "
                                    << t.non_manifold_vertices << " non-manifold vertices";
    split_cells += split.result.contour.split_cells;
    const MeshTopology p = checkTopology(meshOf(text, 17 + n, 0, false).result.mesh);
    plain_bad_vertices += p.non_manifold_vertices;
    plain_bad_edges += p.non_manifold_edges;
  }
  EXPECT_GT(split_cells, 0u);
  std::printf("6 touching-sphere grids: %zu cells split; plain DC: %zu non-manifold vertices, %zu "
              "non-manifold edges\n", split_cells, plain_bad_vertices, plain_bad_edges);
}

TEST(MeshContour, UnboundedSceneNeedsABox) {
  CompiledScene c = sceneFrom("scene {\n  sphere(radius: 1)\n  plane(normal: [0, 1, 0], offset: 0)\n}\n");
  MeshOptions o;
  o.resolution = 16;
  const MeshResult r = meshScene(c.scene, o);
  EXPECT_EQ(r.error, "the scene is unbounded (plane at line 3); give --box x0,y0,z0,x1,y1,z1");
  o.box = Aabb{glm::dvec3(-2), glm::dvec3(2)};
  const MeshResult boxed = meshScene(c.scene, o);
  EXPECT_EQ(boxed.error, "");
  EXPECT_GT(boxed.mesh.triangles.size(), 0u);
  // The box cuts the plane: an open mesh, but still manifold and consistently wound.
  const MeshTopology t = checkTopology(boxed.mesh);
  EXPECT_GT(t.boundary_edges, 0u);
  EXPECT_EQ(t.inconsistent_edges, 0u);

  CompiledScene rep = sceneFrom("scene { repeat(cell: [2, 0, 0]) { sphere(radius: 0.5) } }");
  EXPECT_NE(meshScene(rep.scene, {}).error.find("unbounded (repeat at line 1)"), std::string::npos);
}

TEST(MeshContour, GridLimitIsAnError) {
  CompiledScene c = sceneFrom(kSphere);
  MeshOptions o;
  o.voxel_size = 1e-3;  // 2000^3 cells
  EXPECT_NE(meshScene(c.scene, o).error.find("more than the limit of 1024^3"), std::string::npos);
}

TEST(MeshContour, SparseSamplingGivesTheSameMesh) {
  CompiledScene c = sceneFrom(
      "scene { union { sphere(radius: 0.3) translate([3, 1, 0]) { box(size: [0.5, 0.5, 0.5]) } } }");
  MeshOptions o;
  o.resolution = 48;
  const MeshResult sparse = meshScene(c.scene, o);
  o.sparse = false;
  const MeshResult dense = meshScene(c.scene, o);
  EXPECT_EQ(sparse.mesh.triangles.size(), dense.mesh.triangles.size());
  EXPECT_EQ(sparse.mesh.positions, dense.mesh.positions);
  EXPECT_LT(sparse.points_evaluated, dense.points_evaluated / 2);
}

TEST(MeshQef, ThreePlanesMeetAtTheCorner) {
  Qef q;
  q.add({0.3, 0.1, 0.2}, {1, 0, 0});
  q.add({0.1, 0.4, 0.0}, {0, 1, 0});
  q.add({0.9, 0.2, 0.5}, {0, 0, 1});
  q.add({0.3, 0.7, 0.6}, {1, 0, 0});
  const glm::dvec3 x = q.solve();
  EXPECT_NEAR(x.x, 0.3, 1e-12);
  EXPECT_NEAR(x.y, 0.4, 1e-12);
  EXPECT_NEAR(x.z, 0.5, 1e-12);
}

TEST(MeshQef, FlatSamplesStayAtTheMassPoint) {
  Qef q;
  q.add({0, 0, 1}, {0, 0, 1});
  q.add({1, 0, 1}, {0, 0, 1});
  q.add({0, 1, 1}, {0, 0, 1});
  const glm::dvec3 x = q.solve();
  EXPECT_NEAR(glm::distance(x, glm::dvec3(1.0 / 3, 1.0 / 3, 1)), 0, 1e-12);
}

TEST(MeshQef, JacobiEigenReconstructs) {
  const glm::dmat3 m(4, 1, -2, 1, 3, 0.5, -2, 0.5, 5);
  glm::dvec3 values;
  glm::dmat3 v;
  symmetricEigen(m, values, v);
  const glm::dmat3 back = v * glm::dmat3(values.x, 0, 0, 0, values.y, 0, 0, 0, values.z) * glm::transpose(v);
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) EXPECT_NEAR(back[c][r], m[c][r], 1e-12);
}

}  // namespace
}  // namespace sdfc
