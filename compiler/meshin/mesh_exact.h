// The exact shader form of a mesh: its hierarchy and triangles in the scene's
// storage buffer, searched nearest first with branch and bound near the
// surface, the sign from the sampled grid (or, where the grid cannot tell, the
// nearest triangle's face). docs/mesh_in.md says why and where it fails.
#pragma once
#include <cstddef>
#include <string>
#include <vector>

namespace sdfc {

class MeshDistance;
struct MeshGridLayout;

// Each triangle's angle-weighted pseudo-normals (3 corners, 3 edges) in the
// scene data, read once an evaluation for the sign.
constexpr size_t kMeshNormalVec4s = 5;

// What the exact form adds to the scene data: 2 vec4 per hierarchy node, 3 + 5
// per triangle. Beyond this the auto mode keeps the grid and --mesh-mode exact is
// an error: the storage buffer range every Vulkan device has is 128 MiB, and
// the grid and the rest of the scene need room too.
constexpr size_t kMaxMeshExactBytes = size_t(96) << 20;
size_t meshExactBytes(const MeshDistance& mesh);

// Within this many grid error bounds of the surface the shader searches the
// triangles; farther, the grid's value less its error bound is the distance
// (a bound, at least a third of it). 2 keeps the search's cap, |g| + bound,
// inside the grid's band (3.46 bounds), where the grid is not clamped.
constexpr double kMeshExactNear = 2.0;

// Hierarchy levels one visit of the shader's search descends (unrolled).
constexpr int kMeshDescentLevels = 16;

struct MeshExactData {
  size_t nodes = 0, triangles = 0, normals = 0;  // vec4 indices in the scene data
};
// Appends the hierarchy, the triangles (corners, unit face normal in w) and
// their corners' and edges' pseudo-normals.
MeshExactData appendMeshExactData(const MeshDistance& mesh, std::vector<float>& data);

// The helper functions every exact mesh shares (sdMeshTriangle2, sdMeshSide).
const char* meshExactHelperGlsl();
// `name`(vec3 p): the signed distance, reading the grid at `grid` and the
// data at `at`; `visits` is the loop bound (a GLSL int expression), `loop_zero`
// its start ("loopZero()" in the kernel), `count` adds the kernel's loop count.
std::string meshExactGlsl(const std::string& name, const MeshDistance& mesh, const MeshGridLayout& grid,
                          size_t grid_base, const MeshExactData& at, const std::string& visits,
                          const std::string& loop_zero, bool count);

}  // namespace sdfc
