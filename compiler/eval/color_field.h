// Colour fields in float64: the reference the emitted GLSL is tested against,
// and what `sdfc eval --material` prints.
#pragma once
#include <glm/glm.hpp>

#include "ir/scene.h"

namespace sdfc {

// Checker and stripes change colour in a step: a face lying on a step (a
// floor at y = 0 under a checker) took either colour by the hit point's last
// bits, speckled. Their colour is that of the point this fraction of the
// field's size inside the surface, along the outward normal; the kernel's
// (emit/color_field_glsl.cpp) likewise.
constexpr double kFieldInset = 0.01;
// Where field f is read for the surface point p with outward unit normal n:
// p itself, or for checker and stripes p - n * kFieldInset * size.
glm::dvec3 fieldPoint(const ir::ColorField& field, const glm::dvec3& p, const glm::dvec3& n, double time);

// The blend t in [0, 1] of a procedural field at world point p and time.
double fieldBlend(const ir::ColorField& field, const glm::dvec3& p, double time);
// The field's colour at world point p with unit surface normal n: mix(a, b, t),
// or a texture's triplanar colour (the normal only matters for textures).
glm::dvec3 fieldColor(const ir::ColorField& field, const glm::dvec3& p, const glm::dvec3& n, double time);
// A material's colour at p: albedo (tint) or, for an emitter, its emission.
glm::dvec3 materialColor(const ir::Material& material, const glm::dvec3& p, const glm::dvec3& n, double time);

// Texture lookups (docs/language.md, "Colour fields"): the image repeats
// over uv in [0, 1)^2, v up (the image's top row at v near 1), bilinear
// between texel centres.
glm::dvec3 textureBilinear(const ir::TextureImage& image, double u, double v);
// Triplanar: the image on the yz, zx and xy planes (uv = (z, y), (x, z),
// (x, y) over size), weighted by n.x^4, n.y^4, n.z^4 normalised.
glm::dvec3 textureTriplanar(const ir::TextureImage& image, const glm::dvec3& p, const glm::dvec3& n, double size);

}  // namespace sdfc
