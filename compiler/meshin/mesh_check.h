// mesh(file: "part.stl") at check time: reads the file beside the scene,
// reports what is wrong with it at the `file:` string, warns when it is open
// or had triangles of no area, and builds its float64 distance.
#pragma once
#include <memory>
#include <string>

#include "diag/diagnostics.h"
#include "meshin/mesh_shape.h"

namespace sdfc {

// The auto mode's exact meshes have at most this many triangles. On lavapipe
// the exact search costs 15-30x the grid's time a sample, and seconds more
// kernel compilation (docs/mesh_in.md): worth it for a small mesh, whose first
// image stays within seconds; a large scan keeps the grid's fast first image.
constexpr size_t kMeshExactAutoTriangles = 32768;

// Sets m.mode and m.mode_reason for the mode `asked` (Auto: the compiler's
// rule); false when Exact is asked and the mesh cannot have it.
bool chooseMeshMode(MeshShape& m, MeshMode asked);

// `path` is resolved already; `written` is the string as in the scene, whose
// range `at` the diagnostics point to. Null after an error.
std::shared_ptr<MeshShape> loadMesh(const std::string& path, const std::string& written, SourceRange at,
                                    MeshMode mode, Diagnostics& diags);

}  // namespace sdfc
