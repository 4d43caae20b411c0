// A linear RGBA float image in row-major order, top row first.
#pragma once
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace sdfc {

struct FloatImage {
  uint32_t width = 0, height = 0;
  std::vector<float> rgba;  // width * height * 4

  FloatImage() = default;
  FloatImage(uint32_t w, uint32_t h, float fill = 0.0f)
      : width(w), height(h), rgba(size_t(w) * h * 4, fill) {}

  size_t pixelCount() const { return size_t(width) * height; }
  bool empty() const { return rgba.empty(); }
  float* at(uint32_t x, uint32_t y) { return &rgba[(size_t(y) * width + x) * 4]; }
  const float* at(uint32_t x, uint32_t y) const { return &rgba[(size_t(y) * width + x) * 4]; }
};

// The denoisers' check of their inputs: throws std::invalid_argument(message)
// unless b has a's size.
inline void requireSameSize(const FloatImage& a, const FloatImage& b, const std::string& message) {
  if (a.width != b.width || a.height != b.height || a.rgba.size() != b.rgba.size())
    throw std::invalid_argument(message);
}

}  // namespace sdfc
