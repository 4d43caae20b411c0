// Per-pixel choice among candidate filterings of two independent sample halves
// (the cross-half selection of NFOR, Bitterli et al. 2016, sec. 5).
//
// Candidate k of half a, f_a^k, is compared with the other half b: b's noise is
// independent of a's, so E[(f_a^k - b)^2] = MSE(f_a^k) + Var b, the same Var b
// for every candidate; the candidate with the least squared difference,
// box-smoothed over a window (one pixel's difference is as noisy as b), has the
// least estimated error there; the candidates are blended by weights that fall
// steeply with the estimate (a hard choice follows the estimate's noise: castle
// relMSE 0.000217 against 0.000209 blended). Half b is chosen against a alike.
// Strong filters win on flat areas, weak ones at edges their weights blur.
//
// No bias at convergence: every candidate is the identity at zero variance, so
// the choice is too.
#pragma once
#include <vector>

namespace sdfc {

struct SelectParams {
  int radius = 2;  // box (2r+1)^2 over the squared differences (castle, glass Menger: 2 of 1, 2, 4, 7)
  // Squared differences divided by (value^2 + floor), value the candidates'
  // mean: the relative error a viewer (and relMSE) sees; 0 = absolute error.
  float relative_floor = 0.01f;
  // Candidate k's weight is (least e / e_k)^sharpness, e the smoothed squared
  // difference (castle, colonnade, glass Menger: 8 of 2, 4, 8; huge: the argmin).
  float sharpness = 8.0f;
};

// `candidates_a[k]`, `candidates_b[k]`: rgb planes (3 floats a pixel, w x h) of
// halves a and b filtered by candidate k; `a`, `b` the unfiltered halves.
// Writes each half's per-pixel blend to out_a, out_b; `choice` (if not null)
// gets the index of half a's least estimated error at each pixel.
void selectPerPixel(const std::vector<std::vector<float>>& candidates_a,
                    const std::vector<std::vector<float>>& candidates_b, const std::vector<float>& a,
                    const std::vector<float>& b, int w, int h, const SelectParams& params,
                    std::vector<float>& out_a, std::vector<float>& out_b,
                    std::vector<int>* choice = nullptr);

}  // namespace sdfc
