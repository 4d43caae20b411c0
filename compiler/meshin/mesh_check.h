// mesh(file: "part.stl") at check time: reads the file beside the scene,
// reports what is wrong with it at the `file:` string, warns when it is open
// or had triangles of no area, and builds its float64 distance.
#pragma once
#include <memory>
#include <string>

#include "diag/diagnostics.h"
#include "meshin/mesh_shape.h"

namespace sdfc {

// `path` is resolved already; `written` is the string as in the scene, whose
// range `at` the diagnostics point to. Null after an error.
std::shared_ptr<MeshShape> loadMesh(const std::string& path, const std::string& written, SourceRange at,
                                    MeshMode mode, Diagnostics& diags);

}  // namespace sdfc
