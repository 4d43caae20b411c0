// Mesh export: glTF materials and primitives read back through tinygltf,
// embedded .gltf, binary STL, and writing through a temporary file.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <tiny_gltf.h>

#include "cli/cli_support.h"
#include "driver/compile.h"
#include "mesh_write.h"
#include "mesher.h"

namespace sdfc {
namespace {

const char* kMaterials = R"(
let clay = diffuse(albedo: [0.8, 0.3, 0.25])
let lens = glass(ior: 1.45, tint: [0.9, 0.95, 1])
let lamp = emissive(color: [1, 0.5, 0.25], strength: 4)
let steel = metal(albedo: [0.9, 0.8, 0.7], roughness: 0.25)
let chrome = mirror(tint: [0.95, 0.96, 0.97])
let unused = diffuse(albedo: [0, 1, 0])
scene {
  sphere(radius: 0.5, material: clay)
  translate([1.5, 0, 0]) { sphere(radius: 0.5, material: lens) }
  translate([3, 0, 0]) { box(size: [0.8, 0.8, 0.8], material: lamp) }
  translate([0, 1.5, 0]) { sphere(radius: 0.5, material: steel) }
  translate([1.5, 1.5, 0]) { torus(major: 0.4, minor: 0.1, material: chrome) }
}
)";

struct Fixture {
  CompiledScene compiled;
  TriangleMesh mesh;
};

Fixture meshed(const char* text) {
  Fixture f;
  Diagnostics diags;
  f.compiled = checkSource("t.sdf", text, CompileOptions{}, diags);
  EXPECT_FALSE(diags.hasErrors()) << diags.format();
  MeshOptions o;
  o.resolution = 64;
  MeshResult r = meshScene(f.compiled.scene, o);
  EXPECT_EQ(r.error, "");
  f.mesh = std::move(r.mesh);
  return f;
}

const tinygltf::Material* byName(const tinygltf::Model& m, const std::string& name) {
  for (const tinygltf::Material& mat : m.materials)
    if (mat.name == name) return &mat;
  return nullptr;
}

void expectColour(const std::vector<double>& got, std::vector<double> want) {
  ASSERT_EQ(got.size(), want.size());
  for (size_t i = 0; i < want.size(); ++i) EXPECT_NEAR(got[i], want[i], 1e-9) << i;
}

void checkModel(const tinygltf::Model& model, const TriangleMesh& mesh) {
  // Five materials in use, the unused one left out; one primitive each.
  ASSERT_EQ(model.meshes.size(), 1u);
  EXPECT_EQ(model.materials.size(), 5u);
  EXPECT_EQ(model.meshes[0].primitives.size(), 5u);
  size_t triangles = 0;
  for (const tinygltf::Primitive& p : model.meshes[0].primitives) {
    EXPECT_EQ(p.mode, TINYGLTF_MODE_TRIANGLES);
    EXPECT_GE(p.material, 0);
    triangles += model.accessors[size_t(p.indices)].count / 3;
    const tinygltf::Accessor& pos = model.accessors[size_t(p.attributes.at("POSITION"))];
    EXPECT_EQ(pos.minValues.size(), 3u);
    EXPECT_EQ(model.accessors[size_t(p.attributes.at("NORMAL"))].count, pos.count);
  }
  EXPECT_EQ(triangles, mesh.triangles.size());

  const tinygltf::Material* clay = byName(model, "clay");
  ASSERT_TRUE(clay);
  expectColour(clay->pbrMetallicRoughness.baseColorFactor, {0.8, 0.3, 0.25, 1});
  EXPECT_EQ(clay->pbrMetallicRoughness.metallicFactor, 0);
  EXPECT_EQ(clay->pbrMetallicRoughness.roughnessFactor, 1);

  const tinygltf::Material* chrome = byName(model, "chrome");
  ASSERT_TRUE(chrome);
  expectColour(chrome->pbrMetallicRoughness.baseColorFactor, {0.95, 0.96, 0.97, 1});
  EXPECT_EQ(chrome->pbrMetallicRoughness.metallicFactor, 1);
  EXPECT_EQ(chrome->pbrMetallicRoughness.roughnessFactor, 0);

  const tinygltf::Material* steel = byName(model, "steel");
  ASSERT_TRUE(steel);
  EXPECT_EQ(steel->pbrMetallicRoughness.metallicFactor, 1);
  EXPECT_NEAR(steel->pbrMetallicRoughness.roughnessFactor, 0.5, 1e-12);  // sqrt(GGX alpha)

  const tinygltf::Material* lens = byName(model, "lens");
  ASSERT_TRUE(lens);
  ASSERT_TRUE(lens->extensions.count("KHR_materials_transmission"));
  EXPECT_EQ(lens->extensions.at("KHR_materials_transmission").Get("transmissionFactor").GetNumberAsDouble(), 1);
  ASSERT_TRUE(lens->extensions.count("KHR_materials_ior"));
  EXPECT_NEAR(lens->extensions.at("KHR_materials_ior").Get("ior").GetNumberAsDouble(), 1.45, 1e-12);

  const tinygltf::Material* lamp = byName(model, "lamp");
  ASSERT_TRUE(lamp);
  expectColour(lamp->emissiveFactor, {1, 0.5, 0.25});
  ASSERT_TRUE(lamp->extensions.count("KHR_materials_emissive_strength"));
  EXPECT_NEAR(lamp->extensions.at("KHR_materials_emissive_strength").Get("emissiveStrength").GetNumberAsDouble(),
              4, 1e-12);

  for (const char* ext : {"KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_emissive_strength"})
    EXPECT_NE(std::find(model.extensionsUsed.begin(), model.extensionsUsed.end(), ext), model.extensionsUsed.end())
        << ext;
}

TEST(MeshExport, GlbLoadsBackWithMaterialsPerPrimitive) {
  Fixture f = meshed(kMaterials);
  const std::string bytes = encodeMesh(f.mesh, f.compiled.scene, MeshFormat::Glb);
  ASSERT_EQ(bytes.compare(0, 4, "glTF"), 0);
  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string err, warn;
  ASSERT_TRUE(loader.LoadBinaryFromMemory(&model, &err, &warn, reinterpret_cast<const unsigned char*>(bytes.data()),
                                          unsigned(bytes.size())))
      << err;
  checkModel(model, f.mesh);
}

TEST(MeshExport, GltfEmbedsItsBuffer) {
  Fixture f = meshed(kMaterials);
  const std::string text = encodeMesh(f.mesh, f.compiled.scene, MeshFormat::Gltf);
  EXPECT_NE(text.find("data:application/octet-stream;base64,"), std::string::npos);
  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string err, warn;
  ASSERT_TRUE(loader.LoadASCIIFromString(&model, &err, &warn, text.data(), unsigned(text.size()), "")) << err;
  checkModel(model, f.mesh);
}

TEST(MeshExport, SceneWithoutMaterialsGetsTheRenderersGrey) {
  Fixture f = meshed("scene { sphere(radius: 1) }");
  const std::string bytes = encodeMesh(f.mesh, f.compiled.scene, MeshFormat::Glb);
  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string err, warn;
  ASSERT_TRUE(loader.LoadBinaryFromMemory(&model, &err, &warn, reinterpret_cast<const unsigned char*>(bytes.data()),
                                          unsigned(bytes.size())));
  ASSERT_EQ(model.materials.size(), 1u);
  expectColour(model.materials[0].pbrMetallicRoughness.baseColorFactor, {0.75, 0.75, 0.75, 1});
}

// Colour fields become vertex colours (issue 33): COLOR_0 at every vertex is
// the field there, and the material's base colour is white (glTF multiplies).
TEST(MeshExport, ColourFieldsAreVertexColours) {
  Fixture f = meshed(R"(
let band = diffuse(albedo: gradient([0.1, 0.2, 0.9], [0.9, 0.6, 0.1], from: -0.5, to: 0.5))
let clay = diffuse(albedo: [0.8, 0.3, 0.25])
scene {
  sphere(radius: 0.5, material: band)
  translate([1.5, 0, 0]) { sphere(radius: 0.5, material: clay) }
}
)");
  const std::string bytes = encodeMesh(f.mesh, f.compiled.scene, MeshFormat::Glb);
  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string err, warn;
  ASSERT_TRUE(loader.LoadBinaryFromMemory(&model, &err, &warn, reinterpret_cast<const unsigned char*>(bytes.data()),
                                          unsigned(bytes.size())))
      << err;
  int checked = 0;
  for (const tinygltf::Primitive& p : model.meshes[0].primitives) {
    const tinygltf::Material& m = model.materials[size_t(p.material)];
    if (m.name == "clay") {
      EXPECT_EQ(p.attributes.count("COLOR_0"), 0u);  // constant colours stay material factors
      expectColour(m.pbrMetallicRoughness.baseColorFactor, {0.8, 0.3, 0.25, 1});
      continue;
    }
    ASSERT_EQ(m.name, "band");
    expectColour(m.pbrMetallicRoughness.baseColorFactor, {1, 1, 1, 1});
    ASSERT_EQ(p.attributes.count("COLOR_0"), 1u);
    const tinygltf::Accessor& pos = model.accessors[size_t(p.attributes.at("POSITION"))];
    const tinygltf::Accessor& col = model.accessors[size_t(p.attributes.at("COLOR_0"))];
    ASSERT_EQ(col.count, pos.count);
    ASSERT_EQ(col.type, TINYGLTF_TYPE_VEC3);
    auto floats = [&](const tinygltf::Accessor& a) {
      const tinygltf::BufferView& v = model.bufferViews[size_t(a.bufferView)];
      return reinterpret_cast<const float*>(model.buffers[0].data.data() + v.byteOffset + a.byteOffset);
    };
    const float* xyz = floats(pos);
    const float* rgb = floats(col);
    for (size_t i = 0; i < pos.count; ++i) {
      const double t = std::clamp(double(xyz[i * 3 + 1]) + 0.5, 0.0, 1.0);
      EXPECT_NEAR(rgb[i * 3 + 0], 0.1 + 0.8 * t, 1e-6);
      EXPECT_NEAR(rgb[i * 3 + 1], 0.2 + 0.4 * t, 1e-6);
      EXPECT_NEAR(rgb[i * 3 + 2], 0.9 - 0.8 * t, 1e-6);
      ++checked;
    }
  }
  EXPECT_GT(checked, 100);
}

TEST(MeshExport, BinaryStlHasEveryTriangle) {
  Fixture f = meshed("scene { box(size: [1, 2, 3]) }");
  const std::string bytes = encodeMesh(f.mesh, f.compiled.scene, MeshFormat::Stl);
  ASSERT_EQ(bytes.size(), 84 + 50 * f.mesh.triangles.size());
  uint32_t count = 0;
  std::memcpy(&count, bytes.data() + 80, 4);
  EXPECT_EQ(count, f.mesh.triangles.size());
  float first[12];
  std::memcpy(first, bytes.data() + 84, sizeof first);
  EXPECT_NEAR(first[0] * first[0] + first[1] * first[1] + first[2] * first[2], 1, 1e-5);  // unit normal
}

TEST(MeshExport, FormatsByExtensionAndAtomicWrite) {
  EXPECT_EQ(meshFormatFor("a/b.GLB"), MeshFormat::Glb);
  EXPECT_EQ(meshFormatFor("x.gltf"), MeshFormat::Gltf);
  EXPECT_EQ(meshFormatFor("x.stl"), MeshFormat::Stl);
  EXPECT_EQ(meshFormatFor("x.obj"), std::nullopt);
  const std::string path = std::string(SDFC_BINARY_DIR) + "/mesh_export_test.stl";
  writeFileAtomically(path, "hello");
  std::ifstream in(path, std::ios::binary);
  std::stringstream got;
  got << in.rdbuf();
  EXPECT_EQ(got.str(), "hello");
  EXPECT_FALSE(std::ifstream(path + ".tmp").good());
  std::remove(path.c_str());
  EXPECT_THROW(writeFileAtomically("/nonexistent-dir/x.stl", "x"), std::runtime_error);
}

}  // namespace
}  // namespace sdfc
