// Triangle meshes read at compile time for mesh(file: "part.stl"): binary and
// ASCII STL, OBJ (v and f lines; polygons fanned), glTF and GLB (every
// triangle list, strip and fan primitive of every mesh, node transforms
// applied). A closed mesh that faces inward is turned to face outward. docs/mesh_in.md
// has the rules: vertices must be finite and within float32's range,
// triangles of no area are dropped (and counted), at most kMaxMeshTriangles.
#pragma once
#include <glm/glm.hpp>
#include <cstdint>
#include <string>
#include <vector>

namespace sdfc {

// Far beyond what a render needs (a million triangles load and render), and
// what keeps a mesh's float64 copy and hierarchy under a few hundred MB.
constexpr size_t kMaxMeshTriangles = 4000000;
// ASCII STL of four million triangles is about 1 GB; more is refused unread.
constexpr size_t kMaxMeshFileBytes = size_t(1) << 30;

struct InputMesh {
  std::vector<glm::dvec3> vertices;
  std::vector<glm::uvec3> triangles;  // indices into `vertices`, welded by exact position
};

struct MeshFile {
  InputMesh mesh;
  bool ok = false;
  // When !ok: why, in a sentence that follows "cannot read 'x.stl': " when
  // `unreadable`, or stands after "'x.stl': " otherwise ("line 12: ...").
  bool unreadable = false;
  std::string error;
  size_t degenerate = 0;      // triangles of no area, dropped
  size_t boundary_edges = 0;  // edges of one triangle only: the mesh is open
  size_t nonmanifold_edges = 0;  // edges of three or more triangles
  size_t flipped_edges = 0;  // edges of two triangles facing opposite ways (inconsistent orientation)
  size_t edges = 0;
  // A closed, consistently oriented mesh that faced inward (negative volume,
  // `inward_volume`): its triangles were turned to face outward.
  bool turned_outward = false;
  double inward_volume = 0;
  std::string format;  // "binary STL", "ASCII STL", "OBJ", "glTF", "GLB"
};

MeshFile readMeshFile(const std::string& path);

}  // namespace sdfc
