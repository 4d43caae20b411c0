#include "meshin/mesh_check.h"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <unistd.h>

namespace sdfc {

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
  shape->distance = std::make_unique<MeshDistance>(file.mesh);
  shape->mode = mode == MeshMode::Exact ? MeshMode::Exact : MeshMode::Grid;
  shape->grid_layout = meshGridLayout(shape->distance->bounds());
  return shape;
}

}  // namespace sdfc
