// A sharp union's parts pruned per cell of a grid (passes/prune_grid.cpp): in
// each cell, the parts that can be the nearest there. Evaluating only those
// gives the union's value at every point of the cell (the others are farther
// than one of them everywhere in it), so the shader looks up its cell and
// skips the rest (issue 46: each point pays for the parts near it).
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

namespace sdfc::ir {

struct Node;

// Bits of a cell's mask per float of the shader's vec4 (a float holds
// integers below 2^24 exactly): at most 4 * 24 parts take part.
constexpr int kPruneBitsPerWord = 24;
constexpr int kPruneMaxParts = 4 * kPruneBitsPerWord;

struct PruneGrid {
  // The union's parts, nested sharp unions flattened into it, each with the
  // material it inherits from the unions it was taken out of (-1: the root's).
  std::vector<std::shared_ptr<Node>> parts;
  std::vector<int> inherited;
  // Per part: its bit in a cell's mask, or -1 for a part evaluated everywhere
  // (unbounded, moving with time, or without a Lipschitz bound).
  std::vector<int> bit;
  glm::dvec3 lo{0};
  double cell = 0;
  glm::ivec3 dims{0};
  std::vector<std::array<std::uint32_t, 4>> masks;  // per cell, x fastest; 24 bits a word
  // For --emit ir: the share of the pruned parts' cost a cell keeps, over all
  // cells and over cells near a surface; the time the grid took.
  double kept_cost = 1, kept_cost_near = 1;
  double build_seconds = 0;

  size_t prunedParts() const {
    size_t n = 0;
    for (int b : bit) n += b >= 0;
    return n;
  }
  // Whether a cell with `mask` evaluates part i (a part without a bit: everywhere).
  bool lists(const std::array<std::uint32_t, 4>& mask, size_t i) const {
    const int b = bit[i];
    return b < 0 || ((mask[b / kPruneBitsPerWord] >> (b % kPruneBitsPerWord)) & 1u) != 0;
  }
};

}  // namespace sdfc::ir
