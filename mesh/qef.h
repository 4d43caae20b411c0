// The quadric error function of dual contouring: the point minimising
// sum_i (n_i . (x - p_i))^2 over a cell's Hermite samples (p_i, n_i).
#pragma once
#include <glm/glm.hpp>

namespace sdfc {

class Qef {
 public:
  void add(const glm::dvec3& point, const glm::dvec3& normal);
  int count() const { return count_; }
  glm::dvec3 massPoint() const { return count_ ? point_sum_ / double(count_) : glm::dvec3(0); }
  // Minimiser of the QEF nearest the mass point: the pseudo-inverse of A^T A
  // drops directions whose singular value is below `relative_cutoff` times
  // the largest (Ju et al. 2002, section 2.3; Lindstrom 2000 for solving
  // about the mass point), so flat or curved-smooth samples stay near the
  // mass point instead of shooting off along the tangent.
  glm::dvec3 solve(double relative_cutoff = 0.1) const;

 private:
  glm::dmat3 ata_{0.0};
  glm::dvec3 atb_{0.0};  // sum n (n . p)
  glm::dvec3 point_sum_{0.0};
  int count_ = 0;
};

// Eigen-decomposition of a symmetric 3x3 matrix by cyclic Jacobi rotations:
// m = V diag(values) V^T, eigenvectors in V's columns.
void symmetricEigen(const glm::dmat3& m, glm::dvec3& values, glm::dmat3& vectors);

}  // namespace sdfc
