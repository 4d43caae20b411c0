// A mesh(file: ...) as the IR holds it: what was read, its float64 distance,
// and how the shader gets it (docs/mesh_in.md).
#pragma once
#include <memory>
#include <mutex>
#include <string>

#include "meshin/mesh_distance.h"
#include "meshin/mesh_file.h"
#include "meshin/mesh_grid.h"

namespace sdfc {

enum class MeshMode { Auto, Grid, Exact };

struct MeshShape {
  std::string file;  // as written in the scene
  std::string format;
  size_t triangles = 0, degenerate = 0, boundary_edges = 0, edges = 0, flipped_edges = 0;
  double volume = 0;  // signed: positive when the faces point out
  std::unique_ptr<MeshDistance> distance;
  MeshMode mode = MeshMode::Grid;  // what the shader uses
  std::string mode_reason;         // why, for --emit ir ("auto: closed, oriented, ...")
  MeshGridLayout grid_layout;

  // The sampled grid, built on first use (rendering needs it; eval and mesh do
  // not). A non-empty `cache_version` (sdfc's) reads and fills the on-disk
  // cache (meshin/mesh_grid_cache.h).
  const MeshGrid& grid(const std::string& cache_version = "") const {
    std::call_once(grid_once_, [&] { grid_ = cachedGrid(cache_version); });
    return grid_;
  }

 private:
  MeshGrid cachedGrid(const std::string& cache_version) const;
  mutable std::once_flag grid_once_;
  mutable MeshGrid grid_;
};

}  // namespace sdfc
