#include "render_layers.h"

#include <algorithm>
#include <cmath>
#include <iterator>

#include "camera.h"
#include "eval/evaluator.h"
#include "for_each_row.h"

namespace sdfc {

void layerIdsAt(const ir::Scene& scene, double time, const glm::dvec3& o, const glm::dvec3& d, double t,
                int& object, int& material) {
  object = -1;
  material = -1;
  if (!scene.root) return;
  // Past the hit by far more than the float32 depth's error, so the point lies
  // inside the shape the ray enters (the kernel reads its material so too).
  const glm::dvec3 q = o + d * (t + 1e-4 * (1.0 + t));
  const Evaluator evaluator(scene, time);
  const ir::Node& root = *scene.root;
  const bool shapes = root.kind == ir::NodeKind::Union && !root.children.empty();
  if (!shapes) {
    object = 0;
    material = evaluator.evalNode(root, q, -1).material;
  } else {
    double best = INFINITY;
    for (size_t i = 0; i < root.children.size(); ++i) {
      const EvalResult r = evaluator.evalNode(*root.children[i], q, root.material);
      if (r.distance < best) {
        best = r.distance;
        object = int(i);
        material = r.material;
      }
    }
  }
  // A shape with no material anywhere above it is drawn with material 0.
  material = std::max(material, 0);
}

const char* const kLayerRayChannelNames[9] = {"albedo.R", "albedo.G", "albedo.B", "N.X", "N.Y", "N.Z",
                                              "Z",        "material", "object"};

std::vector<ExrChannel> layerSampleChannels(const FloatImage& color, uint64_t samples) {
  const size_t pixels = size_t(color.width) * color.height;
  std::vector<ExrChannel> c;
  for (const char* name : {"R", "G", "B", "variance.Y"}) c.push_back({name, std::vector<float>(pixels)});
  const double n = double(samples);
  for (size_t i = 0; i < pixels; ++i) {
    const float* rgba = &color.rgba[i * 4];
    for (int k = 0; k < 3; ++k) c[k].values[i] = rgba[k];
    // Variance of the pixel's mean luminance: the samples' (unbiased) variance / n.
    const double mean_y = 0.2126 * rgba[0] + 0.7152 * rgba[1] + 0.0722 * rgba[2];
    const double var = n >= 2 ? std::max(0.0, (double(rgba[3]) - mean_y * mean_y) * n / (n - 1)) / n : 0.0;
    c[3].values[i] = float(var);
  }
  return c;
}

std::vector<ExrChannel> layerRayChannels(const CompiledScene& compiled, const CameraDesc& camera,
                                         const RenderSettings& settings, const RenderOutput& out) {
  const uint32_t w = settings.width, h = settings.height;
  const size_t pixels = size_t(w) * h;
  std::vector<ExrChannel> c;
  for (const char* name : kLayerRayChannelNames) c.push_back({name, std::vector<float>(pixels)});
  // The camera ray through each pixel's centre, as the kernel's cameraRay
  // (pinhole; its float32 frame parameters, in double).
  const gpu::FrameParams frame = makeFrameParams(camera, w, h, settings.time);
  const glm::dvec3 origin(frame.cam_origin), right(frame.cam_right), up(frame.cam_up), forward(frame.cam_forward);
  const double tan_half = frame.cam_origin.w, aspect = double(w) / double(h);
  // Rows on both cores: the ids are a float64 evaluation of every top-level
  // shape per pixel, the layers' dearest part on the CPU.
  forEachRow(int(h), [&](int row) {
    const uint32_t y = uint32_t(row);
    for (uint32_t x = 0; x < w; ++x) {
      const size_t i = size_t(y) * w + x;
      const float* nd = &out.normal_depth.rgba[i * 4];
      const float* as = &out.albedo_steps.rgba[i * 4];
      for (int k = 0; k < 3; ++k) {
        c[k].values[i] = as[k];
        c[3 + k].values[i] = nd[k];
      }
      const bool hit = nd[3] >= 0;
      c[6].values[i] = hit ? nd[3] : kLayersMissDepth;
      int object = -1, material = -1;
      if (hit) {
        const double ndc_x = 2.0 * (x + 0.5) / w - 1.0, ndc_y = 1.0 - 2.0 * (y + 0.5) / h;
        const glm::dvec3 d = glm::normalize(forward + (ndc_x * aspect * tan_half) * right + (ndc_y * tan_half) * up);
        layerIdsAt(compiled.scene, settings.time, origin, d, nd[3], object, material);
      }
      c[7].values[i] = hit ? float(material) : kLayersMissId;
      c[8].values[i] = hit ? float(object) : kLayersMissId;
    }
  });
  return c;
}

std::vector<ExrChannel> renderLayers(const CompiledScene& compiled, const CameraDesc& camera,
                                     const RenderSettings& settings, const RenderOutput& out) {
  std::vector<ExrChannel> c = layerSampleChannels(out.color, out.samples_done);
  std::vector<ExrChannel> ray = layerRayChannels(compiled, camera, settings, out);
  c.insert(c.end(), std::make_move_iterator(ray.begin()), std::make_move_iterator(ray.end()));
  return c;
}

}  // namespace sdfc
