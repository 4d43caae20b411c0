// mesh(file: ...): reading and its checks, the float64 distance against brute
// force, its sign against ray parity, a mesh from `sdfc mesh` read back, and
// the shader's grid (meshin/). Every mesh is made here, none is stored.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>

#include "driver/compile.h"
#include "eval/evaluator.h"
#include "meshin/mesh_distance.h"
#include "meshin/mesh_file.h"
#include "meshin/mesh_grid.h"
#include "mesh_soup.h"
#include "mesh_write.h"
#include "mesher.h"

namespace sdfc {
namespace {

using glm::dvec3;
using test::Soup;
using test::icosphere;
using test::merged;
using test::binaryStl;
using test::obj;

InputMesh asInput(const Soup& s) { return {s.v, s.f}; }

std::string tempDir() {
  static const std::string dir = [] {
    std::string d = std::filesystem::temp_directory_path() / ("sdfc_mesh_in_" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir;
}

std::string writeFile(const std::string& name, const std::string& bytes) {
  const std::string path = tempDir() + "/" + name;
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

// Independent of meshin's region test: the nearest point of the plane when
// it falls inside (all three edge tests), else the nearest of the three
// edges as clamped segments.
double bruteTriangle(const dvec3& p, const dvec3& a, const dvec3& b, const dvec3& c) {
  const dvec3 n = glm::normalize(glm::cross(b - a, c - a));
  const dvec3 q = p - glm::dot(p - a, n) * n;
  const bool in = glm::dot(glm::cross(b - a, q - a), n) >= 0 && glm::dot(glm::cross(c - b, q - b), n) >= 0 &&
                  glm::dot(glm::cross(a - c, q - c), n) >= 0;
  if (in) return std::fabs(glm::dot(p - a, n));
  auto seg = [&](const dvec3& u, const dvec3& w) {
    const double t = std::clamp(glm::dot(p - u, w - u) / glm::dot(w - u, w - u), 0.0, 1.0);
    return glm::length(p - (u + t * (w - u)));
  };
  return std::min({seg(a, b), seg(b, c), seg(c, a)});
}

double brute(const Soup& s, const dvec3& p) {
  double best = 1e300;
  for (const glm::uvec3& f : s.f) best = std::min(best, bruteTriangle(p, s.v[f[0]], s.v[f[1]], s.v[f[2]]));
  return best;
}

// Crossings of the ray p + t d (t > 0) with the soup (Moller and Trumbore 1997).
int crossings(const Soup& s, const dvec3& p, const dvec3& d) {
  int n = 0;
  for (const glm::uvec3& f : s.f) {
    const dvec3 a = s.v[f[0]], e1 = s.v[f[1]] - a, e2 = s.v[f[2]] - a;
    const dvec3 h = glm::cross(d, e2);
    const double det = glm::dot(e1, h);
    if (std::fabs(det) < 1e-14) continue;
    const dvec3 w = p - a;
    const double u = glm::dot(w, h) / det;
    const dvec3 q = glm::cross(w, e1);
    const double v = glm::dot(d, q) / det;
    const double t = glm::dot(e2, q) / det;
    if (u >= 0 && v >= 0 && u + v <= 1 && t > 0) ++n;
  }
  return n;
}

void expectDistancesMatchBruteForce(const Soup& s, unsigned seed) {
  const MeshDistance m(asInput(s));
  std::mt19937 rng(seed);
  const Aabb box = m.bounds().grow(0.5);
  std::uniform_real_distribution<double> x(box.lo.x, box.hi.x), y(box.lo.y, box.hi.y), z(box.lo.z, box.hi.z);
  for (int i = 0; i < 400; ++i) {
    const dvec3 p(x(rng), y(rng), z(rng));
    const double want = brute(s, p);
    ASSERT_NEAR(m.unsignedDistance(p), want, 1e-12 + 1e-12 * want) << "at " << p.x << ", " << p.y << ", " << p.z;
    // A cap nearer than the surface answers the cap.
    EXPECT_EQ(m.unsignedDistance(p, want * 0.5), want * 0.5);
  }
}

TEST(MeshIn, DistanceEqualsBruteForceClosed) { expectDistancesMatchBruteForce(icosphere(2), 1); }

TEST(MeshIn, DistanceEqualsBruteForceOpen) {
  Soup s = icosphere(2);
  std::vector<glm::uvec3> upper;
  for (const glm::uvec3& f : s.f)
    if (s.v[f[0]].y + s.v[f[1]].y + s.v[f[2]].y > 0) upper.push_back(f);
  s.f = upper;
  expectDistancesMatchBruteForce(s, 2);
}

TEST(MeshIn, DistanceEqualsBruteForceSelfIntersecting) {
  expectDistancesMatchBruteForce(merged(icosphere(2), icosphere(1, 0.8, dvec3(0.7, 0.2, 0))), 3);
}

// Inside by the winding number where a random ray crosses the surface an odd
// number of times, for closed meshes (one sphere; two overlapping: depth 2 counts inside).
TEST(MeshIn, SignAgreesWithRayParity) {
  for (const Soup& s : {icosphere(3), merged(icosphere(2), icosphere(2, 0.5, dvec3(2, 0, 0)))}) {
    const MeshDistance m(asInput(s));
    std::mt19937 rng(7);
    const Aabb box = m.bounds().grow(0.3);
    std::uniform_real_distribution<double> u(0, 1);
    std::normal_distribution<double> g;
    int checked = 0;
    for (int i = 0; i < 600; ++i) {
      const dvec3 p = box.lo + (box.hi - box.lo) * dvec3(u(rng), u(rng), u(rng));
      if (m.unsignedDistance(p) < 1e-3) continue;  // the ray test is unreliable at the surface
      const dvec3 d = glm::normalize(dvec3(g(rng), g(rng), g(rng)));
      const bool odd = crossings(s, p, d) % 2 == 1;
      EXPECT_EQ(m.signedDistance(p) < 0, odd) << "winding " << m.winding(p);
      ++checked;
    }
    EXPECT_GT(checked, 500);
  }
}

// The hierarchical winding number against the exact sum of solid angles.
TEST(MeshIn, FastWindingNumberIsNearTheExactSum) {
  const Soup s = icosphere(3);
  const MeshDistance m(asInput(s));
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-2, 2);
  double worst = 0;
  for (int i = 0; i < 200; ++i) {
    const dvec3 p(u(rng), u(rng), u(rng));
    double exact = 0;
    for (const glm::uvec3& f : s.f) exact += triangleSolidAngle(p, s.v[f[0]], s.v[f[1]], s.v[f[2]]);
    exact /= 4 * M_PI;
    worst = std::max(worst, std::fabs(m.winding(p) - exact));
  }
  EXPECT_LT(worst, 0.02);
}

TEST(MeshIn, ReadsBinaryStlObjAlike) {
  const Soup s = icosphere(2);
  const MeshFile stl = readMeshFile(writeFile("ico.stl", binaryStl(s)));
  const MeshFile o = readMeshFile(writeFile("ico.obj", obj(s)));
  ASSERT_TRUE(stl.ok) << stl.error;
  ASSERT_TRUE(o.ok) << o.error;
  EXPECT_EQ(stl.format, "binary STL");
  EXPECT_EQ(o.format, "OBJ");
  EXPECT_EQ(stl.mesh.triangles.size(), s.f.size());
  EXPECT_EQ(o.mesh.triangles.size(), s.f.size());
  // Welded by position: a closed mesh, every edge shared by two triangles.
  EXPECT_EQ(stl.mesh.vertices.size(), s.v.size());
  EXPECT_EQ(stl.boundary_edges, 0u);
  EXPECT_EQ(stl.edges, s.f.size() * 3 / 2);
}

TEST(MeshIn, ReadsAsciiStlAndCountsOpenEdgesAndDegenerates) {
  const std::string text =
      "solid two\n"
      " facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n   vertex 0 1 0\n  endloop\n endfacet\n"
      " facet normal 0 0 1\n  outer loop\n   vertex 1 0 0\n   vertex 1 1 0\n   vertex 0 1 0\n  endloop\n endfacet\n"
      " facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 2 0 0\n   vertex 1 0 0\n  endloop\n endfacet\n"
      "endsolid two\n";
  const MeshFile f = readMeshFile(writeFile("square.stl", text));
  ASSERT_TRUE(f.ok) << f.error;
  EXPECT_EQ(f.format, "ASCII STL");
  EXPECT_EQ(f.mesh.triangles.size(), 2u);
  EXPECT_EQ(f.degenerate, 1u);  // the collinear third
  EXPECT_EQ(f.boundary_edges, 4u);
}

TEST(MeshIn, BadFilesSayWhy) {
  auto error = [](const std::string& name, const std::string& bytes) {
    const MeshFile f = readMeshFile(writeFile(name, bytes));
    EXPECT_FALSE(f.ok);
    return f.error;
  };
  EXPECT_NE(error("empty.stl", "").find("neither ASCII STL"), std::string::npos);
  EXPECT_EQ(error("nothing.stl", "solid x\nendsolid x\n"), "it holds no triangles");
  EXPECT_EQ(error("nan.obj", "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n"), "line 4: a vertex coordinate is not a number (nan)");
  EXPECT_EQ(error("inf.obj", "v 0 0 0\nv 1 0 0\nv 1e39 1 0\nf 1 2 3\n"), "line 4: a vertex coordinate is beyond float32's range");
  EXPECT_EQ(error("index.obj", "v 0 0 0\nv 1 0 0\nf 1 2 7\n"), "line 3: '7' is not a vertex (2 defined so far)");
  EXPECT_EQ(error("flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n"), "all 1 of its triangles have no area");
  EXPECT_EQ(error("part.ply", "ply\n"), "'.ply' is not a mesh format sdfc reads (.stl, .obj, .gltf, .glb)");
  EXPECT_NE(error("bad.glb", "glTF nonsense").find("not a valid GLB file"), std::string::npos);
  const MeshFile missing = readMeshFile(tempDir() + "/no such.stl");
  EXPECT_TRUE(missing.unreadable);
  EXPECT_EQ(missing.error, "No such file or directory");
  const MeshFile dir = readMeshFile(tempDir());
  EXPECT_EQ(dir.error, "it is a directory");
}

// A .gltf with its buffer inline (base64): float VEC3 positions and one
// primitive per (mode, indices), unsigned int indices, in one node scaled by
// `scale` (a negative component mirrors).
std::string gltfOf(const std::vector<dvec3>& positions, const std::vector<std::pair<int, std::vector<uint32_t>>>& prims,
                   const dvec3& scale = dvec3(1)) {
  std::string bytes;
  for (const dvec3& p : positions)
    for (int a = 0; a < 3; ++a) {
      const float f = float(p[a]);
      bytes.append(reinterpret_cast<const char*>(&f), 4);
    }
  std::vector<size_t> offsets;
  for (const auto& prim : prims) {
    offsets.push_back(bytes.size());
    bytes.append(reinterpret_cast<const char*>(prim.second.data()), prim.second.size() * 4);
  }
  static const char kDigits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string b64;
  for (size_t i = 0; i < bytes.size(); i += 3) {
    uint32_t n = uint32_t(uint8_t(bytes[i])) << 16;
    if (i + 1 < bytes.size()) n |= uint32_t(uint8_t(bytes[i + 1])) << 8;
    if (i + 2 < bytes.size()) n |= uint32_t(uint8_t(bytes[i + 2]));
    b64 += kDigits[n >> 18 & 63];
    b64 += kDigits[n >> 12 & 63];
    b64 += i + 1 < bytes.size() ? kDigits[n >> 6 & 63] : '=';
    b64 += i + 2 < bytes.size() ? kDigits[n & 63] : '=';
  }
  dvec3 lo(1e300), hi(-1e300);
  for (const dvec3& p : positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
  auto num = [](double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.9g", v);
    return std::string(buf);
  };
  std::string views = "{\"buffer\": 0, \"byteOffset\": 0, \"byteLength\": " + std::to_string(positions.size() * 12) + "}";
  std::string accessors = "{\"bufferView\": 0, \"componentType\": 5126, \"count\": " + std::to_string(positions.size()) +
                          ", \"type\": \"VEC3\", \"min\": [" + num(lo.x) + ", " + num(lo.y) + ", " + num(lo.z) +
                          "], \"max\": [" + num(hi.x) + ", " + num(hi.y) + ", " + num(hi.z) + "]}";
  std::string primitives;
  for (size_t i = 0; i < prims.size(); ++i) {
    views += ", {\"buffer\": 0, \"byteOffset\": " + std::to_string(offsets[i]) + ", \"byteLength\": " +
             std::to_string(prims[i].second.size() * 4) + "}";
    accessors += ", {\"bufferView\": " + std::to_string(i + 1) + ", \"componentType\": 5125, \"count\": " +
                 std::to_string(prims[i].second.size()) + ", \"type\": \"SCALAR\"}";
    primitives += std::string(i ? ", " : "") + "{\"attributes\": {\"POSITION\": 0}, \"indices\": " +
                  std::to_string(i + 1) + ", \"mode\": " + std::to_string(prims[i].first) + "}";
  }
  return "{\"asset\": {\"version\": \"2.0\"}, \"scene\": 0, \"scenes\": [{\"nodes\": [0]}], \"nodes\": [{\"mesh\": 0, "
         "\"scale\": [" + num(scale.x) + ", " + num(scale.y) + ", " + num(scale.z) + "]}], \"meshes\": [{\"name\": \"m\", "
         "\"primitives\": [" + primitives + "]}], \"buffers\": [{\"byteLength\": " + std::to_string(bytes.size()) +
         ", \"uri\": \"data:application/octet-stream;base64," + b64 + "\"}], \"bufferViews\": [" + views +
         "], \"accessors\": [" + accessors + "]}";
}

dvec3 faceNormal(const InputMesh& m, const glm::uvec3& t) {
  return glm::cross(m.vertices[t[1]] - m.vertices[t[0]], m.vertices[t[2]] - m.vertices[t[0]]);
}

TEST(MeshIn, GltfStripsAndFansAreTriangles) {
  // Beside a list of one triangle (z = 0), a strip of four corners (z = 1)
  // and a fan of five (z = 2): 1 + 2 + 3 triangles, all facing +z.
  std::vector<dvec3> p = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0},
                          {0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1},
                          {0, 0, 2}, {1, 0, 2}, {1, 1, 2}, {0.5, 1.5, 2}, {0, 1, 2}};
  const MeshFile f = readMeshFile(writeFile("strips.gltf", gltfOf(p, {{4, {0, 1, 2}}, {5, {3, 4, 5, 6}},
                                                                       {6, {7, 8, 9, 10, 11}}})));
  ASSERT_TRUE(f.ok) << f.error;
  ASSERT_EQ(f.mesh.triangles.size(), 6u);
  for (const glm::uvec3& t : f.mesh.triangles) {
    const dvec3 n = faceNormal(f.mesh, t);
    EXPECT_GT(n.z, 0);
    EXPECT_EQ(n.x, 0);
    EXPECT_EQ(n.y, 0);
  }
  // A file of strips alone is a mesh too (it was "no triangles").
  const MeshFile only = readMeshFile(writeFile("only strip.gltf", gltfOf(p, {{5, {3, 4, 5, 6}}})));
  ASSERT_TRUE(only.ok) << only.error;
  EXPECT_EQ(only.mesh.triangles.size(), 2u);
}

// Indices are unsigned integers in glTF: a float index accessor (one holding
// NaN, found by fuzz/mesh_file_fuzz: converting it to an index was undefined
// behaviour) is refused.
TEST(MeshIn, GltfFloatIndicesAreRefused) {
  std::string text = gltfOf({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{4, {0x7fc00000u, 1, 2}}});
  const std::string unsigned_int = "\"componentType\": 5125";
  const size_t at = text.find(unsigned_int);
  ASSERT_NE(at, std::string::npos);
  text.replace(at, unsigned_int.size(), "\"componentType\": 5126");
  const MeshFile f = readMeshFile(writeFile("float indices.gltf", text));
  EXPECT_FALSE(f.ok);
  EXPECT_EQ(f.error, "mesh 'm': indices must be unsigned integer scalars");
}

TEST(MeshIn, InwardMeshIsTurnedOutward) {
  Soup in = icosphere(2);
  for (glm::uvec3& t : in.f) std::swap(t[1], t[2]);
  const MeshFile f = readMeshFile(writeFile("inward.stl", binaryStl(in)));
  ASSERT_TRUE(f.ok) << f.error;
  EXPECT_TRUE(f.turned_outward);
  EXPECT_LT(f.inward_volume, -4.0);  // about -4.19, the unit ball's
  const MeshDistance d(f.mesh);
  EXPECT_NEAR(d.signedDistance(dvec3(0)), -1.0, 0.02);  // inside (it was +1: a shell)
  EXPECT_NEAR(d.signedDistance(dvec3(3, 0, 0)), 2.0, 0.02);
  // An outward one is left alone, and so is one mirrored by its glTF node
  // (the faces' order reversed with the determinant).
  const Soup out = icosphere(2);
  EXPECT_FALSE(readMeshFile(writeFile("outward.stl", binaryStl(out))).turned_outward);
  std::vector<uint32_t> list;
  for (const glm::uvec3& t : out.f) list.insert(list.end(), {t[0], t[1], t[2]});
  const MeshFile mirrored = readMeshFile(writeFile("mirrored.gltf", gltfOf(out.v, {{4, list}}, dvec3(-1, 1, 1))));
  ASSERT_TRUE(mirrored.ok) << mirrored.error;
  EXPECT_FALSE(mirrored.turned_outward);
  // The checker says so, as a named warning at the file argument.
  writeFile("inward.stl", binaryStl(in));
  Diagnostics diags;
  CompileOptions o;
  o.produce_spirv = false;
  const std::string text = "scene {\n  mesh(file: \"inward.stl\")\n}\n";
  const CompiledScene c = compileSource(writeFile("inward.sdf", text), text, o, diags);
  EXPECT_NE(diags.format().find("inward.sdf:2:14: warning: 'inward.stl' faces inward (closed, with volume -4."),
            std::string::npos)
      << diags.format();
  EXPECT_NE(diags.format().find("[-Wmesh-inward]"), std::string::npos) << diags.format();
}

std::string sceneWith(const std::string& body) {
  return "camera(position: [0, 0.5, 4], target: [0, 0, 0])\nscene {\n" + body + "\n}\n";
}

CompiledScene checked(const std::string& name, const std::string& text, Diagnostics& diags,
                      MeshMode mode = MeshMode::Auto) {
  const std::string path = writeFile(name, text);
  CompileOptions o;
  o.produce_spirv = false;
  o.check.mesh_mode = mode;
  return compileSource(path, text, o, diags);
}

TEST(MeshIn, CheckerErrorsPointAtTheFileArgument) {
  writeFile("open.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  Diagnostics diags;
  // Kept: the diagnostics point into its source.
  const CompiledScene c = checked("errors.sdf", sceneWith("  mesh(file: \"missing.stl\")\n  mesh(\"open.obj\")\n  mesh(fille: \"x.stl\")"), diags);
  const std::string text = diags.format();
  EXPECT_NE(text.find("errors.sdf:3:14: error: cannot read 'missing.stl': No such file or directory (looked for '" +
                      tempDir() + "/missing.stl')"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("errors.sdf:4:8: warning: 'open.obj' is not closed: 3 of its 3 edges are boundary edges"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("'mesh' has no parameter 'fille' (or it is given twice); did you mean 'file'?"), std::string::npos)
      << text;
}

// The compiler's grid: the IR says so, the GLSL reads it, and every corner
// holds the float64 signed distance (clamped to the band).
TEST(MeshIn, GridModeIsInTheIrAndTheData) {
  writeFile("ico3.stl", binaryStl(icosphere(3)));
  Diagnostics diags;
  const CompiledScene c = checked("grid.sdf", sceneWith("  mesh(file: \"ico3.stl\")"), diags, MeshMode::Grid);
  ASSERT_TRUE(c.ok) << diags.format();
  const std::string ir = ir::dump(c.scene);
  EXPECT_NE(ir.find("mesh \"ico3.stl\" (binary STL, 1280 triangles, closed;"), std::string::npos) << ir;
  EXPECT_NE(ir.find("shader: grid (--mesh-mode grid)"), std::string::npos) << ir;
  EXPECT_NE(c.emitted.glsl.find("sdMeshGrid(p, 0)"), std::string::npos);
  const ir::Node& mesh = *c.scene.root->children[0];
  ASSERT_EQ(mesh.kind, ir::NodeKind::Mesh);
  const MeshGridLayout& l = mesh.mesh->grid_layout;
  const MeshGrid& g = mesh.mesh->grid();
  ASSERT_EQ(c.emitted.scene_data.size(), 16 + (l.corners() + 3) / 4 * 4);
  std::mt19937 rng(5);
  for (int i = 0; i < 300; ++i) {
    const size_t k = rng() % l.corners();
    const dvec3 p = l.lo + l.cell * dvec3(double(k % l.dims.x), double(k / l.dims.x % l.dims.y),
                                          double(k / (size_t(l.dims.x) * l.dims.y)));
    const double want = mesh.mesh->distance->signedDistance(p);
    const double clamped = std::clamp(want, -l.band, l.band);
    EXPECT_NEAR(g.values[k], clamped, 1e-6) << "corner " << k;
    EXPECT_EQ(c.emitted.scene_data[16 + k], g.values[k]);
  }
  // The float64 evaluator uses the exact distance: a sphere's within the chord error.
  Evaluator eval(c.scene);
  EXPECT_NEAR(eval.distance(dvec3(0, 0, 2)), 1.0, 0.01);
  EXPECT_NEAR(eval.distance(dvec3(0, 0, 0)), -1.0, 0.01);
}

// A scene meshed by `sdfc mesh` (dual contouring, exported as GLB) and read
// back: its distance is the scene's within the export's own error (its
// vertices' largest distance from the surface plus the chord's sagitta).
TEST(MeshIn, ExportedMeshReadsBackAsTheScene) {
  // A rounded box: exact everywhere (a smooth union would be a bound only).
  const std::string text = sceneWith("  box(size: [1.2, 0.8, 1], rounding: 0.15)");
  Diagnostics diags;
  CompiledScene scene = checked("exported.sdf", text, diags);
  ASSERT_TRUE(scene.ok) << diags.format();
  MeshOptions o;
  o.resolution = 48;
  MeshResult r = meshScene(scene.scene, o);
  ASSERT_EQ(r.error, "");
  const std::string glb = writeFile("exported.glb", encodeMesh(r.mesh, scene.scene, MeshFormat::Glb));
  const MeshFile f = readMeshFile(glb);
  ASSERT_TRUE(f.ok) << f.error;
  EXPECT_EQ(f.boundary_edges, 0u);
  Evaluator eval(scene.scene);
  double vertex_error = 0;
  for (const dvec3& v : f.mesh.vertices) vertex_error = std::max(vertex_error, std::fabs(eval.distance(v)));
  // Edges span at most a cell diagonal; the smallest radius of curvature is the rounding's 0.15.
  const double edge = std::sqrt(3.0) * r.plan.voxel;
  const double tolerance = vertex_error + edge * edge / (8 * 0.15);
  const MeshDistance m(f.mesh);
  std::mt19937 rng(9);
  const Aabb box = m.bounds().grow(1.0);
  std::uniform_real_distribution<double> u(0, 1);
  double worst = 0;
  for (int i = 0; i < 500; ++i) {
    const dvec3 p = box.lo + (box.hi - box.lo) * dvec3(u(rng), u(rng), u(rng));
    worst = std::max(worst, std::fabs(m.signedDistance(p) - eval.distance(p)));
  }
  EXPECT_LE(worst, tolerance) << "vertex error " << vertex_error << ", voxel " << r.plan.voxel;
}

}  // namespace
}  // namespace sdfc
