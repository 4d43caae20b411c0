#include "api/evaluate.h"

#include <vector>

#include "eval/block_evaluator.h"
#include "parallel.h"

namespace sdfc::api {

bool evaluate(const ir::Scene& scene, const EvalBatch& b) {
  // Large batches evaluate each point's listed parts only (the same bits):
  // the grid's 10-20 ms pay from about this many points.
  const BlockEvaluator evaluator(scene, b.time, b.count >= 100000);
  std::atomic<bool> stopped{false};
  std::vector<BlockEvaluator::Scratch> scratch(workerCount(b.threads));
  // Chunks small enough that an interrupt is seen quickly, large enough to cost nothing.
  parallelFor(b.count, 4096, b.threads, [&](size_t begin, size_t end, int worker) {
    if (b.interrupt && b.interrupt->load()) {
      stopped = true;
      return;
    }
    const double* p = b.points + 3 * begin;
    const size_t n = end - begin;
    if (b.distance || b.material)
      evaluator.evaluate(p, n, b.distance ? b.distance + begin : nullptr, b.material ? b.material + begin : nullptr,
                         scratch[worker]);
    // A shape with no material anywhere above it renders with the file's first
    // one (the shader's sdMaterial falls through to it): report that one too.
    if (b.material && !scene.materials.empty())
      for (size_t i = begin; i < end; ++i)
        if (b.material[i] < 0) b.material[i] = 0;
    if (b.gradient) evaluator.gradient(p, n, b.gradient + 3 * begin, scratch[worker]);
  });
  return !stopped;
}

}  // namespace sdfc::api
