#include "api/evaluate.h"

#include "eval/evaluator.h"
#include "parallel.h"

namespace sdfc::api {

bool evaluate(const ir::Scene& scene, const EvalBatch& b) {
  const Evaluator evaluator(scene, b.time);
  std::atomic<bool> stopped{false};
  // Chunks small enough that an interrupt is seen quickly, large enough to cost nothing.
  parallelFor(b.count, 4096, b.threads, [&](size_t begin, size_t end, int) {
    if (b.interrupt && b.interrupt->load()) {
      stopped = true;
      return;
    }
    for (size_t i = begin; i < end; ++i) {
      const glm::dvec3 p(b.points[3 * i], b.points[3 * i + 1], b.points[3 * i + 2]);
      if (b.distance || b.material) {
        const EvalResult r = evaluator.at(p);
        if (b.distance) b.distance[i] = r.distance;
        if (b.material) b.material[i] = r.material;
      }
      if (b.gradient) {
        const glm::dvec3 g = evaluator.gradient(p);
        b.gradient[3 * i] = g.x;
        b.gradient[3 * i + 1] = g.y;
        b.gradient[3 * i + 2] = g.z;
      }
    }
  });
  return !stopped;
}

}  // namespace sdfc::api
