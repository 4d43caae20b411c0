#include "emit/env_map_glsl.h"

#include <cmath>
#include <cstdlib>
#include <cstring>

#include "emit/embedded_sources.h"
#include "emit/feature_filter.h"
#include "emit/glsl_emitter.h"
#include "eval/env_map.h"

namespace sdfc {
namespace {

float wordAsFloat(uint32_t w) {
  float f;
  std::memcpy(&f, &w, sizeof f);
  return f;
}

void padToVec4(std::vector<float>& data) {
  while (data.size() % 4) data.push_back(0.0f);
}

// Halvings that find an index among n.
int searchSteps(int n) {
  int steps = 0;
  while ((1 << steps) < n) ++steps;
  return steps;
}

}  // namespace

EnvMapLayout appendEnvMapData(const ir::Sky& sky, std::vector<float>& data) {
  // A benchmark's baseline only (bench/env_map.py): uniform directions.
  const char* sampling = std::getenv("SDFC_ENVMAP_SAMPLING");
  const EnvMapData map = buildEnvMap(*sky.map, sampling && std::string(sampling) == "uniform");
  EnvMapLayout l;
  l.width = map.width;
  l.height = map.height;
  l.grid_x = map.grid_x;
  l.grid_y = map.grid_y;
  l.scale = map.scale;
  padToVec4(data);
  l.texels = data.size();
  // Shared-exponent words are never a NaN or infinity as floats
  // (eval/shared_exponent.h): carried in the float data as they are.
  data.reserve(data.size() + map.texels.size() + map.column_cdf.size() + map.row_cdf.size() + 8);
  for (uint32_t w : map.texels) data.push_back(wordAsFloat(w));
  l.column_cdf = data.size();
  data.insert(data.end(), map.column_cdf.begin(), map.column_cdf.end());
  l.row_cdf = data.size();
  data.insert(data.end(), map.row_cdf.begin(), map.row_cdf.end());
  padToVec4(data);
  return l;
}

void emitEnvMap(const ir::Sky& sky, const EnvMapLayout& l, const std::set<std::string>& features,
                std::ostringstream& out) {
  const double a = sky.rotation_degrees * M_PI / 180.0;
  out << "\n// The environment map (sky(map: ...)): " << l.width << " x " << l.height << " texels.\n";
  out << "const int kEnvWidth = " << l.width << ", kEnvHeight = " << l.height << ";\n";
  out << "const int kEnvTexels = " << l.texels << ", kEnvColumnCdf = " << l.column_cdf
      << ", kEnvRowCdf = " << l.row_cdf << ";\n";
  out << "const int kEnvCellsX = " << l.width - 1 << ", kEnvCellsY = " << l.height - 1
      << ";  // the cells between texel centres\n";
  out << "const int kEnvGridX = " << l.grid_x << ", kEnvGridY = " << l.grid_y
      << ";  // the sampling grid's cells (at most 512 x 256)\n";
  out << "const int kEnvColumnSteps = " << searchSteps(l.grid_x) << ", kEnvRowSteps = " << searchSteps(l.grid_y)
      << ";\n";
  out << "const float kEnvScale = " << glslFloat(sky.strength * l.scale) << ";  // strength x storage scale\n";
  out << "const vec2 kEnvRotation = vec2(" << glslFloat(std::cos(a)) << ", " << glslFloat(std::sin(a)) << ");\n";
  out << "const float kEnvPdfScale = " << glslFloat(double(l.grid_x) * l.grid_y / (2 * M_PI * M_PI))
      << ";  // grid cells per steradian at sin(theta) = 1\n";
  out << filterFeatures(embeddedSource("kernel/envmap.glsl"), features);
}

}  // namespace sdfc
