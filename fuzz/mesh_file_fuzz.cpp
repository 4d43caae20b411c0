// libFuzzer target: the mesh file reader (meshin/mesh_file.cpp) on arbitrary
// bytes, read as each format it knows by extension: binary and ASCII STL, OBJ,
// glTF (JSON with data: URIs) and GLB. Every input must end in a mesh or a
// reason; a mesh it accepts must hold finite vertices and indices in range.
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "fuzz/input_file.h"
#include "meshin/mesh_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  for (const char* extension : {"stl", "obj", "gltf", "glb"}) {
    const sdfc::MeshFile m = sdfc::readMeshFile(sdfc::fuzz::writeInput(data, size, extension));
    if (!m.ok) {
      if (m.error.empty()) {
        std::fprintf(stderr, "mesh_file_fuzz: .%s refused without a reason\n", extension);
        std::abort();
      }
      continue;
    }
    for (const glm::dvec3& v : m.mesh.vertices)
      if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z)) {
        std::fprintf(stderr, "mesh_file_fuzz: .%s accepted a vertex that is not finite\n", extension);
        std::abort();
      }
    for (const glm::uvec3& t : m.mesh.triangles)
      if (t.x >= m.mesh.vertices.size() || t.y >= m.mesh.vertices.size() || t.z >= m.mesh.vertices.size()) {
        std::fprintf(stderr, "mesh_file_fuzz: .%s accepted an index out of range\n", extension);
        std::abort();
      }
  }
  return 0;
}
