// Walker's alias tables (eval/alias_table.h): the distribution a table
// draws from, read back from its entries, is the one it was built from,
// for every kind of weights it meets (uniform, one spike, zeros, a single
// outcome, magnitudes 1e-30 to 1e30 apart); an outcome of weight 0 is never
// drawn; and the remainder a draw hands on is uniform.
#include "eval/alias_table.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace sdfc {
namespace {

// Each outcome's probability as the table draws it: its own share of its
// bucket and the rest of every bucket that names it, over n buckets.
std::vector<double> drawnProbabilities(const AliasTable& t) {
  const int n = int(t.threshold.size());
  std::vector<double> p(n, 0.0);
  for (int i = 0; i < n; ++i) {
    EXPECT_GE(t.threshold[i], 0.0f);
    EXPECT_LE(t.threshold[i], 1.0f);
    EXPECT_GE(t.alias[i], 0);
    EXPECT_LT(t.alias[i], n);
    p[i] += double(t.threshold[i]) / n;
    p[t.alias[i]] += (1.0 - double(t.threshold[i])) / n;
  }
  return p;
}

void expectDraws(const std::vector<double>& w) {
  const AliasTable t = buildAliasTable(w);
  ASSERT_EQ(t.threshold.size(), w.size());
  double sum = 0;
  for (double x : w) sum += x;
  const std::vector<double> p = drawnProbabilities(t);
  for (size_t i = 0; i < w.size(); ++i) {
    const double want = w[i] / sum;
    // float thresholds: within a float's rounding of each bucket it touches
    EXPECT_NEAR(p[i], want, 1e-7 * (want + 1.0 / w.size())) << "outcome " << i << " of " << w.size();
    if (w[i] == 0) {
      EXPECT_EQ(p[i], 0.0) << "outcome " << i << " has weight 0 and is drawn";
      EXPECT_EQ(t.threshold[i], 0.0f);
    }
  }
}

TEST(AliasTable, DrawsTheDistributionItWasBuiltFrom) {
  expectDraws({1.0});
  expectDraws({0.0, 3.0});
  expectDraws({1, 1, 1, 1, 1, 1, 1});
  expectDraws({1e6, 1, 1, 1, 1, 1, 1, 1, 1});
  expectDraws({0, 0, 5, 0, 0, 0, 1e-30, 0});
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int n : {2, 3, 63, 512, 1000}) {
    std::vector<double> smooth(n), spiky(n), sparse(n), wide(n);
    for (int i = 0; i < n; ++i) {
      smooth[i] = 1 + std::sin(i * 0.1);
      spiky[i] = unit(rng) < 0.01 ? 1e4 : unit(rng);
      sparse[i] = unit(rng) < 0.7 ? 0.0 : unit(rng);
      wide[i] = std::pow(10.0, 60 * unit(rng) - 30);
    }
    sparse[n / 2] = 1;  // some weight
    for (const auto& w : {smooth, spiky, sparse, wide}) expectDraws(w);
  }
}

TEST(AliasTable, SamplesAndTheirRemaindersAreUniform) {
  // u on a fine even grid: each outcome drawn in proportion to its weight,
  // and the remainders it hands on spread evenly over [0, 1).
  const std::vector<double> w = {0.5, 0.0, 2.0, 1.0, 0.25, 4.0, 0.0, 0.25};
  const AliasTable t = buildAliasTable(w);
  const int n = 1 << 20, kBins = 8;
  std::vector<double> count(w.size(), 0.0);
  std::vector<std::vector<double>> bins(w.size(), std::vector<double>(kBins, 0.0));
  for (int k = 0; k < n; ++k) {
    float r;
    const int i = sampleAlias(t.threshold.data(), t.alias.data(), int(w.size()), (k + 0.5f) / n, r);
    ASSERT_GE(r, 0.0f);
    ASSERT_LT(r, 1.0f);
    count[i] += 1;
    bins[i][std::min(int(r * kBins), kBins - 1)] += 1;
  }
  for (size_t i = 0; i < w.size(); ++i) {
    EXPECT_NEAR(count[i] / n, w[i] / 8.0, 1e-5) << "outcome " << i;
    if (count[i] == 0) continue;
    for (int b = 0; b < kBins; ++b)
      EXPECT_NEAR(bins[i][b] / count[i], 1.0 / kBins, 1e-3) << "outcome " << i << ", remainder bin " << b;
  }
}

}  // namespace
}  // namespace sdfc
