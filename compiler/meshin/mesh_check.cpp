#include "meshin/mesh_check.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <unistd.h>

#include "meshin/mesh_exact.h"

namespace sdfc {

bool chooseMeshMode(MeshShape& m, MeshMode asked) {
  const size_t bytes = meshExactBytes(*m.distance);
  char mb[64];
  std::snprintf(mb, sizeof mb, "%.1f MiB", double(bytes) / (1 << 20));
  if (bytes > kMaxMeshExactBytes) {
    m.mode = MeshMode::Grid;
    m.mode_reason = std::string("its triangles and hierarchy are ") + mb + " of data, more than the " +
                    std::to_string(kMaxMeshExactBytes >> 20) + " MiB the storage buffer leaves them";
    return asked != MeshMode::Exact;
  }
  if (asked != MeshMode::Auto) {
    m.mode = asked;
    m.mode_reason = asked == MeshMode::Exact ? "--mesh-mode exact" : "--mesh-mode grid";
    return true;
  }
  // Exact needs the nearest face's side to agree with the inside the grid's
  // winding numbers give, which holds on closed, consistently outward meshes.
  std::string why;
  if (m.boundary_edges > 0) why = "open";
  else if (m.flipped_edges > 0) why = "faces not consistently oriented";
  else if (m.volume <= 0) why = "faces pointing in";
  else if (m.triangles > kMeshExactAutoTriangles) why = "more than " + std::to_string(kMeshExactAutoTriangles) + " triangles";
  m.mode = why.empty() ? MeshMode::Exact : MeshMode::Grid;
  m.mode_reason = why.empty() ? std::string("auto: closed and oriented, ") + mb + " of triangles and hierarchy"
                              : "auto: " + why;
  return true;
}

std::shared_ptr<MeshShape> loadMesh(const std::string& path, const std::string& written, SourceRange at,
                                    MeshMode mode, Diagnostics& diags) {
  MeshFile file = readMeshFile(path);
  if (!file.ok) {
    if (file.unreadable) {
      std::error_code ignored;
      const std::string tried = std::filesystem::absolute(path, ignored).lexically_normal().string();
      diags.error(at, "cannot read '" + written + "': " + file.error + " (looked for '" + tried + "')");
    } else {
      diags.error(at, "'" + written + "'" + (file.format.empty() ? "" : " (" + file.format + ")") + ": " + file.error);
    }
    return nullptr;
  }
  auto shape = std::make_shared<MeshShape>();
  shape->file = written;
  shape->format = file.format;
  shape->triangles = file.mesh.triangles.size();
  shape->degenerate = file.degenerate;
  shape->boundary_edges = file.boundary_edges;
  shape->edges = file.edges;
  if (file.degenerate > 0)
    diags.warning(at, "mesh-degenerate",
                  "'" + written + "': " + std::to_string(file.degenerate) + " of its " +
                      std::to_string(file.degenerate + shape->triangles) + " triangles have no area and are dropped");
  if (file.boundary_edges > 0 || file.nonmanifold_edges > 0) {
    std::string how = std::to_string(file.boundary_edges) + " of its " + std::to_string(file.edges) +
                      " edges are boundary edges (one triangle)";
    if (file.nonmanifold_edges > 0) how += " and " + std::to_string(file.nonmanifold_edges) + " belong to three or more";
    diags.warning(at, "mesh-open",
                  "'" + written + "' is not closed: " + how + "; its winding number decides inside, a guess near holes");
  }
  if (file.turned_outward) {
    std::ostringstream volume;
    volume << file.inward_volume;
    diags.warning(at, "mesh-inward",
                  "'" + written + "' faces inward (closed, with volume " + volume.str() +
                      "): its triangles are turned to face outward, so the part is solid and the rest empty");
  }
  shape->flipped_edges = file.flipped_edges;
  for (const glm::uvec3& t : file.mesh.triangles) {
    const glm::dvec3 &a = file.mesh.vertices[t[0]], &b = file.mesh.vertices[t[1]], &c = file.mesh.vertices[t[2]];
    shape->volume += glm::dot(a, glm::cross(b, c)) / 6;
  }
  shape->distance = std::make_unique<MeshDistance>(file.mesh);
  shape->grid_layout = meshGridLayout(shape->distance->bounds());
  if (!chooseMeshMode(*shape, mode)) {
    diags.error(at, "'" + written + "' cannot be exact in the shader (--mesh-mode exact): " + shape->mode_reason +
                        "; --mesh-mode grid samples it");
    return nullptr;
  }
  return shape;
}

}  // namespace sdfc
