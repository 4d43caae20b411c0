// GLSL for the environment light sky(map: ...): its texels and sampling
// distribution appended to the scene data, and sdSky with the sampling
// functions of kernel/envmap.glsl (SDFC_HAS_ENVMAP; docs/lighting.md).
#pragma once
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "ir/scene.h"

namespace sdfc {

// Where the map's data lie in the scene data, in floats, and its size.
struct EnvMapLayout {
  size_t texels = 0, column_cdf = 0, row_cdf = 0;
  int width = 0, height = 0;
  int grid_x = 0, grid_y = 0;  // the sampling grid (eval/env_map.h)
  float scale = 1;
};

// Builds the map's distribution (eval/env_map.h) and appends it, vec4-aligned.
EnvMapLayout appendEnvMapData(const ir::Sky& sky, std::vector<float>& data);
// Writes the constants, sdSky and (SDFC_TRACE) the sampling functions.
void emitEnvMap(const ir::Sky& sky, const EnvMapLayout& layout, const std::set<std::string>& features,
                std::ostringstream& out);

}  // namespace sdfc
