// The float64 reference: distance, gradient and material of the checked
// scene at any point and time. The generated shaders are tested against it.
#pragma once
#include <glm/glm.hpp>

#include "ir/scene.h"

namespace sdfc {

struct EvalResult {
  double distance = 0;
  int material = -1;  // -1: no material set anywhere above the surface
};

class Evaluator {
 public:
  Evaluator(const ir::Scene& scene, double time = 0) : scene_(scene), time_(time) {}
  EvalResult at(const glm::dvec3& p) const;
  double distance(const glm::dvec3& p) const { return at(p).distance; }
  // Central differences with step h (float64 keeps this accurate to ~1e-8).
  glm::dvec3 gradient(const glm::dvec3& p, double h = 1e-6) const;
  // The same for any node (tests evaluate single primitives and operators).
  EvalResult evalNode(const ir::Node& node, const glm::dvec3& p, int inherited) const;
  // Instance i of an Instances node alone (tests check the grid's bound with it).
  double instanceDistance(const ir::Node& node, size_t i, const glm::dvec3& p) const {
    return evalInstance(node, i, p, -1).distance;
  }

 private:
  EvalResult evalInstances(const ir::Node& node, const glm::dvec3& p, int inherited) const;
  EvalResult evalInstance(const ir::Node& node, size_t i, const glm::dvec3& p, int inherited) const;
  EvalResult evalBlend(const ir::Node& node, const glm::dvec3& p, int inherited, double k) const;

  const ir::Scene& scene_;
  double time_;
};

// Smooth minimum/maximum (Quilez's polynomial smin): lowers min(a, b) by at
// most k/4 where |a - b| < k. Shared by evaluator and tests.
double smoothMin(double a, double b, double k);
double smoothMax(double a, double b, double k);

// The cell a repeated point falls in, for cell size `cell` and `count`
// copies (0 = infinite), and its offset inside that cell.
double repeatCellIndex(double x, double cell, int count);
// Where twist, bend and repeat_polar read their child (docs/language.md):
// p turned about y by -rate * p.y degrees; p turned about y so that its
// (x, z) angle grows by rate * p.x degrees; p turned back by `radians` of
// (x, z) angle (onto sector 0).
glm::dvec3 twistPoint(const glm::dvec3& p, double degrees_per_unit);
glm::dvec3 bendPoint(const glm::dvec3& p, double degrees_per_unit);
glm::dvec3 polarPoint(const glm::dvec3& p, double radians);

}  // namespace sdfc
