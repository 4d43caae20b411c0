#include "eval/alias_table.h"

#include <algorithm>
#include <cmath>

namespace sdfc {

AliasTable buildAliasTable(const std::vector<double>& weights) {
  const int n = int(weights.size());
  AliasTable t;
  t.threshold.assign(n, 0.0f);
  t.alias.resize(n);
  double sum = 0;
  for (double w : weights) sum += w;
  // Each outcome's weight in buckets (n * its probability): under 1 it
  // needs an alias to fill its bucket, over 1 it lends to others.
  std::vector<double> scaled(n);
  std::vector<int> small, large;
  for (int i = 0; i < n; ++i) {
    t.alias[i] = i;
    scaled[i] = weights[i] * n / sum;
    (scaled[i] < 1.0 ? small : large).push_back(i);
  }
  while (!small.empty() && !large.empty()) {
    const int s = small.back(), l = large.back();
    small.pop_back();
    t.threshold[s] = float(scaled[s]);
    t.alias[s] = l;
    scaled[l] -= 1.0 - scaled[s];  // Vose: what l lent, taken from its own weight
    if (scaled[l] < 1.0) {
      large.pop_back();
      small.push_back(l);
    }
  }
  // What rounding leaves over is within an ulp of a full bucket: its own.
  // One of weight 0 left over (only if rounding went far) lends nothing, so
  // it stays never drawn, its bucket given to an outcome that has weight.
  const int some_positive = int(std::max_element(weights.begin(), weights.end()) - weights.begin());
  for (int i : large) t.threshold[i] = 1.0f;
  for (int i : small) {
    t.threshold[i] = weights[i] > 0 ? 1.0f : 0.0f;
    if (weights[i] <= 0) t.alias[i] = some_positive;
  }
  return t;
}

int sampleAlias(const float* threshold, const int* alias, int n, float u, float& remainder) {
  const float s = u * float(n);
  const int bucket = std::min(int(s), n - 1);
  // (As the kernel: float32, and the remainder kept below 1.)
  const float f = std::min(s - float(bucket), 0x1.fffffep-1f);
  const float q = threshold[bucket];
  if (f < q) {
    remainder = std::min(f / q, 0x1.fffffep-1f);
    return bucket;
  }
  remainder = std::min((f - q) / (1.0f - q), 0x1.fffffep-1f);
  return alias[bucket];
}

}  // namespace sdfc
