#include "denoise_features.h"

namespace sdfc {

std::vector<float> boxMean(const std::vector<float>& in, int w, int h, int channels, int radius) {
  std::vector<float> row(in.size()), out(in.size());
  forEachRow(h, [&](int y) {
    for (int x = 0; x < w; ++x) {
      const int x0 = std::max(0, x - radius), x1 = std::min(w - 1, x + radius);
      for (int c = 0; c < channels; ++c) {
        float sum = 0;
        for (int q = x0; q <= x1; ++q) sum += in[(size_t(y) * w + q) * channels + c];
        row[(size_t(y) * w + x) * channels + c] = sum / float(x1 - x0 + 1);
      }
    }
  });
  forEachRow(h, [&](int y) {
    const int y0 = std::max(0, y - radius), y1 = std::min(h - 1, y + radius);
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < channels; ++c) {
        float sum = 0;
        for (int q = y0; q <= y1; ++q) sum += row[(size_t(q) * w + x) * channels + c];
        out[(size_t(y) * w + x) * channels + c] = sum / float(y1 - y0 + 1);
      }
  });
  return out;
}

Features::Features(const FloatImage& normal_depth, const FloatImage& albedo_steps)
  : width(int(normal_depth.width)), height(int(normal_depth.height)) {
  const size_t n = normal_depth.pixelCount();
  hit.resize(n);
  normal.resize(n * 3);
  depth.resize(n);
  albedo.resize(n * 3);
  depth_dx.assign(n, 0.0f);
  depth_dy.assign(n, 0.0f);
  for (size_t i = 0; i < n; ++i) {
    hit[i] = normal_depth.rgba[i * 4 + 3] >= 0.0f;
    depth[i] = normal_depth.rgba[i * 4 + 3];
    for (int c = 0; c < 3; ++c) {
      normal[i * 3 + c] = normal_depth.rgba[i * 4 + c];
      albedo[i * 3 + c] = albedo_steps.rgba[i * 4 + c];
    }
  }
  auto depth_at = [&](size_t q) { return depth[q]; };
  auto hit_at = [&](size_t q) { return hit[q] != 0; };
  auto slope = [&](size_t i, long back, long ahead, bool has_back, bool has_ahead) {
    return depthSlope(i, back, ahead, has_back, has_ahead, depth_at, hit_at);
  };
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const size_t i = size_t(y) * width + x;
      if (!hit[i]) continue;
      depth_dx[i] = slope(i, -1, 1, x > 0, x + 1 < width);
      depth_dy[i] = slope(i, -long(width), long(width), y > 0, y + 1 < height);
    }
}

}  // namespace sdfc
