// Compressed meshes decoded at load: a mesh encoded here with the real encoders (Draco, meshoptimizer)
// loads with exactly the positions, normals and triangles it was encoded from.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include <draco/compression/encode.h>
#include <draco/mesh/triangle_soup_mesh_builder.h>
#include <meshoptimizer.h>

#include "renderer/scene/GltfLoader.h"
#include "tests/unit/scene/GltfTestBuilder.h"

namespace radiant {
namespace {

using test::GltfBuilder;
using test::json;

// A unit cube's 12 triangles with per-face normals (24 corners shared by 2 triangles each side).
struct Cube {
  std::vector<glm::vec3> p, n;
  std::vector<std::uint32_t> idx;
  Cube() {
    for (int axis = 0; axis < 3; ++axis)
      for (int side = 0; side < 2; ++side) {
        glm::vec3 normal(0.f);
        normal[axis] = side ? 1.f : -1.f;
        const glm::vec3 u = glm::vec3(axis == 1, axis == 2, axis == 0), v = glm::cross(normal, u);
        const std::uint32_t base = std::uint32_t(p.size());
        for (auto [a, b] : {std::pair{-1.f, -1.f}, {1.f, -1.f}, {1.f, 1.f}, {-1.f, 1.f}}) {
          p.push_back(0.5f * (normal + a * u + b * v));
          n.push_back(normal);
        }
        idx.insert(idx.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
      }
  }
};

// Triangles as sorted corner positions, so encoders that reorder vertices compare equal.
std::vector<std::array<float, 9>> triangles(const std::vector<glm::vec3>& p, const std::vector<std::uint32_t>& idx) {
  std::vector<std::array<float, 9>> t;
  for (std::size_t i = 0; i + 2 < idx.size(); i += 3) {
    std::array<glm::vec3, 3> c{p[idx[i]], p[idx[i + 1]], p[idx[i + 2]]};
    // Rotate (not reorder: winding matters) so the smallest corner comes first.
    auto less = [](const glm::vec3& a, const glm::vec3& b) {
      return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z);
    };
    std::rotate(c.begin(), std::min_element(c.begin(), c.end(), less), c.end());
    t.push_back({c[0].x, c[0].y, c[0].z, c[1].x, c[1].y, c[1].z, c[2].x, c[2].y, c[2].z});
  }
  std::sort(t.begin(), t.end());
  return t;
}

TEST(GltfCompression, DracoPrimitiveDecodesToTheEncodedMesh) {
  const Cube cube;
  draco::TriangleSoupMeshBuilder builder;
  builder.Start(int(cube.idx.size() / 3));
  const int pos = builder.AddAttribute(draco::GeometryAttribute::POSITION, 3, draco::DT_FLOAT32);
  const int nrm = builder.AddAttribute(draco::GeometryAttribute::NORMAL, 3, draco::DT_FLOAT32);
  for (std::size_t f = 0; f < cube.idx.size() / 3; ++f) {
    const auto* i = &cube.idx[f * 3];
    builder.SetAttributeValuesForFace(pos, draco::FaceIndex(std::uint32_t(f)), &cube.p[i[0]], &cube.p[i[1]], &cube.p[i[2]]);
    builder.SetAttributeValuesForFace(nrm, draco::FaceIndex(std::uint32_t(f)), &cube.n[i[0]], &cube.n[i[1]], &cube.n[i[2]]);
  }
  std::unique_ptr<draco::Mesh> mesh = builder.Finalize();
  ASSERT_TRUE(mesh);
  draco::Encoder encoder;  // no quantization set: floats are stored losslessly
  draco::EncoderBuffer encoded;
  ASSERT_TRUE(encoder.EncodeMeshToBuffer(*mesh, &encoded).ok());

  GltfBuilder b;
  const int view = b.view(encoded.data(), encoded.size());
  const int posAcc = b.push("accessors", {{"componentType", 5126}, {"count", mesh->num_points()}, {"type", "VEC3"},
                                          {"min", {-0.5, -0.5, -0.5}}, {"max", {0.5, 0.5, 0.5}}});
  const int nrmAcc = b.push("accessors", {{"componentType", 5126}, {"count", mesh->num_points()}, {"type", "VEC3"}});
  const int idxAcc = b.push("accessors", {{"componentType", 5125}, {"count", cube.idx.size()}, {"type", "SCALAR"}});
  const json draco = {{"bufferView", view},
                      {"attributes", {{"POSITION", mesh->GetNamedAttribute(draco::GeometryAttribute::POSITION)->unique_id()},
                                      {"NORMAL", mesh->GetNamedAttribute(draco::GeometryAttribute::NORMAL)->unique_id()}}}};
  const int m = b.mesh(json::array({{{"attributes", {{"POSITION", posAcc}, {"NORMAL", nrmAcc}}}, {"indices", idxAcc},
                                     {"extensions", {{"KHR_draco_mesh_compression", draco}}}}}));
  b.scene({b.node({{"name", "cube"}, {"mesh", m}})});
  b.doc["extensionsUsed"] = {"KHR_draco_mesh_compression"};
  b.doc["extensionsRequired"] = {"KHR_draco_mesh_compression"};
  for (const std::string& file : {b.glb(), b.gltf()}) {
    const Scene s = loadSceneFromMemory(file);
    ASSERT_EQ(s.meshes.size(), 1u);
    const MeshInstance& mi = s.meshes[0];
    EXPECT_EQ(mi.triangleCount(), 12u);
    EXPECT_EQ(triangles(mi.positions, mi.indices), triangles(cube.p, cube.idx));
    // Each corner keeps its face's normal: the normal equals the direction of its face's centre.
    for (std::size_t t = 0; t < mi.indices.size(); t += 3) {
      const glm::vec3 c = (mi.positions[mi.indices[t]] + mi.positions[mi.indices[t + 1]] + mi.positions[mi.indices[t + 2]]) / 3.f;
      for (int k = 0; k < 3; ++k) EXPECT_LT(glm::length(mi.normals[mi.indices[t + k]] - glm::normalize(glm::round(c * 2.f))), 1e-6f);
    }
    EXPECT_TRUE(s.warnings.empty());
  }
}

TEST(GltfCompression, MeshoptBufferViewsDecodeToTheEncodedBytes) {
  const Cube cube;
  std::vector<unsigned char> vbuf(meshopt_encodeVertexBufferBound(cube.p.size(), 12));
  vbuf.resize(meshopt_encodeVertexBuffer(vbuf.data(), vbuf.size(), cube.p.data(), cube.p.size(), 12));
  std::vector<unsigned char> ibuf(meshopt_encodeIndexBufferBound(cube.idx.size(), cube.p.size()));
  ibuf.resize(meshopt_encodeIndexBuffer(ibuf.data(), ibuf.size(), cube.idx.data(), cube.idx.size()));

  GltfBuilder b;
  const int vData = b.view(vbuf.data(), vbuf.size()), iData = b.view(ibuf.data(), ibuf.size());
  auto compressed = [&](int dataView, std::size_t count, int stride, const char* mode, bool attributes) {
    const json& d = b.doc["bufferViews"][dataView];
    json v = {{"buffer", 1}, {"byteOffset", 0}, {"byteLength", count * stride},
              {"extensions", {{"EXT_meshopt_compression", {{"buffer", 0}, {"byteOffset", d["byteOffset"]},
                                                           {"byteLength", d["byteLength"]}, {"byteStride", stride},
                                                           {"count", count}, {"mode", mode}}}}}};
    if (attributes) v["byteStride"] = stride;
    return b.push("bufferViews", v);
  };
  const int pv = compressed(vData, cube.p.size(), 12, "ATTRIBUTES", true);
  const int iv = compressed(iData, cube.idx.size(), 4, "TRIANGLES", false);
  const int posAcc = b.push("accessors", {{"bufferView", pv}, {"componentType", 5126}, {"count", cube.p.size()}, {"type", "VEC3"},
                                          {"min", {-0.5, -0.5, -0.5}}, {"max", {0.5, 0.5, 0.5}}});
  const int idxAcc = b.push("accessors", {{"bufferView", iv}, {"componentType", 5125}, {"count", cube.idx.size()}, {"type", "SCALAR"}});
  const int m = b.mesh(json::array({{{"attributes", {{"POSITION", posAcc}}}, {"indices", idxAcc}}}));
  b.scene({b.node({{"name", "cube"}, {"mesh", m}})});
  b.doc["extensionsUsed"] = {"EXT_meshopt_compression"};
  b.doc["extensionsRequired"] = {"EXT_meshopt_compression"};
  // GLB: buffer 0 is the BIN chunk with the compressed streams, buffer 1 the uri-less fallback.
  std::string glb;
  {
    json d = b.doc;
    std::string bin = b.bin;
    while (bin.size() % 4) bin.push_back('\0');
    d["buffers"] = json::array({{{"byteLength", bin.size()}},
                                {{"byteLength", 4096}, {"extensions", {{"EXT_meshopt_compression", {{"fallback", true}}}}}}});
    std::string j = d.dump();
    while (j.size() % 4) j.push_back(' ');
    auto le32 = [&](std::uint32_t v) { for (int i = 0; i < 4; ++i) glb.push_back(char((v >> (8 * i)) & 255)); };
    glb += "glTF";
    le32(2);
    le32(std::uint32_t(28 + j.size() + bin.size()));
    le32(std::uint32_t(j.size()));
    le32(0x4E4F534Au);
    glb += j;
    le32(std::uint32_t(bin.size()));
    le32(0x004E4942u);
    glb += bin;
  }
  const Scene s = loadSceneFromMemory(glb);
  ASSERT_EQ(s.meshes.size(), 1u);
  EXPECT_EQ(s.meshes[0].positions, cube.p);  // meshopt is lossless: bit-exact
  EXPECT_EQ(s.meshes[0].indices, cube.idx);
  EXPECT_FALSE(s.digest.empty());

  // A corrupt stream is a SceneError naming the bufferView's extension.
  std::string broken = glb;
  const std::size_t binStart = broken.size() - ((b.bin.size() + 3) & ~std::size_t(3));
  for (std::size_t i = 0; i < vbuf.size(); ++i) broken[binStart + i] = char(0xA5);
  try {
    loadSceneFromMemory(broken);
    ADD_FAILURE() << "a corrupt meshopt stream loaded";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.pointer, "/bufferViews/" + std::to_string(pv) + "/extensions/EXT_meshopt_compression");
  }
}

TEST(GltfCompression, UnsupportedOptionalExtensionIsAWarningNotSilence) {
  GltfBuilder b;
  const int m = b.mesh(json::array({test::trianglePrimitive<std::uint8_t>(b, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2})}));
  b.scene({b.node({{"mesh", m}})});
  b.doc["extensionsUsed"] = {"KHR_materials_iridescence", "KHR_texture_transform"};
  const Scene s = loadSceneFromMemory(b.gltf());
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("KHR_materials_iridescence"), std::string::npos) << s.warnings[0];
}

TEST(GltfExtensions, ClearcoatSheenAndSpecularFactorsAreReadAndClamped) {
  GltfBuilder b;
  const int mat = b.material({{"extensions",
                               {{"KHR_materials_clearcoat", {{"clearcoatFactor", 0.8}, {"clearcoatRoughnessFactor", 0.3}}},
                                {"KHR_materials_sheen", {{"sheenColorFactor", {0.5, 0.25, 2.0}}, {"sheenRoughnessFactor", 0.4}}},
                                {"KHR_materials_specular", {{"specularFactor", 0.5}, {"specularColorFactor", {2.0, 1.0, 0.5}}}}}}});
  const int m = b.mesh(json::array({test::trianglePrimitive<std::uint8_t>(b, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2}, {}, {}, mat)}));
  b.scene({b.node({{"mesh", m}})});
  b.doc["extensionsUsed"] = {"KHR_materials_clearcoat", "KHR_materials_sheen", "KHR_materials_specular"};
  const Scene s = loadSceneFromMemory(b.gltf());
  ASSERT_EQ(s.materials.size(), 1u);
  const Material& x = s.materials[0];
  EXPECT_FLOAT_EQ(x.clearcoatFactor, 0.8f);
  EXPECT_FLOAT_EQ(x.clearcoatRoughnessFactor, 0.3f);
  EXPECT_EQ(x.sheenColorFactor, glm::vec3(0.5f, 0.25f, 1.f));  // a colour factor is clamped to [0, 1]
  EXPECT_FLOAT_EQ(x.sheenRoughnessFactor, 0.4f);
  EXPECT_FLOAT_EQ(x.specularFactor, 0.5f);
  EXPECT_EQ(x.specularColorFactor, glm::vec3(2.f, 1.f, 0.5f));  // may exceed 1 (F0 = min(F0 color, 1))
  // Supported, factors and textures (GltfLoader.LayeredExtensionTexturesAreRead...): nothing to warn of.
  EXPECT_TRUE(s.warnings.empty());
}

// KHR_materials_volume: the factors as written; sigma_t = -ln(c) / d (the spec's "Attenuation"), so
// that exp(-sigma_t d) gives back the colour; the thin-wall default (thicknessFactor 0) has no medium.
TEST(GltfExtensions, VolumeFactorsAreReadAndGiveTheSpecsAttenuationCoefficient) {
  GltfBuilder b;
  const int vol = b.material({{"extensions",
                               {{"KHR_materials_transmission", {{"transmissionFactor", 1.0}}},
                                {"KHR_materials_volume",
                                 {{"thicknessFactor", 0.5}, {"attenuationDistance", 2.0}, {"attenuationColor", {0.25, 0.5, 1.0}}}}}}});
  const int thin = b.material({{"extensions", {{"KHR_materials_volume", {{"attenuationDistance", 2.0}, {"attenuationColor", {0.25, 0.5, 1.0}}}}}}});
  const int m = b.mesh(json::array({test::trianglePrimitive<std::uint8_t>(b, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2}, {}, {}, vol),
                                    test::trianglePrimitive<std::uint8_t>(b, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2}, {}, {}, thin)}));
  b.scene({b.node({{"mesh", m}})});
  b.doc["extensionsUsed"] = {"KHR_materials_transmission", "KHR_materials_volume"};
  const Scene s = loadSceneFromMemory(b.gltf());
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
  ASSERT_EQ(s.materials.size(), 2u);
  const Material& x = s.materials[0];
  EXPECT_FLOAT_EQ(x.thicknessFactor, 0.5f);
  EXPECT_FLOAT_EQ(x.attenuationDistance, 2.f);
  EXPECT_EQ(x.attenuationColor, glm::vec3(0.25f, 0.5f, 1.f));
  const glm::vec3 sigma = x.attenuationCoefficient();
  EXPECT_NEAR(sigma.r, std::log(4.0) / 2.0, 1e-6);
  EXPECT_NEAR(sigma.g, std::log(2.0) / 2.0, 1e-6);
  EXPECT_EQ(sigma.b, 0.f);
  EXPECT_NEAR(std::exp(-sigma.r * 2.f), 0.25f, 1e-6);
  EXPECT_FALSE(s.materials[1].hasVolume());
  EXPECT_EQ(s.materials[1].attenuationCoefficient(), glm::vec3(0.f));
}

// Values outside the spec's ranges render with a warning naming the field (the file is drawn, the
// value repaired): never a NaN or infinite coefficient.
TEST(GltfWarnings, VolumeValuesOutOfRangeAreRepairedWithAWarning) {
  GltfBuilder b;
  const int mat = b.material({{"extensions",
                               {{"KHR_materials_volume",
                                 {{"thicknessFactor", -1.0}, {"attenuationDistance", 0.0}, {"attenuationColor", {-0.5, 0.5, 3.0}}}}}}});
  const int black = b.material({{"extensions",
                                 {{"KHR_materials_volume",
                                   {{"thicknessFactor", 1.0}, {"attenuationDistance", 1e-38}, {"attenuationColor", {0.0, 1.0, 0.5}}}}}}});
  const int m = b.mesh(json::array({test::trianglePrimitive<std::uint8_t>(b, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2}, {}, {}, mat),
                                    test::trianglePrimitive<std::uint8_t>(b, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2}, {}, {}, black)}));
  b.scene({b.node({{"mesh", m}})});
  b.doc["extensionsUsed"] = {"KHR_materials_volume"};
  const Scene s = loadSceneFromMemory(b.gltf());
  ASSERT_EQ(s.warnings.size(), 3u);
  EXPECT_NE(s.warnings[0].find("/materials/0/extensions/KHR_materials_volume/thicknessFactor"), std::string::npos) << s.warnings[0];
  EXPECT_NE(s.warnings[1].find("/materials/0/extensions/KHR_materials_volume/attenuationDistance"), std::string::npos) << s.warnings[1];
  EXPECT_NE(s.warnings[2].find("/materials/0/extensions/KHR_materials_volume/attenuationColor"), std::string::npos) << s.warnings[2];
  EXPECT_EQ(s.materials[0].thicknessFactor, 0.f);
  EXPECT_EQ(s.materials[0].attenuationDistance, std::numeric_limits<float>::infinity());
  EXPECT_EQ(s.materials[0].attenuationColor, glm::vec3(0.f, 0.5f, 1.f));
  // Black at a vanishing distance: the largest finite coefficient, and 0 x sigma stays 0 (no NaN).
  const glm::vec3 sigma = s.materials[1].attenuationCoefficient();
  EXPECT_EQ(sigma.r, std::numeric_limits<float>::max());
  EXPECT_EQ(sigma.g, 0.f);
  EXPECT_TRUE(std::isfinite(sigma.b) && sigma.b > 0.f);
  EXPECT_EQ(0.f * sigma.r, 0.f);
}

// glTF-Validator accepts a texture without a source (an extension may hold its only image): the file
// renders, the material without that texture, and a warning names it.
TEST(GltfWarnings, TextureWithoutSourceIsDroppedWithAWarning) {
  GltfBuilder b;
  const int mat = b.material({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}});
  const int m = b.mesh(json::array({test::trianglePrimitive<std::uint8_t>(b, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2},
                                                                            {}, {{0, 0}, {1, 0}, {0, 1}}, mat)}));
  b.scene({b.node({{"mesh", m}})});
  b.doc["textures"] = json::array({{{"extensions", {{"KHR_texture_basisu", {{"source", 0}}}}}}});
  b.doc["extensionsUsed"] = {"KHR_texture_basisu"};
  const Scene s = loadSceneFromMemory(b.gltf());
  EXPECT_FALSE(s.materials[0].baseColorTexture.valid());
  ASSERT_EQ(s.warnings.size(), 2u);  // the unsupported extension, and the texture it leaves without an image
  EXPECT_NE(s.warnings[1].find("/textures/0"), std::string::npos) << s.warnings[1];
}

}  // namespace
}  // namespace radiant
