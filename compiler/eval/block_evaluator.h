// The float64 field for many points at once: the tree is walked once per
// block of kEvalBlock points and each node's operation is a loop over the
// block, with the node's constants (arguments, matrices, blend radii) worked
// out once per block instead of once per point. The operations per point are
// the per-point Evaluator's, in the same order, so the results are equal bit
// for bit (tests/block_evaluator_test.cpp checks every example and node kind).
#pragma once
#include <memory>
#include <vector>

#include "eval/evaluator.h"

namespace sdfc {

constexpr int kEvalBlock = 128;

struct PointBlock {
  double x[kEvalBlock], y[kEvalBlock], z[kEvalBlock];
  int count = 0;
  glm::dvec3 at(int i) const { return {x[i], y[i], z[i]}; }
  void set(int i, const glm::dvec3& p) {
    x[i] = p.x;
    y[i] = p.y;
    z[i] = p.z;
  }
};

struct BlockResult {
  double distance[kEvalBlock];
  int material[kEvalBlock];
};

class BlockEvaluator {
 public:
  // With `prune`, the root union's parts are evaluated per point only where
  // its prune grid lists them (passes/prune_grid.cpp; built here, 10-20 ms on
  // scenes of tens of parts): the same bits, each point paying for the parts
  // near it (`mesh` and large `eval` batches).
  BlockEvaluator(const ir::Scene& scene, double time = 0, bool prune = false);

  // Working memory for one thread: a block of points and results per tree
  // level, kept on the heap so a deep tree cannot overflow a thread's stack.
  class Scratch {
   public:
    struct Level {
      PointBlock points, extra;
      BlockResult result, other;
    };
    Level& level(size_t depth);

   private:
    std::vector<std::unique_ptr<Level>> levels_;
  };

  // The field at points.count <= kEvalBlock points.
  void at(const PointBlock& points, BlockResult& out, Scratch& scratch) const;
  // Any number of points, n x 3 row-major; distance and material may be null.
  void evaluate(const double* xyz, size_t n, double* distance, int* material, Scratch& scratch) const;
  // Central differences with step h, as Evaluator::gradient: n x 3 out.
  void gradient(const double* xyz, size_t n, double* gradient, Scratch& scratch, double h = 1e-6) const;

  // The per-point evaluator, for single points (the mesher's crossings and
  // Newton steps) and for the nodes walked point by point here.
  const Evaluator& pointwise() const { return point_; }

 private:
  void evalNode(const ir::Node& n, const PointBlock& p, int inherited, BlockResult& out, Scratch& scratch,
                size_t depth) const;

  // The root's parts at the points of `points` whose cell lists the same parts.
  void atPruned(const PointBlock& points, BlockResult& out, Scratch& scratch) const;

  const ir::Scene& scene_;
  double time_;
  Evaluator point_;
  std::shared_ptr<const ir::PruneGrid> prune_;
};

}  // namespace sdfc
