#include "meshin/mesh_file.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <limits>
#include <sys/stat.h>
#include <unistd.h>
#include <unordered_map>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <tiny_gltf.h>

namespace sdfc {
namespace {

using glm::dvec3;

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string extensionOf(const std::string& path) {
  const size_t slash = path.rfind('/'), dot = path.rfind('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  return lower(path.substr(dot + 1));
}

// The whole regular file (a FIFO would block, /dev/zero never ends), or why not.
bool readWhole(const std::string& path, std::string& text, std::string& why) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    why = std::strerror(errno);
    return false;
  }
  struct stat st;
  if (::fstat(fd, &st) != 0) why = std::strerror(errno);
  else if (S_ISDIR(st.st_mode)) why = "it is a directory";
  else if (!S_ISREG(st.st_mode)) why = "it is not a regular file (a FIFO, device or socket)";
  else if (static_cast<unsigned long long>(st.st_size) > kMaxMeshFileBytes)
    why = std::to_string(st.st_size) + " bytes, at most " + std::to_string(kMaxMeshFileBytes >> 20) + " MiB";
  if (why.empty()) text.resize(static_cast<size_t>(st.st_size));
  size_t got = 0;
  while (why.empty() && got < text.size()) {
    const ssize_t n = ::read(fd, text.data() + got, text.size() - got);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) why = std::strerror(errno);
    if (n <= 0) break;
    got += static_cast<size_t>(n);
  }
  ::close(fd);
  text.resize(got);
  return why.empty();
}

// Welds corners by their exact coordinates while triangles are added, checks
// each vertex, and drops triangles of no area.
class TriangleBuilder {
 public:
  explicit TriangleBuilder(MeshFile& out) : out_(out) {}

  // `where`: how a message names the triangle ("line 12", "triangle 7").
  bool add(const dvec3 (&corner)[3], const std::string& where) {
    if (out_.mesh.triangles.size() >= kMaxMeshTriangles) {
      out_.error = "more than " + std::to_string(kMaxMeshTriangles) + " triangles (the limit)";
      return false;
    }
    constexpr double kFloatMax = std::numeric_limits<float>::max();
    for (const dvec3& v : corner)
      for (int a = 0; a < 3; ++a)
        if (!(std::fabs(v[a]) <= kFloatMax)) {
          out_.error = where + ": a vertex coordinate is " +
                       (std::isfinite(v[a]) ? "beyond float32's range" : std::isnan(v[a]) ? "not a number (nan)" : "infinite");
          return false;
        }
    glm::uvec3 t;
    for (int k = 0; k < 3; ++k) t[k] = index(corner[k]);
    const dvec3 n = glm::cross(corner[1] - corner[0], corner[2] - corner[0]);
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || !(glm::dot(n, n) > 0)) {
      ++out_.degenerate;
      return true;
    }
    out_.mesh.triangles.push_back(t);
    return true;
  }

  // Area that is tiny against the mesh's size is dropped too (float32 noise
  // in an exporter's slivers): once the box is known.
  void finish() {
    InputMesh& m = out_.mesh;
    dvec3 lo(1e300), hi(-1e300);
    for (const dvec3& v : m.vertices) lo = glm::min(lo, v), hi = glm::max(hi, v);
    const double size = m.vertices.empty() ? 0 : glm::length(hi - lo);
    const double tiny = 1e-14 * size * size;
    size_t kept = 0;
    for (const glm::uvec3& t : m.triangles) {
      const dvec3 n = glm::cross(m.vertices[t[1]] - m.vertices[t[0]], m.vertices[t[2]] - m.vertices[t[0]]);
      if (glm::length(n) <= tiny) ++out_.degenerate;
      else m.triangles[kept++] = t;
    }
    m.triangles.resize(kept);
    // Edges by the triangles that share them: one (boundary) or three and more;
    // and the way each runs it (+1 from lower to higher index, -1 back): two
    // faces oriented alike run a shared edge in opposite ways.
    struct Uses {
      std::uint32_t count = 0;
      std::int32_t direction = 0;
    };
    std::unordered_map<std::uint64_t, Uses> uses;
    uses.reserve(m.triangles.size() * 2);
    for (const glm::uvec3& t : m.triangles)
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t a = t[k], b = t[(k + 1) % 3];
        Uses& u = uses[(std::uint64_t(std::min(a, b)) << 32) | std::max(a, b)];
        ++u.count;
        u.direction += a < b ? 1 : -1;
      }
    out_.edges = uses.size();
    for (const auto& [edge, u] : uses) {
      if (u.count == 1) ++out_.boundary_edges;
      if (u.count >= 3) ++out_.nonmanifold_edges;
      if (u.count == 2 && u.direction != 0) ++out_.flipped_edges;
    }
    // A closed, consistently oriented mesh of negative volume faces inward:
    // its winding number is -1 inside and 0 outside, never above one half, so
    // it would be positive everywhere (a shell of no thickness). Turned to
    // face outward, and said so (the mesh-inward warning).
    if (out_.boundary_edges == 0 && out_.nonmanifold_edges == 0 && out_.flipped_edges == 0) {
      double volume = 0;
      for (const glm::uvec3& t : m.triangles)
        volume += glm::dot(m.vertices[t[0]], glm::cross(m.vertices[t[1]], m.vertices[t[2]])) / 6;
      if (volume < 0) {
        for (glm::uvec3& t : m.triangles) std::swap(t[1], t[2]);
        out_.turned_outward = true;
        out_.inward_volume = volume;
      }
    }
  }

 private:
  std::uint32_t index(const dvec3& v) {
    struct Key {
      double x, y, z;
    } key{v.x + 0.0, v.y + 0.0, v.z + 0.0};  // + 0.0: -0 and 0 weld
    std::uint64_t h = 1469598103934665603ull;
    const unsigned char* bytes = reinterpret_cast<const unsigned char*>(&key);
    for (size_t i = 0; i < sizeof key; ++i) h = (h ^ bytes[i]) * 1099511628211ull;
    auto [it, fresh] = welded_.try_emplace(h, 0);
    // A hash collision between different positions keeps them apart.
    if (!fresh && out_.mesh.vertices[it->second] == dvec3(key.x, key.y, key.z)) return it->second;
    const std::uint32_t i = static_cast<std::uint32_t>(out_.mesh.vertices.size());
    out_.mesh.vertices.push_back(dvec3(key.x, key.y, key.z));
    if (fresh) it->second = i;
    return i;
  }

  MeshFile& out_;
  std::unordered_map<std::uint64_t, std::uint32_t> welded_;
};

size_t lineAt(const std::string& text, size_t offset) {
  return 1 + static_cast<size_t>(std::count(text.begin(), text.begin() + std::min(offset, text.size()), '\n'));
}

bool readBinaryStl(const std::string& text, MeshFile& out) {
  std::uint32_t count;
  std::memcpy(&count, text.data() + 80, 4);
  TriangleBuilder b(out);
  for (std::uint32_t i = 0; i < count; ++i) {
    const char* rec = text.data() + 84 + size_t(i) * 50 + 12;  // after the normal
    float f[9];
    std::memcpy(f, rec, sizeof f);
    const dvec3 c[3] = {dvec3(f[0], f[1], f[2]), dvec3(f[3], f[4], f[5]), dvec3(f[6], f[7], f[8])};
    if (!b.add(c, "triangle " + std::to_string(i + 1))) return false;
  }
  b.finish();
  return true;
}

// Whitespace-separated words; `pos` moves past the word returned.
bool nextWord(const std::string& s, size_t& pos, size_t& begin, size_t& end) {
  while (pos < s.size() && std::isspace(static_cast<unsigned char>(s[pos]))) ++pos;
  if (pos >= s.size()) return false;
  begin = pos;
  while (pos < s.size() && !std::isspace(static_cast<unsigned char>(s[pos]))) ++pos;
  end = pos;
  return true;
}

bool parseNumber(const std::string& s, size_t begin, size_t end, double& v) {
  const std::string word = s.substr(begin, end - begin);
  char* stop = nullptr;
  v = std::strtod(word.c_str(), &stop);
  return !word.empty() && stop == word.c_str() + word.size();
}

bool readAsciiStl(const std::string& text, MeshFile& out) {
  TriangleBuilder b(out);
  size_t pos = 0, wb, we;
  dvec3 corner[3];
  int corners = 0;
  while (nextWord(text, pos, wb, we)) {
    const std::string word = lower(text.substr(wb, we - wb));
    if (word == "endloop" || word == "endfacet") {
      if (word == "endloop" && corners != 3) {
        out.error = "line " + std::to_string(lineAt(text, wb)) + ": a facet has " + std::to_string(corners) +
                    " vertices; STL facets are triangles";
        return false;
      }
      if (word == "endloop" && !b.add(corner, "line " + std::to_string(lineAt(text, wb)))) return false;
      corners = 0;
      continue;
    }
    if (word != "vertex") continue;
    if (corners == 3) {
      out.error = "line " + std::to_string(lineAt(text, wb)) + ": a facet has more than 3 vertices";
      return false;
    }
    for (int a = 0; a < 3; ++a) {
      double v;
      if (!nextWord(text, pos, wb, we) || !parseNumber(text, wb, we, v)) {
        out.error = "line " + std::to_string(lineAt(text, wb)) + ": 'vertex' takes three numbers";
        return false;
      }
      corner[corners][a] = v;
    }
    ++corners;
  }
  b.finish();
  return true;
}

// v x y z, and f i j k ... with i, i/t, i//n or i/t/n (1-based; negative:
// from the last vertex so far); a polygon is fanned from its first corner.
bool readObj(const std::string& text, MeshFile& out) {
  TriangleBuilder b(out);
  std::vector<dvec3> v;
  std::vector<long> face;
  size_t line_start = 0, line = 0;
  while (line_start < text.size()) {
    size_t stop = text.find('\n', line_start);
    if (stop == std::string::npos) stop = text.size();
    const std::string row = text.substr(line_start, stop - line_start);
    line_start = stop + 1;
    ++line;
    size_t pos = 0, wb, we;
    if (!nextWord(row, pos, wb, we)) continue;
    const std::string key = row.substr(wb, we - wb);
    const std::string where = "line " + std::to_string(line);
    if (key == "v") {
      dvec3 p;
      for (int a = 0; a < 3; ++a)
        if (!nextWord(row, pos, wb, we) || !parseNumber(row, wb, we, p[a])) {
          out.error = where + ": 'v' takes three numbers";
          return false;
        }
      v.push_back(p);
    } else if (key == "f") {
      face.clear();
      while (nextWord(row, pos, wb, we)) {
        const std::string corner = row.substr(wb, we - wb);
        char* end = nullptr;
        const long i = std::strtol(corner.c_str(), &end, 10);
        const long resolved = i < 0 ? long(v.size()) + i : i - 1;
        if (end == corner.c_str() || (*end != '\0' && *end != '/') || i == 0 || resolved < 0 ||
            resolved >= long(v.size())) {
          out.error = where + ": '" + corner + "' is not a vertex (" + std::to_string(v.size()) +
                      " defined so far)";
          return false;
        }
        face.push_back(resolved);
      }
      if (face.size() < 3) {
        out.error = where + ": a face needs at least 3 vertices";
        return false;
      }
      for (size_t k = 1; k + 1 < face.size(); ++k) {
        const dvec3 c[3] = {v[face[0]], v[face[k]], v[face[k + 1]]};
        if (!b.add(c, where)) return false;
      }
    }
  }
  b.finish();
  return true;
}

glm::dmat4 nodeMatrix(const tinygltf::Node& node) {
  if (node.matrix.size() == 16) {
    glm::dmat4 m;
    for (int i = 0; i < 16; ++i) m[i / 4][i % 4] = node.matrix[i];
    return m;
  }
  glm::dmat4 m(1.0);
  if (node.translation.size() == 3) m[3] = glm::dvec4(node.translation[0], node.translation[1], node.translation[2], 1);
  if (node.rotation.size() == 4)
    m = m * glm::mat4_cast(glm::dquat(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]));
  if (node.scale.size() == 3) m = glm::scale(m, dvec3(node.scale[0], node.scale[1], node.scale[2]));
  return m;
}

// One accessor's element `i`, as doubles (positions: float; indices: unsigned).
bool accessorValue(const tinygltf::Model& model, const tinygltf::Accessor& acc, size_t i, int components,
                   double* value) {
  if (acc.bufferView < 0 || acc.bufferView >= int(model.bufferViews.size())) return false;
  const tinygltf::BufferView& view = model.bufferViews[acc.bufferView];
  if (view.buffer < 0 || view.buffer >= int(model.buffers.size())) return false;
  const std::vector<unsigned char>& data = model.buffers[view.buffer].data;
  const int size = tinygltf::GetComponentSizeInBytes(acc.componentType);
  if (size <= 0) return false;
  const size_t stride = view.byteStride ? view.byteStride : size_t(size) * components;
  const size_t at = view.byteOffset + acc.byteOffset + i * stride;
  if (at + size_t(size) * components > data.size() || at + size_t(size) * components > view.byteOffset + view.byteLength)
    return false;
  for (int c = 0; c < components; ++c) {
    const unsigned char* p = data.data() + at + size_t(c) * size;
    switch (acc.componentType) {
      case TINYGLTF_COMPONENT_TYPE_FLOAT: { float f; std::memcpy(&f, p, 4); value[c] = f; break; }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: value[c] = *p; break;
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: { std::uint16_t u; std::memcpy(&u, p, 2); value[c] = u; break; }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: { std::uint32_t u; std::memcpy(&u, p, 4); value[c] = u; break; }
      default: return false;
    }
  }
  return true;
}

// A primitive's triangles as glTF draws them: a list (mode 4, the default)
// takes corners 3 at a time; a strip (5) makes triangle i of corners i, i + 1,
// i + 2, the first two swapped on odd i so that all face alike; a fan (6) of
// corners 0, i + 1, i + 2. Points and lines (0 to 3) have no surface.
bool readGltfMesh(const tinygltf::Model& model, const tinygltf::Mesh& mesh, const glm::dmat4& m, TriangleBuilder& b,
                  MeshFile& out) {
  // A mirroring transform turns the faces inside out: their corners are
  // taken in the other order (glTF's rule for a negative determinant).
  const bool mirrored = glm::determinant(m) < 0;
  for (const tinygltf::Primitive& prim : mesh.primitives) {
    const int mode = prim.mode == -1 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
    if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP && mode != TINYGLTF_MODE_TRIANGLE_FAN)
      continue;
    auto pos = prim.attributes.find("POSITION");
    if (pos == prim.attributes.end() || pos->second < 0 || pos->second >= int(model.accessors.size())) continue;
    const tinygltf::Accessor& pa = model.accessors[pos->second];
    if (pa.type != TINYGLTF_TYPE_VEC3 || pa.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT || pa.sparse.isSparse) {
      out.error = "mesh '" + mesh.name + "': positions must be float VEC3 (not sparse)";
      return false;
    }
    const tinygltf::Accessor* ia = nullptr;
    if (prim.indices >= 0) {
      if (prim.indices >= int(model.accessors.size())) return out.error = "an index accessor is missing", false;
      ia = &model.accessors[prim.indices];
      // glTF's indices are unsigned integers: a float accessor could hold NaN.
      if (ia->type != TINYGLTF_TYPE_SCALAR || (ia->componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
                                               ia->componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
                                               ia->componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT))
        return out.error = "mesh '" + mesh.name + "': indices must be unsigned integer scalars", false;
    }
    const size_t corners = ia ? ia->count : pa.count;
    const size_t triangles = mode == TINYGLTF_MODE_TRIANGLES ? corners / 3 : corners >= 3 ? corners - 2 : 0;
    for (size_t t = 0; t < triangles; ++t) {
      size_t corner[3];
      if (mode == TINYGLTF_MODE_TRIANGLES) corner[0] = 3 * t, corner[1] = 3 * t + 1, corner[2] = 3 * t + 2;
      else if (mode == TINYGLTF_MODE_TRIANGLE_FAN) corner[0] = 0, corner[1] = t + 1, corner[2] = t + 2;
      else if (t % 2 == 0) corner[0] = t, corner[1] = t + 1, corner[2] = t + 2;
      else corner[0] = t + 1, corner[1] = t, corner[2] = t + 2;
      if (mirrored) std::swap(corner[1], corner[2]);
      dvec3 c[3];
      for (int k = 0; k < 3; ++k) {
        double index = double(corner[k]);
        if (ia && !accessorValue(model, *ia, corner[k], 1, &index))
          return out.error = "mesh '" + mesh.name + "': an index lies outside its buffer", false;
        double xyz[3];
        if (!(index >= 0 && index < double(pa.count)) || !accessorValue(model, pa, size_t(index), 3, xyz))
          return out.error = "mesh '" + mesh.name + "': a vertex index lies outside its positions", false;
        c[k] = dvec3(m * glm::dvec4(xyz[0], xyz[1], xyz[2], 1));
      }
      if (!b.add(c, "mesh '" + mesh.name + "' triangle " + std::to_string(t + 1))) return false;
    }
  }
  return true;
}

bool readGltf(const std::string& path, const std::string& text, bool binary, MeshFile& out) {
  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string err, warn;
  const std::string dir = path.rfind('/') == std::string::npos ? "." : path.substr(0, path.rfind('/'));
  const bool loaded =
      binary ? loader.LoadBinaryFromMemory(&model, &err, &warn, reinterpret_cast<const unsigned char*>(text.data()),
                                           static_cast<unsigned>(text.size()), dir)
             : loader.LoadASCIIFromString(&model, &err, &warn, text.data(), static_cast<unsigned>(text.size()), dir);
  if (!loaded) {
    while (!err.empty() && (err.back() == '\n' || err.back() == ' ')) err.pop_back();
    out.error = "not a valid " + std::string(binary ? "GLB" : "glTF") + " file: " + (err.empty() ? "unknown reason" : err);
    return false;
  }
  TriangleBuilder b(out);
  // The default scene's node tree with its transforms; with no scenes, every mesh as it is.
  if (model.scenes.empty()) {
    for (const tinygltf::Mesh& mesh : model.meshes)
      if (!readGltfMesh(model, mesh, glm::dmat4(1.0), b, out)) return false;
  } else {
    const int scene = model.defaultScene >= 0 && model.defaultScene < int(model.scenes.size()) ? model.defaultScene : 0;
    std::vector<std::pair<int, glm::dmat4>> stack;
    for (int n : model.scenes[scene].nodes) stack.push_back({n, glm::dmat4(1.0)});
    size_t visited = 0;
    while (!stack.empty()) {
      auto [index, parent] = stack.back();
      stack.pop_back();
      if (index < 0 || index >= int(model.nodes.size()) || ++visited > 100000)
        return out.error = "its node tree is broken (a bad index or a cycle)", false;
      const tinygltf::Node& node = model.nodes[index];
      const glm::dmat4 m = parent * nodeMatrix(node);
      if (node.mesh >= 0 && node.mesh < int(model.meshes.size()) && !readGltfMesh(model, model.meshes[node.mesh], m, b, out))
        return false;
      for (int c : node.children) stack.push_back({c, m});
    }
  }
  b.finish();
  return true;
}

}  // namespace

MeshFile readMeshFile(const std::string& path) {
  MeshFile out;
  std::string text, why;
  if (!readWhole(path, text, why)) {
    out.unreadable = true;
    out.error = why;
    return out;
  }
  const std::string ext = extensionOf(path);
  bool ok = false;
  if (ext == "stl") {
    std::uint32_t count = 0;
    if (text.size() >= 84) std::memcpy(&count, text.data() + 80, 4);
    // Binary when the size says so: some binary files' headers begin "solid" too.
    if (text.size() >= 84 && text.size() == 84 + size_t(count) * 50) {
      out.format = "binary STL";
      ok = readBinaryStl(text, out);
    } else if (text.compare(0, 5, "solid") == 0) {
      out.format = "ASCII STL";
      ok = readAsciiStl(text, out);
    } else {
      out.error = "neither ASCII STL (it does not begin 'solid') nor binary STL (" + std::to_string(text.size()) +
                  " bytes, where its header's count says " + std::to_string(84 + size_t(count) * 50) + ")";
    }
  } else if (ext == "obj") {
    out.format = "OBJ";
    ok = readObj(text, out);
  } else if (ext == "gltf" || ext == "glb") {
    out.format = ext == "glb" ? "GLB" : "glTF";
    ok = readGltf(path, text, ext == "glb", out);
  } else {
    out.error = "'." + ext + "' is not a mesh format sdfc reads (.stl, .obj, .gltf, .glb)";
  }
  if (!ok) return out;
  if (out.mesh.triangles.empty()) {
    out.error = out.degenerate > 0 ? "all " + std::to_string(out.degenerate) + " of its triangles have no area"
                                   : "it holds no triangles";
    return out;
  }
  out.ok = true;
  return out;
}

}  // namespace sdfc
