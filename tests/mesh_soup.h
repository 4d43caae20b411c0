// Triangle meshes made in the tests (none is stored): an icosphere, a union
// of two, and their bytes as binary STL and OBJ. Header-only because the test
// CMakeLists globs *_test.cpp only.
#pragma once
#include <glm/glm.hpp>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

namespace sdfc::test {

using glm::dvec3;

struct Soup {
  std::vector<dvec3> v;
  std::vector<glm::uvec3> f;
};

// The unit icosahedron subdivided `levels` times onto the sphere of `radius` at `centre`.
inline Soup icosphere(int levels, double radius = 1, dvec3 centre = dvec3(0)) {
  const double t = (1 + std::sqrt(5.0)) / 2;
  Soup s;
  s.v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
         {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (dvec3& p : s.v) p = glm::normalize(p);
  s.f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
         {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
         {3, 8, 9},  {4, 9, 5},  {2, 4, 11},  {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<unsigned, unsigned>, unsigned> mid;
    auto m = [&](unsigned a, unsigned b) {
      auto key = std::make_pair(std::min(a, b), std::max(a, b));
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      s.v.push_back(glm::normalize(s.v[a] + s.v[b]));
      return mid[key] = unsigned(s.v.size() - 1);
    };
    std::vector<glm::uvec3> next;
    for (const glm::uvec3& f : s.f) {
      const unsigned ab = m(f[0], f[1]), bc = m(f[1], f[2]), ca = m(f[2], f[0]);
      next.insert(next.end(), {{f[0], ab, ca}, {f[1], bc, ab}, {f[2], ca, bc}, {ab, bc, ca}});
    }
    s.f = next;
  }
  for (dvec3& p : s.v) p = centre + radius * p;
  return s;
}

inline Soup merged(const Soup& a, const Soup& b) {
  Soup s = a;
  const unsigned base = unsigned(s.v.size());
  s.v.insert(s.v.end(), b.v.begin(), b.v.end());
  for (glm::uvec3 f : b.f) s.f.push_back(f + base);
  return s;
}

inline std::string binaryStl(const Soup& s) {
  std::string out(80, '\0');
  const std::uint32_t n = std::uint32_t(s.f.size());
  out.append(reinterpret_cast<const char*>(&n), 4);
  for (const glm::uvec3& f : s.f) {
    float rec[12] = {0, 0, 0};
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a) rec[3 + 3 * k + a] = float(s.v[f[k]][a]);
    out.append(reinterpret_cast<const char*>(rec), sizeof rec);
    out.append(2, '\0');
  }
  return out;
}

inline std::string obj(const Soup& s) {
  std::string out = "# made by mesh_in_test\no part\n";
  char line[128];
  for (const dvec3& p : s.v) {
    std::snprintf(line, sizeof line, "v %.17g %.17g %.17g\n", p.x, p.y, p.z);
    out += line;
  }
  for (const glm::uvec3& f : s.f) {
    std::snprintf(line, sizeof line, "f %u/1 %u//2 %u\n", f[0] + 1, f[1] + 1, f[2] + 1);
    out += line;
  }
  return out;
}

}  // namespace sdfc::test
