#include "mesh_write.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <map>
#include <sstream>
#include <stdexcept>

#include <tiny_gltf.h>

#include "eval/color_field.h"

namespace sdfc {
namespace {

using glm::dvec3;

// A triangle corner whose face normal is farther than this from the field's
// normal sits on a crease (a CSG edge, a box corner): it gets the face normal
// on its own vertex, so shading keeps the edge sharp.
const double kCreaseCos = std::cos(35.0 * 3.14159265358979323846 / 180.0);

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

tinygltf::Value object(std::initializer_list<std::pair<const std::string, tinygltf::Value>> fields) {
  return tinygltf::Value(tinygltf::Value::Object(fields));
}

// The renderer's material model as glTF metallic-roughness (see docs in mesh_write.h).
tinygltf::Material gltfMaterial(const ir::Material& m, double time, std::vector<std::string>& extensions) {
  tinygltf::Material g;
  g.name = m.name;
  const dvec3 albedo = m.albedo.at(time);
  auto& pbr = g.pbrMetallicRoughness;
  pbr.baseColorFactor = {albedo.x, albedo.y, albedo.z, 1.0};
  auto use = [&](const char* name) {
    if (std::find(extensions.begin(), extensions.end(), name) == extensions.end()) extensions.push_back(name);
  };
  switch (m.model) {
    case ir::MaterialModel::Diffuse:
      pbr.metallicFactor = 0;
      pbr.roughnessFactor = 1;
      break;
    case ir::MaterialModel::Mirror:
      pbr.metallicFactor = 1;
      pbr.roughnessFactor = 0;
      break;
    case ir::MaterialModel::Metal:
      // The renderer's roughness is GGX alpha; glTF's is perceptual, alpha = r^2.
      pbr.metallicFactor = 1;
      pbr.roughnessFactor = std::sqrt(std::clamp(m.roughness, 0.0, 1.0));
      break;
    case ir::MaterialModel::Glass:
      pbr.metallicFactor = 0;
      pbr.roughnessFactor = 0;
      g.extensions["KHR_materials_transmission"] = object({{"transmissionFactor", tinygltf::Value(1.0)}});
      g.extensions["KHR_materials_ior"] = object({{"ior", tinygltf::Value(m.ior)}});
      use("KHR_materials_transmission");
      use("KHR_materials_ior");
      break;
    case ir::MaterialModel::Emissive: {
      // emission = colour * strength; glTF wants a factor <= 1 and a strength.
      const dvec3 e = m.emission.at(time);
      const double peak = std::max(e.x, std::max(e.y, e.z));
      const double strength = std::max(peak, 1.0);
      g.emissiveFactor = {e.x / strength, e.y / strength, e.z / strength};
      if (strength > 1) {
        g.extensions["KHR_materials_emissive_strength"] =
            object({{"emissiveStrength", tinygltf::Value(strength)}});
        use("KHR_materials_emissive_strength");
      }
      pbr.baseColorFactor = {0, 0, 0, 1};
      pbr.metallicFactor = 0;
      pbr.roughnessFactor = 1;
      break;
    }
  }
  return g;
}

// Appends `bytes` to the buffer (4-byte aligned) as a new buffer view.
int addView(tinygltf::Model& model, const void* bytes, size_t size, int target) {
  std::vector<unsigned char>& data = model.buffers[0].data;
  data.resize((data.size() + 3) & ~size_t(3));
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = data.size();
  view.byteLength = size;
  view.target = target;
  data.insert(data.end(), static_cast<const unsigned char*>(bytes), static_cast<const unsigned char*>(bytes) + size);
  model.bufferViews.push_back(view);
  return int(model.bufferViews.size() - 1);
}

int addAccessor(tinygltf::Model& model, int view, int component, int type, size_t count,
                std::vector<double> min = {}, std::vector<double> max = {}) {
  tinygltf::Accessor a;
  a.bufferView = view;
  a.componentType = component;
  a.type = type;
  a.count = count;
  a.minValues = std::move(min);
  a.maxValues = std::move(max);
  model.accessors.push_back(a);
  return int(model.accessors.size() - 1);
}

std::string encodeGltf(const TriangleMesh& mesh, const ir::Scene& scene, bool binary, double time) {
  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "sdfc";
  model.buffers.resize(1);
  // Triangles by material; -1 (no material anywhere above) renders as
  // material 0, or the renderer's light grey when the scene has none.
  std::map<int, std::vector<size_t>> by_material;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    int m = mesh.materials.empty() ? -1 : mesh.materials[t];
    if (m < 0 || m >= int(scene.materials.size())) m = scene.materials.empty() ? -1 : 0;
    by_material[m].push_back(t);
  }
  tinygltf::Mesh gmesh;
  gmesh.name = "scene";
  for (const auto& [material, tris] : by_material) {
    // A colour field becomes the vertices' colours (COLOR_0, which glTF
    // multiplies with the base colour, then white). An emitter's field stays
    // its mean: glTF has no per-vertex emission.
    const ir::Material* fielded = material >= 0 && scene.materials[size_t(material)].field &&
                                          scene.materials[size_t(material)].model != ir::MaterialModel::Emissive
                                      ? &scene.materials[size_t(material)]
                                      : nullptr;
    if (material >= 0) {
      model.materials.push_back(gltfMaterial(scene.materials[size_t(material)], time, model.extensionsUsed));
      if (fielded) model.materials.back().pbrMetallicRoughness.baseColorFactor = {1.0, 1.0, 1.0, 1.0};
    } else {
      ir::Material grey;
      grey.name = "default";
      grey.albedo = ir::constantVec(dvec3(0.75));
      model.materials.push_back(gltfMaterial(grey, time, model.extensionsUsed));
    }
    // This primitive's own vertices: shared where smooth, split at creases.
    std::vector<float> positions, normals, colors;
    std::vector<uint32_t> indices;
    std::map<uint32_t, uint32_t> shared;
    auto emit = [&](const dvec3& p, const dvec3& n) {
      positions.insert(positions.end(), {float(p.x), float(p.y), float(p.z)});
      normals.insert(normals.end(), {float(n.x), float(n.y), float(n.z)});
      if (fielded) {
        const dvec3 c = materialColor(*fielded, p + scene.origin, n, time);
        colors.insert(colors.end(), {float(c.x), float(c.y), float(c.z)});
      }
      return uint32_t(positions.size() / 3 - 1);
    };
    for (size_t t : tris) {
      const glm::uvec3 tri = mesh.triangles[t];
      dvec3 face = glm::cross(mesh.positions[tri.y] - mesh.positions[tri.x],
                              mesh.positions[tri.z] - mesh.positions[tri.x]);
      const double len = glm::length(face);
      face = len > 0 ? face / len : mesh.normals[tri.x];
      for (int c = 0; c < 3; ++c) {
        const uint32_t v = tri[c];
        if (glm::dot(mesh.normals[v], face) >= kCreaseCos) {
          auto [it, fresh] = shared.try_emplace(v, 0);
          if (fresh) it->second = emit(mesh.positions[v], mesh.normals[v]);
          indices.push_back(it->second);
        } else {
          indices.push_back(emit(mesh.positions[v], face));
        }
      }
    }
    std::vector<double> lo(3, 1e300), hi(3, -1e300);
    for (size_t i = 0; i < positions.size(); ++i) {
      lo[i % 3] = std::min(lo[i % 3], double(positions[i]));
      hi[i % 3] = std::max(hi[i % 3], double(positions[i]));
    }
    tinygltf::Primitive prim;
    prim.mode = TINYGLTF_MODE_TRIANGLES;
    prim.material = int(model.materials.size() - 1);
    const size_t count = positions.size() / 3;
    prim.attributes["POSITION"] = addAccessor(
        model, addView(model, positions.data(), positions.size() * 4, TINYGLTF_TARGET_ARRAY_BUFFER),
        TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, count, lo, hi);
    prim.attributes["NORMAL"] = addAccessor(
        model, addView(model, normals.data(), normals.size() * 4, TINYGLTF_TARGET_ARRAY_BUFFER),
        TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, count);
    if (fielded)
      prim.attributes["COLOR_0"] = addAccessor(
          model, addView(model, colors.data(), colors.size() * 4, TINYGLTF_TARGET_ARRAY_BUFFER),
          TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, count);
    prim.indices = addAccessor(
        model, addView(model, indices.data(), indices.size() * 4, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER),
        TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR, indices.size());
    gmesh.primitives.push_back(prim);
  }
  model.meshes.push_back(gmesh);
  tinygltf::Node node;
  node.mesh = 0;
  node.name = "scene";
  model.nodes.push_back(node);
  tinygltf::Scene gscene;
  gscene.nodes.push_back(0);
  model.scenes.push_back(gscene);
  model.defaultScene = 0;

  std::ostringstream out;
  tinygltf::TinyGLTF writer;
  if (!writer.WriteGltfSceneToStream(&model, out, /*prettyPrint=*/!binary, binary))
    throw std::runtime_error("tinygltf could not encode the mesh");
  return out.str();
}

std::string encodeStl(const TriangleMesh& mesh) {
  std::string out(80, '\0');
  const char header[] = "sdfc binary STL";
  std::memcpy(out.data(), header, sizeof header - 1);
  auto put = [&](const void* p, size_t n) { out.append(static_cast<const char*>(p), n); };
  const uint32_t count = uint32_t(mesh.triangles.size());
  put(&count, 4);  // little-endian hosts only (x86-64, arm64)
  for (const glm::uvec3& t : mesh.triangles) {
    const dvec3 a = mesh.positions[t.x], b = mesh.positions[t.y], c = mesh.positions[t.z];
    dvec3 n = glm::cross(b - a, c - a);
    const double len = glm::length(n);
    n = len > 0 ? n / len : dvec3(0);
    const float v[12] = {float(n.x), float(n.y), float(n.z), float(a.x), float(a.y), float(a.z),
                         float(b.x), float(b.y), float(b.z), float(c.x), float(c.y), float(c.z)};
    put(v, sizeof v);
    const uint16_t attributes = 0;
    put(&attributes, 2);
  }
  return out;
}

}  // namespace

std::optional<MeshFormat> meshFormatFor(const std::string& path) {
  const std::string p = lower(path);
  auto ends = [&](const char* ext) {
    const size_t n = std::strlen(ext);
    return p.size() > n && p.compare(p.size() - n, n, ext) == 0;
  };
  if (ends(".glb")) return MeshFormat::Glb;
  if (ends(".gltf")) return MeshFormat::Gltf;
  if (ends(".stl")) return MeshFormat::Stl;
  return std::nullopt;
}

std::string encodeMesh(const TriangleMesh& mesh, const ir::Scene& scene, MeshFormat format, double time) {
  switch (format) {
    case MeshFormat::Glb: return encodeGltf(mesh, scene, true, time);
    case MeshFormat::Gltf: return encodeGltf(mesh, scene, false, time);
    case MeshFormat::Stl: return encodeStl(mesh);
  }
  return {};
}

}  // namespace sdfc
