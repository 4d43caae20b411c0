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
  const size_t cells = map.cell_p.size();
  data.reserve(data.size() + map.texels.size() + 4 * (cells + map.grid_y) + 8);
  for (uint32_t w : map.texels) data.push_back(wordAsFloat(w));
  // A vec4 a cell: (threshold, alias, p, p of the alias), the alias's p so
  // that a draw is one read; then a vec4 a row: (threshold, alias, 0, 0).
  padToVec4(data);
  l.cells = data.size();
  for (size_t i = 0; i < cells; ++i) {
    const size_t row = i - i % size_t(map.grid_x);
    const int alias = map.cells.alias[i];
    data.insert(data.end(), {map.cells.threshold[i], float(alias), map.cell_p[i], map.cell_p[row + alias]});
  }
  l.rows = data.size();
  for (int y = 0; y < map.grid_y; ++y) data.insert(data.end(), {map.rows.threshold[y], float(map.rows.alias[y]), 0.0f, 0.0f});
  padToVec4(data);
  return l;
}

void emitEnvMap(const ir::Sky& sky, const EnvMapLayout& l, const std::set<std::string>& features,
                std::ostringstream& out) {
  const double a = sky.rotation_degrees * M_PI / 180.0;
  out << "\n// The environment map (sky(map: ...)): " << l.width << " x " << l.height << " texels.\n";
  out << "const int kEnvWidth = " << l.width << ", kEnvHeight = " << l.height << ";\n";
  out << "const int kEnvTexels = " << l.texels << ", kEnvCells = " << l.cells / 4 << ", kEnvRows = " << l.rows / 4
      << ";  // kEnvTexels in words, the others in vec4s\n";
  out << "const int kEnvCellsX = " << l.width - 1 << ", kEnvCellsY = " << l.height - 1
      << ";  // the cells between texel centres\n";
  out << "const int kEnvGridX = " << l.grid_x << ", kEnvGridY = " << l.grid_y
      << ";  // the sampling grid's cells (at most 512 x 256)\n";
  out << "const float kEnvScale = " << glslFloat(sky.strength * l.scale) << ";  // strength x storage scale\n";
  out << "const vec2 kEnvRotation = vec2(" << glslFloat(std::cos(a)) << ", " << glslFloat(std::sin(a)) << ");\n";
  out << "const float kEnvPdfScale = " << glslFloat(double(l.grid_x) * l.grid_y / (2 * M_PI * M_PI))
      << ";  // grid cells per steradian at sin(theta) = 1\n";
  out << filterFeatures(embeddedSource("kernel/envmap.glsl"), features);
}

}  // namespace sdfc
