// sdfc's public API, part 3: the float64 field of a checked scene at many points
// at once (distance, gradient, material: what `sdfc eval` prints, bit for bit),
// spread over the cores, and its triangle mesh (`sdfc mesh`'s mesher).
#pragma once
#include <atomic>
#include <cstddef>

#include "ir/scene.h"
#include "mesher.h"

namespace sdfc::api {

struct EvalBatch {
  const double* points = nullptr;  // n x 3, row-major
  size_t count = 0;
  double time = 0;
  double* distance = nullptr;  // n, or null
  double* gradient = nullptr;  // n x 3 (central differences, as `eval --gradient`), or null
  // n: index into scene.materials, the one the renderer shades with (a shape
  // without one takes the first); -1 only when the scene defines none. Or null.
  int* material = nullptr;
  int threads = 0;             // 0: every core
  // Checked between chunks: true stops early; evaluate() then returns false.
  const std::atomic<bool>* interrupt = nullptr;
};

// Fills the batch's outputs; false when interrupted.
bool evaluate(const ir::Scene& scene, const EvalBatch& batch);

// The mesh of `scene` (planGrid, sampling, dual contouring, welding).
inline MeshResult mesh(const ir::Scene& scene, const MeshOptions& options) { return meshScene(scene, options); }

}  // namespace sdfc::api
