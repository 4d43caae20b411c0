// Walker's alias method (Walker 1977; Vose 1991's construction, stable in
// floating point): a discrete distribution over n outcomes drawn with one
// table read, whatever n is. Bucket i of n equal buckets holds outcome i
// with probability threshold[i] and alias[i] otherwise.
//
// The environment map's sampling uses it (eval/env_map.h): one read a draw
// instead of a binary search's log2(n) dependent reads, which the shader on
// lavapipe pays in full for every lane.
#pragma once
#include <vector>

namespace sdfc {

struct AliasTable {
  std::vector<float> threshold;  // in [0, 1]: the share of bucket i that is i
  std::vector<int> alias;        // what the rest of bucket i is
};

// weights: n >= 1 non-negative values with a positive sum. An outcome of
// weight 0 is never drawn: its threshold is 0 and it is nobody's alias.
AliasTable buildAliasTable(const std::vector<double>& weights);

// The outcome u in [0, 1) draws, and u's remainder, again uniform in [0, 1)
// and independent of the outcome (the fraction of the bucket, rescaled to the
// part of it the outcome holds): the caller's next uniform variable.
// threshold and alias: n entries of a table, or a part of one with aliases
// relative to its start (eval/env_map.h keeps a table a row in one array).
int sampleAlias(const float* threshold, const int* alias, int n, float u, float& remainder);

}  // namespace sdfc
