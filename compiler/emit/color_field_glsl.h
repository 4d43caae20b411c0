// GLSL for colour fields: sdMaterialAt(id, p, n), the material of id with its
// colour field evaluated at shading point p with normal n (the kernel calls it
// when SDFC_HAS_FIELDS is set). The closed forms are eval/color_field.cpp's.
#pragma once
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "ir/scene.h"

namespace sdfc {

// The SDFC_HAS_FIELDS / SDFC_HAS_NOISE / SDFC_HAS_TEXTURE features of the used materials.
void addFieldFeatures(const ir::Scene& scene, const std::vector<bool>& used, std::set<std::string>& features);
// Appends the used textures' texels to the scene data (one vec4 each) and
// returns where each image starts, in vec4s.
std::map<const ir::TextureImage*, size_t> appendTextureData(const ir::Scene& scene, const std::vector<bool>& used,
                                                           std::vector<float>& data);
// Writes sdMaterialAt for the used materials that have fields
// (`noise_emitted`: the scene code already holds kernel/noise.glsl, for displace).
void emitFieldMaterials(const ir::Scene& scene, const std::vector<bool>& used,
                        const std::map<const ir::TextureImage*, size_t>& texture_bases, std::ostringstream& out,
                        bool noise_emitted = false);

}  // namespace sdfc
