// An on-disk cache of meshes' sampled grids, beside the SPIR-V cache
// ($XDG_CACHE_HOME/sdfc/mesh-grid): building a 100k-triangle mesh's grid is
// most of its first image (bench/results/mesh_in.md), and a scene edited in the
// viewer rebuilt it at every save. An entry is named by a hash of the mesh's
// triangles (as the distance holds them), the grid's layout and sdfc's
// version; it is written to a temporary and renamed, and one that fails its
// checks (magic, key, count, checksum) is ignored and replaced. A cache that
// cannot be read or written is no error.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "meshin/mesh_grid.h"

namespace sdfc {

std::string meshGridCacheKey(const MeshDistance& mesh, const MeshGridLayout& layout, const std::string& version);
std::string meshGridCachePath(const std::string& key);  // "" when there is no cache folder
std::optional<std::vector<float>> loadCachedMeshGrid(const std::string& key, size_t corners);
void storeCachedMeshGrid(const std::string& key, const std::vector<float>& values);

}  // namespace sdfc
