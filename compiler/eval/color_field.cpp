#include "eval/color_field.h"

#include <algorithm>
#include <cmath>

#include "eval/noise.h"

namespace sdfc {

double fieldBlend(const ir::ColorField& f, const glm::dvec3& p, double time) {
  const double size = f.size.at(time);
  switch (f.kind) {
    case ir::FieldKind::Checker: {
      const glm::dvec3 cell = glm::floor(p / size);
      const double parity = cell.x + cell.y + cell.z;
      return parity - 2 * std::floor(parity / 2);
    }
    case ir::FieldKind::Stripes: {
      const double u = glm::dot(p, f.axis) / size;
      return u - std::floor(u) < 0.5 ? 0 : 1;
    }
    case ir::FieldKind::Gradient: {
      const double from = f.from.at(time), to = f.to.at(time);
      return std::clamp((glm::dot(p, f.axis) - from) / (to - from), 0.0, 1.0);
    }
    case ir::FieldKind::Noise:
      return std::clamp(0.5 + 0.5 * fractalNoise(p * size, f.octaves), 0.0, 1.0);
    case ir::FieldKind::Texture: return 0;
  }
  return 0;
}

glm::dvec3 fieldPoint(const ir::ColorField& f, const glm::dvec3& p, const glm::dvec3& n, double time) {
  if (f.kind != ir::FieldKind::Checker && f.kind != ir::FieldKind::Stripes) return p;
  return p - n * (kFieldInset * f.size.at(time));
}

glm::dvec3 textureBilinear(const ir::TextureImage& image, double u, double v) {
  const int w = image.width, h = image.height;
  const double s = u * w - 0.5, t = v * h - 0.5;
  const double cs = std::floor(s), ct = std::floor(t);
  const double fs = s - cs, ft = t - ct;
  // Wrapped, as the shader does it (emit/kernel/texture.glsl).
  const int i0 = std::min(int(cs - w * std::floor(cs / w)), w - 1), j0 = std::min(int(ct - h * std::floor(ct / h)), h - 1);
  const int i1 = i0 + 1 == w ? 0 : i0 + 1, j1 = j0 + 1 == h ? 0 : j0 + 1;
  auto texel = [&](int i, int j) {  // j counted from the bottom row
    const float* c = &image.rgb[(size_t(h - 1 - j) * w + i) * 3];
    return glm::dvec3(c[0], c[1], c[2]);
  };
  const glm::dvec3 bottom = texel(i0, j0) * (1 - fs) + texel(i1, j0) * fs;
  const glm::dvec3 top = texel(i0, j1) * (1 - fs) + texel(i1, j1) * fs;
  return bottom * (1 - ft) + top * ft;
}

glm::dvec3 textureTriplanar(const ir::TextureImage& image, const glm::dvec3& p, const glm::dvec3& n, double size) {
  glm::dvec3 w = n * n;
  w *= w;
  w /= w.x + w.y + w.z;
  const glm::dvec3 q = p / size;
  return textureBilinear(image, q.z, q.y) * w.x + textureBilinear(image, q.x, q.z) * w.y +
         textureBilinear(image, q.x, q.y) * w.z;
}

glm::dvec3 fieldColor(const ir::ColorField& f, const glm::dvec3& p, const glm::dvec3& n, double time) {
  if (f.kind == ir::FieldKind::Texture) return textureTriplanar(*f.image, p, n, f.size.at(time));
  const double t = fieldBlend(f, fieldPoint(f, p, n, time), time);
  const glm::dvec3 a = f.a.at(time), b = f.b.at(time);
  return a + (b - a) * t;
}

glm::dvec3 materialColor(const ir::Material& m, const glm::dvec3& p, const glm::dvec3& n, double time) {
  const bool emitter = m.model == ir::MaterialModel::Emissive;
  if (m.field) return fieldColor(*m.field, p, n, time) * m.field_scale;
  return emitter ? m.emission.at(time) : m.albedo.at(time);
}

}  // namespace sdfc
