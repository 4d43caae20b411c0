#include "emit/color_field_glsl.h"

#include "emit/embedded_sources.h"
#include "emit/glsl_emitter.h"
#include "eval/color_field.h"

namespace sdfc {
namespace {

std::string vec3Of(const glm::dvec3& v) {
  return "vec3(" + glslFloat(v.x) + ", " + glslFloat(v.y) + ", " + glslFloat(v.z) + ")";
}

std::string inset(const ir::ColorField& f) { return "(" + glslFloat(kFieldInset) + " * " + f.size.glsl() + ")"; }

// The blend t of field f at point q with outward normal n, as a GLSL expression.
std::string blend(const ir::ColorField& f) {
  switch (f.kind) {
    // Read kFieldInset of the size inside the surface (eval/color_field.h):
    // a face on a cell boundary has one colour, not speckles.
    case ir::FieldKind::Checker:
      return "mod(dot(floor((q - n * " + inset(f) + ") / " + f.size.glsl() + "), vec3(1.0)), 2.0)";
    case ir::FieldKind::Stripes:
      return "step(0.5, fract(dot(q - n * " + inset(f) + ", " + vec3Of(f.axis) + ") / " + f.size.glsl() + "))";
    case ir::FieldKind::Gradient:
      return "clamp((dot(q, " + vec3Of(f.axis) + ") - " + f.from.glsl() + ") / (" + f.to.glsl() + " - " +
             f.from.glsl() + "), 0.0, 1.0)";
    case ir::FieldKind::Noise:
      return "clamp(0.5 + 0.5 * sdFractalNoise(q * " + f.size.glsl() + ", " + std::to_string(f.octaves) +
             "), 0.0, 1.0)";
    case ir::FieldKind::Texture: break;  // not a blend (colourOf)
  }
  return "0.0";
}

bool hasField(const ir::Scene& scene, const std::vector<bool>& used, size_t i) {
  return i < used.size() && used[i] && scene.materials[i].field;
}

bool usesKind(const ir::Scene& scene, const std::vector<bool>& used, ir::FieldKind kind) {
  for (size_t i = 0; i < scene.materials.size(); ++i)
    if (hasField(scene, used, i) && scene.materials[i].field->kind == kind) return true;
  return false;
}

std::string colourOf(const ir::ColorField& f, const std::map<const ir::TextureImage*, size_t>& bases) {
  if (f.kind == ir::FieldKind::Texture)
    return "sdTextureTriplanar(" + std::to_string(bases.at(f.image.get())) + ", " + std::to_string(f.image->width) +
           ", " + std::to_string(f.image->height) + ", q, n, " + f.size.glsl() + ")";
  return "mix(" + f.a.glsl() + ", " + f.b.glsl() + ", " + blend(f) + ")";
}

}  // namespace

void addFieldFeatures(const ir::Scene& scene, const std::vector<bool>& used, std::set<std::string>& features) {
  for (size_t i = 0; i < scene.materials.size(); ++i) {
    if (!hasField(scene, used, i)) continue;
    features.insert("SDFC_HAS_FIELDS");
    if (scene.materials[i].field->kind == ir::FieldKind::Noise) features.insert("SDFC_HAS_NOISE");
    if (scene.materials[i].field->kind == ir::FieldKind::Texture) features.insert("SDFC_HAS_TEXTURE");
  }
}

std::map<const ir::TextureImage*, size_t> appendTextureData(const ir::Scene& scene, const std::vector<bool>& used,
                                                           std::vector<float>& data) {
  std::map<const ir::TextureImage*, size_t> bases;
  for (size_t i = 0; i < scene.materials.size(); ++i) {
    if (!hasField(scene, used, i) || scene.materials[i].field->kind != ir::FieldKind::Texture) continue;
    const ir::TextureImage* image = scene.materials[i].field->image.get();
    if (bases.count(image)) continue;
    bases[image] = data.size() / 4;
    data.reserve(data.size() + image->rgb.size() / 3 * 4);
    for (size_t t = 0; t + 2 < image->rgb.size(); t += 3)
      data.insert(data.end(), {image->rgb[t], image->rgb[t + 1], image->rgb[t + 2], 1.0f});
  }
  return bases;
}

void emitFieldMaterials(const ir::Scene& scene, const std::vector<bool>& used,
                        const std::map<const ir::TextureImage*, size_t>& texture_bases, std::ostringstream& out,
                        bool noise_emitted) {
  bool any = false;
  for (size_t i = 0; i < scene.materials.size(); ++i) any = any || hasField(scene, used, i);
  if (!any) return;
  const size_t n = scene.materials.size();
  if (usesKind(scene, used, ir::FieldKind::Noise) && !noise_emitted) out << "\n" << embeddedSource("kernel/noise.glsl");
  if (usesKind(scene, used, ir::FieldKind::Texture)) out << "\n" << embeddedSource("kernel/texture.glsl");
  out << "\n// Colour fields: of the world point, once per shading point.\n";
  out << "Material sdMaterialAt(int id, vec3 p, vec3 n) {\n  Material m = sdMaterial(id);\n";
  // Fields are of world points; the kernel's frame is the world minus origin.
  if (scene.origin != glm::dvec3(0)) out << "  vec3 q = p + " << vec3Of(scene.origin) << ";\n";
  else out << "  vec3 q = p;\n";
  // sdMaterial's fallback: an id it does not list is material 0.
  out << "  int k = id >= 1 && id < " << n << " ? id : 0;\n";
  for (size_t i = 0; i < n; ++i) {
    if (!hasField(scene, used, i)) continue;
    const ir::Material& m = scene.materials[i];
    const ir::ColorField& f = *m.field;
    const std::string colour = colourOf(f, texture_bases);
    out << "  if (k == " << i << ") ";
    if (m.model == ir::MaterialModel::Emissive)
      out << "m.emission = " << colour << " * " << glslFloat(m.field_scale) << ";";
    else
      out << "m.albedo = " << colour << ";";
    out << "  // " << m.name << "\n";
  }
  out << "  return m;\n}\n";
}

}  // namespace sdfc
