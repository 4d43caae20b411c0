#include "qef.h"

#include <algorithm>
#include <cmath>

namespace sdfc {

void Qef::add(const glm::dvec3& point, const glm::dvec3& normal) {
  ata_ += glm::outerProduct(normal, normal);
  atb_ += normal * glm::dot(normal, point);
  point_sum_ += point;
  ++count_;
}

void symmetricEigen(const glm::dmat3& m, glm::dvec3& values, glm::dmat3& vectors) {
  // a[c][r] in glm's column-major layout; symmetric, so rows = columns.
  double a[3][3];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) a[r][c] = m[c][r];
  double v[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (int sweep = 0; sweep < 32; ++sweep) {
    const double off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
    const double diag = a[0][0] * a[0][0] + a[1][1] * a[1][1] + a[2][2] * a[2][2];
    if (off <= 1e-30 * diag || off == 0) break;
    for (int p = 0; p < 2; ++p) {
      for (int q = p + 1; q < 3; ++q) {
        if (a[p][q] == 0) continue;
        // Golub & Van Loan, algorithm 8.4.1 (symmetric Schur decomposition).
        const double theta = (a[q][q] - a[p][p]) / (2 * a[p][q]);
        const double t = (theta >= 0 ? 1.0 : -1.0) / (std::fabs(theta) + std::sqrt(theta * theta + 1));
        const double c = 1 / std::sqrt(t * t + 1), s = t * c;
        for (int k = 0; k < 3; ++k) {  // a = J^T a J
          const double akp = a[k][p], akq = a[k][q];
          a[k][p] = c * akp - s * akq;
          a[k][q] = s * akp + c * akq;
        }
        for (int k = 0; k < 3; ++k) {
          const double apk = a[p][k], aqk = a[q][k];
          a[p][k] = c * apk - s * aqk;
          a[q][k] = s * apk + c * aqk;
        }
        for (int k = 0; k < 3; ++k) {
          const double vkp = v[k][p], vkq = v[k][q];
          v[k][p] = c * vkp - s * vkq;
          v[k][q] = s * vkp + c * vkq;
        }
      }
    }
  }
  for (int i = 0; i < 3; ++i) {
    values[i] = a[i][i];
    for (int r = 0; r < 3; ++r) vectors[i][r] = v[r][i];
  }
}

glm::dvec3 Qef::solve(double relative_cutoff) const {
  if (count_ == 0) return glm::dvec3(0);
  const glm::dvec3 mass = massPoint();
  // Solve A^T A x' = A^T b - A^T A m for the offset x' from the mass point.
  const glm::dvec3 rhs = atb_ - ata_ * mass;
  glm::dvec3 values;
  glm::dmat3 vectors;
  symmetricEigen(ata_, values, vectors);
  const double largest = std::max(values.x, std::max(values.y, values.z));
  if (!(largest > 0)) return mass;
  // Eigenvalues of A^T A are squared singular values of A.
  const double cutoff = relative_cutoff * relative_cutoff * largest;
  glm::dvec3 offset(0);
  for (int i = 0; i < 3; ++i) {
    if (values[i] < cutoff) continue;
    const glm::dvec3 e = vectors[i];
    offset += e * (glm::dot(e, rhs) / values[i]);
  }
  return mass + offset;
}

}  // namespace sdfc
