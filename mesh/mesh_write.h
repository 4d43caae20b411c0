// Writing meshes: glTF 2.0 (.glb, or .gltf with the buffer embedded) with
// one primitive per material and the renderer's materials mapped to PBR,
// and binary STL.
#pragma once
#include <optional>
#include <string>

#include "ir/scene.h"
#include "mesher.h"

namespace sdfc {

enum class MeshFormat { Glb, Gltf, Stl };

// By extension (case-insensitive); nullopt for anything else.
std::optional<MeshFormat> meshFormatFor(const std::string& path);

// The file's bytes. Throws std::runtime_error if tinygltf fails.
std::string encodeMesh(const TriangleMesh& mesh, const ir::Scene& scene, MeshFormat format,
                       double time = 0);

}  // namespace sdfc
