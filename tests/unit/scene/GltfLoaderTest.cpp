#include <gtest/gtest.h>
#include <webp/encode.h>

#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "renderer/scene/GltfLoader.h"
#include "tests/unit/scene/GltfTestBuilder.h"

namespace radiant {
namespace {

using test::GltfBuilder;
using test::json;
using test::trianglePrimitive;

constexpr float kEps = 1e-5f;

void expectVec(const glm::vec3& actual, const glm::vec3& expected, float eps = kEps) {
  EXPECT_NEAR(actual.x, expected.x, eps) << "x";
  EXPECT_NEAR(actual.y, expected.y, eps) << "y";
  EXPECT_NEAR(actual.z, expected.z, eps) << "z";
}

// Quaternion (x, y, z, w) of a rotation by `degrees` about a unit axis, as glTF stores it.
json quat(glm::vec3 axis, float degrees) {
  const float h = glm::radians(degrees) * 0.5f;
  return {axis.x * std::sin(h), axis.y * std::sin(h), axis.z * std::sin(h), std::cos(h)};
}

const std::vector<glm::vec3> kTri = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};

TEST(GltfLoader, DataUriWithU8Indices) {
  GltfBuilder b;
  const int m = b.mesh(json::array({trianglePrimitive<std::uint8_t>(b, kTri, {0, 1, 2})}));
  b.scene({b.node({{"name", "tri"}, {"mesh", m}})});
  const std::string text = b.gltf();
  const Scene s = loadSceneFromMemory(text);
  ASSERT_EQ(s.meshes.size(), 1u);
  const auto& mi = s.meshes[0];
  EXPECT_EQ(mi.name, "tri");
  EXPECT_EQ(mi.indices, (std::vector<std::uint32_t>{0, 1, 2}));
  ASSERT_EQ(mi.positions.size(), 3u);
  expectVec(mi.positions[1], {1, 0, 0});
  EXPECT_EQ(s.digest, "sha256:" + api::sha256Hex(text));
  EXPECT_EQ(s.features.triangles, 1u);
  expectVec(s.features.bounds.max, {1, 1, 0});
}

TEST(GltfLoader, GlbWithU16Indices) {
  GltfBuilder b;
  const int m = b.mesh(json::array({trianglePrimitive<std::uint16_t>(b, {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {2, 2, 0}},
                                                                      {0, 1, 2, 2, 1, 3})}));
  b.scene({b.node({{"mesh", m}})});
  const std::string glb = b.glb();
  ASSERT_EQ(glb.substr(0, 4), "glTF");
  const Scene s = loadSceneFromMemory(glb);
  ASSERT_EQ(s.meshes.size(), 1u);
  EXPECT_EQ(s.meshes[0].indices, (std::vector<std::uint32_t>{0, 1, 2, 2, 1, 3}));
  expectVec(s.meshes[0].positions[3], {2, 2, 0});
  EXPECT_EQ(s.digest, "sha256:" + api::sha256Hex(glb));
}

TEST(GltfLoader, U32IndicesAndNonIndexedPrimitivesInOneMesh) {
  GltfBuilder b;
  const json p0 = trianglePrimitive<std::uint32_t>(b, kTri, {2, 1, 0});
  const json p1 = trianglePrimitive<std::uint32_t>(b, {{5, 0, 0}, {6, 0, 0}, {5, 1, 0}, {6, 1, 0}, {7, 1, 0}, {6, 2, 0}}, {});
  b.scene({b.node({{"mesh", b.mesh(json::array({p0, p1}))}})});
  const Scene s = loadSceneFromMemory(b.gltf());
  ASSERT_EQ(s.meshes.size(), 2u);
  EXPECT_EQ(s.meshes[0].primitive, 0);
  EXPECT_EQ(s.meshes[1].primitive, 1);
  EXPECT_EQ(s.meshes[0].indices, (std::vector<std::uint32_t>{2, 1, 0}));
  EXPECT_EQ(s.meshes[1].indices, (std::vector<std::uint32_t>{0, 1, 2, 3, 4, 5}));  // generated 0..n-1
  EXPECT_EQ(s.features.triangles, 3u);
}

TEST(GltfLoader, MatrixNodeUnderTrsParentTransformsPositionsAndNormals) {
  GltfBuilder b;
  const float r = 1.f / std::sqrt(2.f);
  const int m = b.mesh(json::array({trianglePrimitive<std::uint8_t>(
      b, {{1, 1, 0}, {0, 0, 0}, {1, 0, 0}}, {0, 1, 2}, {{r, r, 0}, {0, 0, 1}, {0, 0, 1}})}));
  // Child: scale (1, 3, 1) then translate (0, 1, 0), as a column-major matrix.
  const int child = b.node({{"mesh", m}, {"matrix", {1, 0, 0, 0, 0, 3, 0, 0, 0, 0, 1, 0, 0, 1, 0, 1}}});
  // Parent: scale 2, rotate 90 degrees about Z, translate (10, 0, 0).
  const int parent = b.node({{"children", {child}}, {"translation", {10, 0, 0}},
                             {"rotation", quat({0, 0, 1}, 90)}, {"scale", {2, 2, 2}}});
  b.scene({parent});
  const Scene s = loadSceneFromMemory(b.gltf());
  ASSERT_EQ(s.meshes.size(), 1u);
  const auto& mi = s.meshes[0];
  // (1,1,0) -> child (1,4,0) -> scale (2,8,0) -> rotate (-8,2,0) -> translate (2,2,0).
  expectVec(mi.positions[0], {2, 2, 0}, 1e-4f);
  // (1,0,0) -> (1,1,0) -> (2,2,0) -> (-2,2,0) -> (8,2,0).
  expectVec(mi.positions[2], {8, 2, 0}, 1e-4f);
  // Normal (1,1,0)/sqrt2 -> inverse transpose of diag(1,3,1): (1,1/3,0) ~ (3,1,0) -> rotate (-1,3,0).
  expectVec(mi.normals[0], glm::vec3(-1, 3, 0) / std::sqrt(10.f), 1e-5f);
  expectVec(mi.normals[1], {0, 0, 1});
  expectVec(glm::vec3(mi.world * glm::vec4(1, 1, 0, 1)), {2, 2, 0}, 1e-4f);
}

TEST(GltfLoader, MirroringTransformKeepsCounterClockwiseFrontFaces) {
  GltfBuilder b;
  const int m = b.mesh(json::array({trianglePrimitive<std::uint8_t>(b, kTri, {0, 1, 2}, {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}})}));
  b.scene({b.node({{"mesh", m}, {"scale", {-1, 1, 1}}})});
  const Scene s = loadSceneFromMemory(b.gltf());
  const auto& mi = s.meshes[0];
  const auto& p = mi.positions;
  const auto& i = mi.indices;
  const glm::vec3 geometric = glm::normalize(glm::cross(p[i[1]] - p[i[0]], p[i[2]] - p[i[0]]));
  expectVec(geometric, {0, 0, 1});   // the winding was flipped with the mirror
  expectVec(mi.normals[0], {0, 0, 1});  // normal (0,0,1) is unchanged by a mirror in x
}

TEST(GltfLoader, MissingNormalsAreGeneratedInWorldSpace) {
  GltfBuilder b;
  const int m = b.mesh(json::array({trianglePrimitive<std::uint8_t>(b, kTri, {0, 1, 2})}));
  // -90 degrees about X turns the triangle's +Z normal to +Y.
  b.scene({b.node({{"mesh", m}, {"rotation", quat({1, 0, 0}, -90)}})});
  const Scene s = loadSceneFromMemory(b.gltf());
  ASSERT_EQ(s.meshes[0].normals.size(), 3u);
  for (const auto& n : s.meshes[0].normals) expectVec(n, {0, 1, 0});
}

TEST(GltfLoader, GeneratedNormalsAreAreaWeighted) {
  GltfBuilder b;
  // Vertex 0 is shared by a triangle of area 1/2 facing +Z and one of area 2 facing +X.
  const int m = b.mesh(json::array({trianglePrimitive<std::uint8_t>(
      b, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 2, 0}, {0, 0, 2}}, {0, 1, 2, 0, 3, 4})}));
  b.scene({b.node({{"mesh", m}})});
  const Scene s = loadSceneFromMemory(b.gltf());
  // Sum of edge cross products: (0,0,1) + (4,0,0).
  expectVec(s.meshes[0].normals[0], glm::vec3(4, 0, 1) / std::sqrt(17.f));
  expectVec(s.meshes[0].normals[1], {0, 0, 1});
  expectVec(s.meshes[0].normals[3], {1, 0, 0});
}

TEST(GltfLoader, TriangleStripsAndFansBecomeLists) {
  GltfBuilder b;
  const std::vector<glm::vec3> quad = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
  json strip = trianglePrimitive<std::uint8_t>(b, quad, {});
  strip["mode"] = 5;
  json fan = trianglePrimitive<std::uint8_t>(b, {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, {});
  fan["mode"] = 6;
  b.scene({b.node({{"mesh", b.mesh(json::array({strip, fan}))}})});
  const Scene s = loadSceneFromMemory(b.gltf());
  ASSERT_EQ(s.meshes.size(), 2u);
  // Strip triangle i is {p_i, p_(i+1+i%2), p_(i+2-i%2)}; fan triangle i is {p_(i+1), p_(i+2), p_0}.
  EXPECT_EQ(s.meshes[0].indices, (std::vector<std::uint32_t>{0, 1, 2, 1, 3, 2}));
  EXPECT_EQ(s.meshes[1].indices, (std::vector<std::uint32_t>{1, 2, 0, 2, 3, 0}));
  for (const auto& mi : s.meshes)
    for (std::size_t t = 0; t < mi.indices.size(); t += 3) {
      const auto& p = mi.positions;
      const glm::vec3 n = glm::cross(p[mi.indices[t + 1]] - p[mi.indices[t]], p[mi.indices[t + 2]] - p[mi.indices[t]]);
      EXPECT_GT(n.z, 0.f) << "every triangle counter-clockwise";
    }
}

TEST(GltfLoader, SparseAccessorOverridesElements) {
  GltfBuilder b;
  json prim = trianglePrimitive<std::uint8_t>(b, kTri, {0, 1, 2});
  const std::uint8_t sparseIdx[] = {2, 0, 0, 0};
  const glm::vec3 sparseVal(0, 5, 0);
  const int iv = b.view(sparseIdx, 1);
  const int vv = b.view(&sparseVal, 12);
  const int pos = prim["attributes"]["POSITION"];
  b.doc["accessors"][pos]["sparse"] = {{"count", 1},
                                       {"indices", {{"bufferView", iv}, {"componentType", 5121}}},
                                       {"values", {{"bufferView", vv}}}};
  b.scene({b.node({{"mesh", b.mesh(json::array({prim}))}})});
  const Scene s = loadSceneFromMemory(b.gltf());
  expectVec(s.meshes[0].positions[2], {0, 5, 0});
  expectVec(s.meshes[0].positions[1], {1, 0, 0});
}

TEST(GltfLoader, PngTextureFromDataUriDecodesTexels) {
  const std::vector<std::uint8_t> texels = {255, 0, 0, 255, 0, 255, 0, 255,      // top row: red, green
                                            0, 0, 255, 255, 255, 255, 255, 128};  // bottom: blue, white a=128
  const std::string png = test::encodePng(2, 2, texels);
  GltfBuilder b;
  b.push("images", {{"uri", "data:image/png;base64," + test::base64(png)}});
  b.push("samplers", {{"magFilter", 9728}, {"minFilter", 9728}, {"wrapS", 33071}, {"wrapT", 33648}});
  b.push("textures", {{"source", 0}, {"sampler", 0}});
  b.push("textures", {{"source", 0}});
  const int mat = b.material({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}},
                                                        {"metallicRoughnessTexture", {{"index", 1}, {"texCoord", 1}}}}},
                              {"occlusionTexture", {{"index", 1}, {"strength", 0.25}}}});
  const int m = b.mesh(json::array({trianglePrimitive<std::uint8_t>(b, kTri, {0, 1, 2}, {}, {{0, 0}, {1, 0}, {0, 1}}, mat)}));
  b.scene({b.node({{"mesh", m}})});
  const Scene s = loadSceneFromMemory(b.gltf());
  ASSERT_EQ(s.textures.size(), 2u);
  const Texture& t = s.textures[0];
  EXPECT_EQ(t.width, 2);
  EXPECT_EQ(t.height, 2);
  EXPECT_EQ(t.rgba8, texels);
  EXPECT_EQ(t.wrapS, 33071);
  EXPECT_EQ(t.wrapT, 33648);
  EXPECT_EQ(t.minFilter, 9728);
  EXPECT_EQ(t.magFilter, 9728);
  EXPECT_EQ(t.colorSpace, TextureColorSpace::SRGB);  // used as base colour
  EXPECT_EQ(s.textures[1].colorSpace, TextureColorSpace::Linear);
  EXPECT_EQ(s.textures[1].wrapS, 10497);  // no sampler: REPEAT
  const Material& mm = s.materials[0];
  EXPECT_EQ(mm.baseColorTexture.texture, 0);
  EXPECT_EQ(mm.metallicRoughnessTexture.texture, 1);
  EXPECT_EQ(mm.metallicRoughnessTexture.texCoord, 1);
  EXPECT_FLOAT_EQ(mm.occlusionTexture.scale, 0.25f);
  EXPECT_TRUE(s.meshes[0].tangents.empty());  // no normal map, no tangents
  ASSERT_EQ(s.meshes[0].uv0.size(), 3u);
  EXPECT_FLOAT_EQ(s.meshes[0].uv0[1].x, 1.f);
  EXPECT_EQ(s.features.textures, 2);
}

TEST(GltfLoader, LayeredExtensionTexturesAreReadWithTheirColourSpacesAndTransforms) {
  // KHR_materials_clearcoat, _sheen and _specular name their textures in extension JSON, which tinygltf
  // leaves unparsed: index, texCoord, the coat normal's scale and KHR_texture_transform come through,
  // the colour textures (sheenColorTexture, specularColorTexture) are sRGB, the data ones linear, a
  // coat normal map alone gets a tangent frame, and nothing is listed in stats.warnings.
  const std::string png = test::encodePng(1, 1, {128, 128, 255, 255});
  GltfBuilder b;
  for (int i = 0; i < 3; ++i) b.push("images", {{"uri", "data:image/png;base64," + test::base64(png)}});
  for (int i = 0; i < 3; ++i) b.push("textures", {{"source", i}});
  const json transform = {{"KHR_texture_transform", {{"offset", {0.5, 0.0}}, {"scale", {2.0, 2.0}}}}};
  const int mat = b.material(
      {{"extensions",
        {{"KHR_materials_clearcoat", {{"clearcoatFactor", 1.0}, {"clearcoatTexture", {{"index", 0}}},
                                      {"clearcoatRoughnessTexture", {{"index", 0}, {"texCoord", 1}}},
                                      {"clearcoatNormalTexture", {{"index", 0}, {"scale", 0.25}}}}},
         {"KHR_materials_sheen", {{"sheenColorTexture", {{"index", 1}, {"extensions", transform}}},
                                  {"sheenRoughnessTexture", {{"index", 0}}}}},
         {"KHR_materials_specular", {{"specularTexture", {{"index", 2}}}, {"specularColorTexture", {{"index", 1}}}}}}}});
  const int m = b.mesh(json::array({trianglePrimitive<std::uint8_t>(b, kTri, {0, 1, 2}, {}, {{0, 1}, {1, 1}, {0, 0}}, mat)}));
  b.scene({b.node({{"mesh", m}})});
  b.doc["extensionsUsed"] = json::array({"KHR_materials_clearcoat", "KHR_materials_sheen", "KHR_materials_specular",
                                         "KHR_texture_transform"});
  const Scene s = loadSceneFromMemory(b.gltf());
  const Material& mm = s.materials[0];
  EXPECT_EQ(mm.clearcoatTexture.texture, 0);
  EXPECT_EQ(mm.clearcoatRoughnessTexture.texCoord, 1);
  EXPECT_EQ(mm.clearcoatNormalTexture.texture, 0);
  EXPECT_FLOAT_EQ(mm.clearcoatNormalTexture.scale, 0.25f);
  EXPECT_EQ(mm.sheenColorTexture.texture, 1);
  EXPECT_EQ(mm.sheenRoughnessTexture.texture, 0);
  EXPECT_EQ(mm.specularTexture.texture, 2);
  EXPECT_EQ(mm.specularColorTexture.texture, 1);
  // uv' = T S uv: (2 u + 0.5, 2 v).
  const glm::vec2 moved = mm.sheenColorTexture.transformUv({0.25f, 0.5f});
  EXPECT_FLOAT_EQ(moved.x, 1.f);
  EXPECT_FLOAT_EQ(moved.y, 1.f);
  EXPECT_FLOAT_EQ(mm.specularColorTexture.transformUv({0.25f, 0.5f}).x, 0.25f);  // its own slot: no transform
  EXPECT_EQ(s.textures[0].colorSpace, TextureColorSpace::Linear);
  EXPECT_EQ(s.textures[1].colorSpace, TextureColorSpace::SRGB);
  EXPECT_EQ(s.textures[2].colorSpace, TextureColorSpace::Linear);
  EXPECT_EQ(s.meshes[0].tangents.size(), 3u);  // the coat's normal map needs the tangent frame
  for (const std::string& w : s.warnings) ADD_FAILURE() << "unexpected warning: " << w;
}

// KHR_materials_volume's thicknessTexture (green, data) comes through with its texCoord and
// KHR_texture_transform, linear, without a warning; an index that does not exist is refused at its pointer.
TEST(GltfLoader, VolumeThicknessTextureIsReadWithItsTransform) {
  const std::string png = test::encodePng(1, 1, {128, 128, 255, 255});
  GltfBuilder b;
  b.push("images", {{"uri", "data:image/png;base64," + test::base64(png)}});
  b.push("textures", {{"source", 0}});
  const json transform = {{"KHR_texture_transform", {{"offset", {0.5, 0.0}}, {"scale", {2.0, 2.0}}}}};
  const int mat = b.material({{"extensions",
                               {{"KHR_materials_volume",
                                 {{"thicknessFactor", 0.3}, {"thicknessTexture", {{"index", 0}, {"texCoord", 1}, {"extensions", transform}}}}}}}});
  const int bad = b.material({{"extensions", {{"KHR_materials_volume", {{"thicknessTexture", {{"index", 4}}}}}}}});
  const int m = b.mesh(json::array({trianglePrimitive<std::uint8_t>(b, kTri, {0, 1, 2}, {}, {{0, 1}, {1, 1}, {0, 0}}, mat)}));
  b.scene({b.node({{"mesh", m}})});
  b.doc["extensionsUsed"] = json::array({"KHR_materials_volume", "KHR_texture_transform"});
  GltfBuilder good = b;
  good.doc["materials"].erase(std::size_t(bad));
  const Scene s = loadSceneFromMemory(good.gltf());
  const Material& mm = s.materials[0];
  EXPECT_FLOAT_EQ(mm.thicknessFactor, 0.3f);
  EXPECT_EQ(mm.thicknessTexture.texture, 0);
  EXPECT_EQ(mm.thicknessTexture.texCoord, 1);
  const glm::vec2 moved = mm.thicknessTexture.transformUv({0.25f, 0.5f});  // (2 u + 0.5, 2 v)
  EXPECT_FLOAT_EQ(moved.x, 1.f);
  EXPECT_FLOAT_EQ(moved.y, 1.f);
  EXPECT_EQ(s.textures[0].colorSpace, TextureColorSpace::Linear);
  for (const std::string& w : s.warnings) ADD_FAILURE() << "unexpected warning: " << w;
  try {
    loadSceneFromMemory(b.gltf());
    ADD_FAILURE() << "a thicknessTexture that does not exist loaded";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.pointer, "/materials/1/extensions/KHR_materials_volume/thicknessTexture/index");
  }
}

TEST(GltfLoader, LayeredExtensionTextureThatDoesNotExistIsRefusedAtItsPointer) {
  GltfBuilder b;
  const int mat = b.material({{"extensions", {{"KHR_materials_sheen", {{"sheenColorTexture", {{"index", 3}}}}}}}});
  const int m = b.mesh(json::array({trianglePrimitive<std::uint8_t>(b, kTri, {0, 1, 2}, {}, {}, mat)}));
  b.scene({b.node({{"mesh", m}})});
  try {
    loadSceneFromMemory(b.gltf());
    FAIL() << "a missing texture was accepted";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.pointer, "/materials/0/extensions/KHR_materials_sheen/sheenColorTexture/index");
  }
}

// A normal-mapped triangle in the XY plane (normal +Z) with the given UVs at (0,0,0), (1,0,0), (0,1,0).
Scene normalMapped(const std::vector<glm::vec2>& uv) {
  const std::string png = test::encodePng(1, 1, {128, 128, 255, 255});
  GltfBuilder b;
  b.push("images", {{"uri", "data:image/png;base64," + test::base64(png)}});
  b.push("textures", {{"source", 0}});
  const int mat = b.material({{"normalTexture", {{"index", 0}, {"scale", 0.5}}}});
  const int m = b.mesh(json::array({trianglePrimitive<std::uint8_t>(b, kTri, {0, 1, 2}, {}, uv, mat)}));
  b.scene({b.node({{"mesh", m}})});
  return loadSceneFromMemory(b.gltf());
}

TEST(GltfLoader, TangentsGeneratedForNormalMapsWithGltfHandedness) {
  // Upright image: v grows down the image, so dP/dv = -Y and the bitangent cross(N, T) * w = +Y
  // must be -dP/dv: w = +1.
  const Scene upright = normalMapped({{0, 1}, {1, 1}, {0, 0}});
  ASSERT_EQ(upright.meshes[0].tangents.size(), 3u);
  EXPECT_FLOAT_EQ(upright.materials[0].normalTexture.scale, 0.5f);
  for (const auto& t : upright.meshes[0].tangents) {
    expectVec(glm::vec3(t), {1, 0, 0});
    EXPECT_EQ(t.w, 1.f);
  }
  // The image mirrored vertically: w = -1.
  const Scene mirrored = normalMapped({{0, 0}, {1, 0}, {0, 1}});
  for (const auto& t : mirrored.meshes[0].tangents) {
    expectVec(glm::vec3(t), {1, 0, 0});
    EXPECT_EQ(t.w, -1.f);
  }
  // U running along +Y instead: the tangent follows it.
  const Scene turned = normalMapped({{0, 0}, {0, 1}, {1, 0}});
  for (const auto& t : turned.meshes[0].tangents) expectVec(glm::vec3(t), {0, 1, 0});
}

TEST(GltfLoader, EveryLightTypeInWorldSpace) {
  GltfBuilder b;
  b.doc["extensionsUsed"] = {"KHR_lights_punctual"};
  b.doc["extensions"]["KHR_lights_punctual"]["lights"] = {
      {{"name", "bulb"}, {"type", "point"}, {"color", {1, 0.5, 0.25}}, {"intensity", 3.5}, {"range", 10}},
      {{"name", "spot"}, {"type", "spot"}, {"intensity", 7}, {"spot", {{"innerConeAngle", 0.2}, {"outerConeAngle", 0.6}}}},
      {{"name", "sun"}, {"type", "directional"}, {"intensity", 2}}};
  auto lightNode = [&](int light, json extra) {
    extra["extensions"] = {{"KHR_lights_punctual", {{"light", light}}}};
    return b.node(extra);
  };
  const int point = lightNode(0, {{"translation", {1, 0, 0}}});
  const int spot = lightNode(1, {{"translation", {0, 0, 2}}, {"rotation", quat({1, 0, 0}, -90)}});
  const int sun = lightNode(2, {{"rotation", quat({0, 1, 0}, 90)}});
  const int parent = b.node({{"translation", {0, 5, 0}}, {"children", {point, spot}}});
  const int m = b.mesh(json::array({trianglePrimitive<std::uint8_t>(b, kTri, {0, 1, 2})}));
  b.scene({parent, sun, b.node({{"mesh", m}})});
  const Scene s = loadSceneFromMemory(b.gltf());
  ASSERT_EQ(s.lights.size(), 3u);
  const Light& p = s.lights[0];
  EXPECT_EQ(p.type, LightType::Point);
  EXPECT_EQ(p.name, "bulb");
  expectVec(p.position, {1, 5, 0});
  expectVec(p.color, {1, 0.5f, 0.25f});
  EXPECT_FLOAT_EQ(p.intensity, 3.5f);
  EXPECT_FLOAT_EQ(p.range, 10.f);
  const Light& sp = s.lights[1];
  EXPECT_EQ(sp.type, LightType::Spot);
  expectVec(sp.position, {0, 5, 2});
  expectVec(sp.direction, {0, -1, 0});  // -Z turned -90 degrees about X points down
  EXPECT_FLOAT_EQ(sp.innerConeAngle, 0.2f);
  EXPECT_FLOAT_EQ(sp.outerConeAngle, 0.6f);
  const Light& d = s.lights[2];
  EXPECT_EQ(d.type, LightType::Directional);
  expectVec(d.direction, {-1, 0, 0});  // -Z turned 90 degrees about Y
  EXPECT_FLOAT_EQ(d.intensity, 2.f);
  EXPECT_EQ(s.features.pointLights, 1);
  EXPECT_EQ(s.features.spotLights, 1);
  EXPECT_EQ(s.features.directionalLights, 1);
  EXPECT_EQ(s.features.lightCount(), 3);
}

TEST(GltfLoader, NoCameraGivesDefaultCameraFramingTheBounds) {
  GltfBuilder b;
  const glm::vec3 lo(-1, -2, -3), hi(4, 5, 6);
  const int m = b.mesh(json::array({trianglePrimitive<std::uint8_t>(b, {lo, {hi.x, lo.y, hi.z}, hi}, {0, 1, 2})}));
  b.scene({b.node({{"mesh", m}})});
  const Scene s = loadSceneFromMemory(b.gltf());
  EXPECT_FALSE(s.camera.fromFile);
  EXPECT_FALSE(s.features.hasCamera);
  EXPECT_EQ(s.camera.projection, ProjectionType::Perspective);
  expectVec(s.features.bounds.min, lo);
  expectVec(s.features.bounds.max, hi);
  // Looks down -Z at the centre.
  const glm::vec3 eye(s.camera.world[3]);
  const glm::vec3 forward = -glm::vec3(s.camera.world[2]);
  expectVec(glm::normalize(s.features.bounds.center() - eye), forward, 1e-5f);
  const glm::mat4 proj = glm::perspective(s.camera.yfov, 1.f, s.camera.znear, 1000.f);
  const glm::mat4 view = glm::inverse(s.camera.world);
  for (int c = 0; c < 8; ++c) {
    const glm::vec3 corner(c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z);
    const glm::vec4 clip = proj * view * glm::vec4(corner, 1.f);
    ASSERT_GT(clip.w, s.camera.znear) << "corner " << c << " behind the near plane";
    EXPECT_LE(std::abs(clip.x / clip.w), 1.f) << "corner " << c;
    EXPECT_LE(std::abs(clip.y / clip.w), 1.f) << "corner " << c;
    EXPECT_GE(clip.z / clip.w, 0.f) << "corner " << c;
    EXPECT_LE(clip.z / clip.w, 1.f) << "corner " << c;
  }
}

TEST(DefaultCamera, FramesBoundsForWideAndTallAspects) {
  Bounds bounds;
  bounds.extend(glm::vec3(-10, 0, 3));
  bounds.extend(glm::vec3(-8, 30, 4));
  for (float aspect : {0.25f, 1.f, 2.5f}) {
    const Camera cam = defaultCameraFor(bounds, aspect);
    const glm::mat4 vp = glm::perspective(cam.yfov, aspect, cam.znear, 1e4f) * glm::inverse(cam.world);
    for (int c = 0; c < 8; ++c) {
      const glm::vec3 corner(c & 1 ? bounds.max.x : bounds.min.x, c & 2 ? bounds.max.y : bounds.min.y,
                             c & 4 ? bounds.max.z : bounds.min.z);
      const glm::vec4 clip = vp * glm::vec4(corner, 1.f);
      ASSERT_GT(clip.w, cam.znear);
      EXPECT_LE(std::abs(clip.x / clip.w), 1.f) << "aspect " << aspect << " corner " << c;
      EXPECT_LE(std::abs(clip.y / clip.w), 1.f) << "aspect " << aspect << " corner " << c;
    }
  }
  // Empty bounds still give a usable camera.
  const Camera empty = defaultCameraFor(Bounds{}, 1.f);
  EXPECT_GT(empty.world[3].z, 0.f);
  EXPECT_GT(empty.znear, 0.f);
}

TEST(GltfLoader, FirstCameraNodeIsUsedWithScaleRemoved) {
  GltfBuilder b;
  b.push("cameras", {{"type", "perspective"}, {"name", "main"},
                     {"perspective", {{"yfov", 0.5}, {"znear", 0.1}, {"zfar", 50}, {"aspectRatio", 1.5}}}});
  b.push("cameras", {{"type", "orthographic"}, {"orthographic", {{"xmag", 2}, {"ymag", 1}, {"znear", 0}, {"zfar", 9}}}});
  const int cam0 = b.node({{"camera", 0}, {"translation", {1, 2, 3}}, {"rotation", quat({0, 1, 0}, 90)}, {"scale", {2, 2, 2}}});
  const int cam1 = b.node({{"camera", 1}});
  b.scene({cam0, cam1});
  const Scene s = loadSceneFromMemory(b.gltf());
  EXPECT_TRUE(s.camera.fromFile);
  EXPECT_TRUE(s.features.hasCamera);
  EXPECT_EQ(s.camera.name, "main");
  EXPECT_EQ(s.camera.projection, ProjectionType::Perspective);
  EXPECT_FLOAT_EQ(s.camera.yfov, 0.5f);
  EXPECT_FLOAT_EQ(s.camera.znear, 0.1f);
  EXPECT_FLOAT_EQ(s.camera.zfar, 50.f);
  EXPECT_FLOAT_EQ(s.camera.aspectRatio, 1.5f);
  expectVec(glm::vec3(s.camera.world[3]), {1, 2, 3});
  expectVec(-glm::vec3(s.camera.world[2]), {-1, 0, 0});  // -Z turned 90 degrees about Y
  EXPECT_NEAR(glm::length(glm::vec3(s.camera.world[0])), 1.f, 1e-6f);  // scale removed

  GltfBuilder o;
  o.push("cameras", {{"type", "orthographic"}, {"orthographic", {{"xmag", 2}, {"ymag", 1}, {"znear", 0.5}, {"zfar", 9}}}});
  o.scene({o.node({{"camera", 0}})});
  const Scene so = loadSceneFromMemory(o.gltf());
  EXPECT_EQ(so.camera.projection, ProjectionType::Orthographic);
  EXPECT_FLOAT_EQ(so.camera.xmag, 2.f);
  EXPECT_FLOAT_EQ(so.camera.ymag, 1.f);
  EXPECT_FLOAT_EQ(so.camera.zfar, 9.f);
}

TEST(GltfLoader, MaterialsExtensionsExtrasAndFeatures) {
  GltfBuilder b;
  b.doc["extensionsUsed"] = {"KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_emissive_strength"};
  b.doc["extensionsRequired"] = {"KHR_materials_emissive_strength"};
  const int lamp = b.material({{"name", "lamp"}, {"emissiveFactor", {1, 0.5, 0}},
                               {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 20}}}}}});
  const int glass = b.material({{"name", "glass"}, {"pbrMetallicRoughness", {{"metallicFactor", 0}, {"roughnessFactor", 0}}},
                                {"extensions", {{"KHR_materials_transmission", {{"transmissionFactor", 1}}},
                                                {"KHR_materials_ior", {{"ior", 1.33}}}}}});
  const int mirror = b.material({{"name", "mirror"}, {"pbrMetallicRoughness", {{"baseColorFactor", {0.9, 0.8, 0.7, 1}},
                                                                               {"metallicFactor", 1}, {"roughnessFactor", 0.05}}},
                                 {"doubleSided", true}, {"alphaMode", "MASK"}, {"alphaCutoff", 0.3}});
  b.material({{"name", "unused_mirror"}, {"pbrMetallicRoughness", {{"metallicFactor", 1}, {"roughnessFactor", 0}}}});
  const std::vector<glm::vec3> two = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
  const int m = b.mesh(json::array({trianglePrimitive<std::uint8_t>(b, two, {0, 1, 2, 2, 1, 3}, {}, {}, lamp),
                                    trianglePrimitive<std::uint8_t>(b, kTri, {0, 1, 2}, {}, {}, glass),
                                    trianglePrimitive<std::uint8_t>(b, kTri, {0, 1, 2}, {}, {}, mirror),
                                    trianglePrimitive<std::uint8_t>(b, kTri, {0, 1, 2})}));
  b.scene({b.node({{"name", "thing"}, {"mesh", m}, {"extras", {{"receiver", true}, {"id", 7}}}})});
  const Scene s = loadSceneFromMemory(b.gltf());
  ASSERT_EQ(s.materials.size(), 4u);
  ASSERT_EQ(s.meshes.size(), 4u);
  const Material& l = s.materials[0];
  EXPECT_FLOAT_EQ(l.emissiveStrength, 20.f);
  expectVec(l.emission(), {20, 10, 0});
  EXPECT_TRUE(l.isEmissive());
  const Material& g = s.materials[1];
  EXPECT_FLOAT_EQ(g.transmissionFactor, 1.f);
  EXPECT_FLOAT_EQ(g.ior, 1.33f);
  EXPECT_TRUE(g.isTransmissive());
  const Material& mi = s.materials[2];
  EXPECT_FLOAT_EQ(mi.baseColorFactor.y, 0.8f);
  EXPECT_FLOAT_EQ(mi.metallicFactor, 1.f);
  EXPECT_FLOAT_EQ(mi.roughnessFactor, 0.05f);
  EXPECT_TRUE(mi.doubleSided);
  EXPECT_EQ(mi.alphaMode, AlphaMode::Mask);
  EXPECT_FLOAT_EQ(mi.alphaCutoff, 0.3f);
  EXPECT_EQ(s.meshes[3].material, -1);
  EXPECT_EQ(s.features.emissiveTriangles, 2);
  EXPECT_TRUE(s.features.hasEmissive());
  EXPECT_EQ(s.features.transmissiveMaterials, 1);
  EXPECT_EQ(s.features.specularMaterials, 2);  // glass and mirror; the unused mirror does not count
  EXPECT_EQ(s.features.triangles, 5u);
  const json extras = json::parse(s.meshes[0].extrasJson);
  EXPECT_EQ(extras["id"], 7);
  EXPECT_EQ(extras["receiver"], true);
  EXPECT_EQ(s.meshes[0].name, "thing");
}

TEST(GltfLoader, ExternalBufferInsideRootAndDigestCoversIt) {
  test::TempDir dir("external");
  GltfBuilder b;
  const int m = b.mesh(json::array({trianglePrimitive<std::uint8_t>(b, kTri, {0, 1, 2})}));
  b.scene({b.node({{"mesh", m}})});
  const auto file = dir.path / "assets" / "tri.gltf";
  test::writeFile(file, b.gltfExternal("data/tri%20mesh.bin"));  // percent-encoded space
  test::writeFile(dir.path / "assets" / "data" / "tri mesh.bin", b.bin);
  LoadOptions options;
  options.assetRoot = dir.path;
  const Scene s = loadScene(file, options);
  EXPECT_EQ(s.name, "tri");
  ASSERT_EQ(s.meshes.size(), 1u);
  expectVec(s.meshes[0].positions[2], {0, 1, 0});
  // Changing only the .bin changes the digest.
  std::string bin2 = b.bin;
  bin2[4] = 1;  // a bit of position 0's x
  test::writeFile(dir.path / "assets" / "data" / "tri mesh.bin", bin2);
  const Scene s2 = loadScene(file, options);
  EXPECT_NE(s.digest, s2.digest);
  // The same document from memory, with the root as base directory.
  options.assetRoot = dir.path / "assets";
  const Scene s3 = loadSceneFromMemory(b.gltfExternal("data/tri%20mesh.bin"), options);
  EXPECT_EQ(s3.meshes[0].positions.size(), 3u);
  // An empty root for loadScene means the file's own directory.
  const Scene s4 = loadScene(file);
  EXPECT_EQ(s4.digest, s2.digest);
}

TEST(GltfLoader, QuantizedAttributesAreNormalised) {
  // KHR_mesh_quantization: normalised UNSIGNED_SHORT texcoords, normalised BYTE normals, SHORT positions.
  GltfBuilder b;
  b.doc["extensionsUsed"] = {"KHR_mesh_quantization"};
  b.doc["extensionsRequired"] = {"KHR_mesh_quantization"};
  const std::int16_t pos[] = {0, 0, 0, 0, 100, 0, 0, 0, 0, 100, 0, 0};  // padded to 4-byte elements
  const std::int8_t nrm[] = {0, 0, 127, 0, 0, 0, -128, 0, 0, 0, 127, 0};
  const std::uint16_t uv[] = {0, 65535, 65535, 0, 32768, 0};
  const int pa = b.accessor(b.view(pos, sizeof(pos), 8), 5122, 3, "VEC3");
  b.doc["accessors"][pa]["min"] = {0, 0, 0};
  b.doc["accessors"][pa]["max"] = {100, 100, 0};
  const int na = b.accessor(b.view(nrm, sizeof(nrm), 4), 5120, 3, "VEC3");
  b.doc["accessors"][na]["normalized"] = true;
  const int ta = b.accessor(b.view(uv, sizeof(uv)), 5123, 3, "VEC2");
  b.doc["accessors"][ta]["normalized"] = true;
  const int m = b.mesh(json::array({{{"attributes", {{"POSITION", pa}, {"NORMAL", na}, {"TEXCOORD_0", ta}}}}}));
  b.scene({b.node({{"mesh", m}, {"scale", {0.01, 0.01, 0.01}}})});
  const Scene s = loadSceneFromMemory(b.gltf());
  const auto& mi = s.meshes[0];
  expectVec(mi.positions[1], {1, 0, 0});
  expectVec(mi.positions[2], {0, 1, 0});
  expectVec(mi.normals[0], {0, 0, 1});
  expectVec(mi.normals[1], {0, 0, -1});  // -128 / 127 clamps to -1
  EXPECT_FLOAT_EQ(mi.uv0[0].y, 1.f);
  EXPECT_FLOAT_EQ(mi.uv0[1].x, 1.f);
  EXPECT_NEAR(mi.uv0[2].x, 32768.f / 65535.f, 1e-7f);
}

TEST(GltfLoader, FileTangentsAreTransformedAndFlipHandednessUnderMirrors) {
  const std::string png = test::encodePng(1, 1, {128, 128, 255, 255});
  GltfBuilder b;
  b.push("images", {{"uri", "data:image/png;base64," + test::base64(png)}});
  b.push("textures", {{"source", 0}});
  const int mat = b.material({{"normalTexture", {{"index", 0}}}});
  json prim = trianglePrimitive<std::uint8_t>(b, kTri, {0, 1, 2}, {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}},
                                              {{0, 1}, {1, 1}, {0, 0}}, mat);
  prim["attributes"]["TANGENT"] = b.vec4({{1, 0, 0, 1}, {1, 0, 0, 1}, {1, 0, 0, 1}});
  const int m = b.mesh(json::array({prim}));
  b.scene({b.node({{"mesh", m}, {"scale", {1, -1, 1}}})});
  const Scene s = loadSceneFromMemory(b.gltf());
  ASSERT_EQ(s.meshes[0].tangents.size(), 3u);
  for (const auto& t : s.meshes[0].tangents) {
    expectVec(glm::vec3(t), {1, 0, 0});
    EXPECT_EQ(t.w, -1.f);  // the mirror in y turns B = cross(N, T) into -B
  }
}

TEST(GltfLoader, ImageInGlbBufferView) {
  const std::vector<std::uint8_t> texels = {10, 20, 30, 255, 40, 50, 60, 255, 70, 80, 90, 255};
  const std::string png = test::encodePng(3, 1, texels);
  GltfBuilder b;
  const int iv = b.view(png.data(), png.size());
  b.push("images", {{"bufferView", iv}, {"mimeType", "image/png"}});
  b.push("textures", {{"source", 0}});
  const int mat = b.material({{"emissiveTexture", {{"index", 0}}}, {"emissiveFactor", {1, 1, 1}}});
  const int m = b.mesh(json::array({trianglePrimitive<std::uint8_t>(b, kTri, {0, 1, 2}, {}, {{0, 0}, {1, 0}, {0, 1}}, mat)}));
  b.scene({b.node({{"mesh", m}})});
  const Scene s = loadSceneFromMemory(b.glb());
  ASSERT_EQ(s.textures.size(), 1u);
  EXPECT_EQ(s.textures[0].width, 3);
  EXPECT_EQ(s.textures[0].rgba8, texels);
  EXPECT_EQ(s.textures[0].colorSpace, TextureColorSpace::SRGB);  // emissive is colour
  EXPECT_EQ(s.features.emissiveTriangles, 1);
}

// EXT_texture_webp: a lossless WebP (encoded here with libwebp) decodes to exactly its texels; the
// extension's image wins over a PNG fallback in `source`; an undecodable WebP is refused at its image.
std::string encodeWebpLossless(int w, int h, const std::vector<std::uint8_t>& rgba) {
  std::uint8_t* out = nullptr;
  const std::size_t n = WebPEncodeLosslessRGBA(rgba.data(), w, h, w * 4, &out);
  std::string bytes(reinterpret_cast<const char*>(out), n);
  WebPFree(out);
  return bytes;
}

TEST(GltfLoader, WebpTexturesDecodeExactlyAndWinOverTheirFallback) {
  const std::vector<std::uint8_t> texels = {250, 0, 10, 255, 0, 240, 20, 255, 5, 6, 230, 255};
  const std::string webp = encodeWebpLossless(3, 1, texels);
  ASSERT_GT(webp.size(), 12u);
  for (const bool fallback : {false, true}) {
    GltfBuilder b;
    b.doc["extensionsUsed"] = {"EXT_texture_webp"};
    if (!fallback) b.doc["extensionsRequired"] = {"EXT_texture_webp"};
    const int wv = b.view(webp.data(), webp.size());
    b.push("images", {{"bufferView", wv}, {"mimeType", "image/webp"}});
    json texture{{"extensions", {{"EXT_texture_webp", {{"source", 0}}}}}};
    if (fallback) {
      const std::string png = test::encodePng(1, 1, {1, 2, 3, 255});
      const int pv = b.view(png.data(), png.size());
      b.push("images", {{"bufferView", pv}, {"mimeType", "image/png"}});
      texture["source"] = 1;
    }
    b.push("textures", texture);
    const int mat = b.material({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}});
    const int m = b.mesh(json::array({trianglePrimitive<std::uint8_t>(b, kTri, {0, 1, 2}, {}, {{0, 0}, {1, 0}, {0, 1}}, mat)}));
    b.scene({b.node({{"mesh", m}})});
    const Scene s = loadSceneFromMemory(b.glb());
    ASSERT_EQ(s.textures.size(), 1u) << fallback;
    EXPECT_EQ(s.textures[0].width, 3);
    EXPECT_EQ(s.textures[0].height, 1);
    EXPECT_EQ(s.textures[0].rgba8, texels) << "fallback " << fallback;
    EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
  }
  // A truncated WebP (the RIFF header without its image): refused at the image, naming it.
  GltfBuilder b;
  const std::string broken = webp.substr(0, 20);
  const int wv = b.view(broken.data(), broken.size());
  b.push("images", {{"bufferView", wv}, {"mimeType", "image/webp"}});
  b.push("textures", {{"extensions", {{"EXT_texture_webp", {{"source", 0}}}}}});
  const int mat = b.material({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}});
  const int m = b.mesh(json::array({trianglePrimitive<std::uint8_t>(b, kTri, {0, 1, 2}, {}, {}, mat)}));
  b.scene({b.node({{"mesh", m}})});
  try {
    loadSceneFromMemory(b.glb());
    ADD_FAILURE() << "a truncated WebP was accepted";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.pointer.rfind("/images/0", 0), 0u) << e.pointer << ": " << e.what();
  }
}

TEST(GltfLoader, ExternalImageInsideRoot) {
  test::TempDir dir("image");
  const std::vector<std::uint8_t> texels = {1, 2, 3, 4};
  test::writeFile(dir.path / "tex" / "a.png", test::encodePng(1, 1, texels));
  GltfBuilder b;
  b.push("images", {{"uri", "tex/a.png"}});
  b.push("textures", {{"source", 0}});
  const int mat = b.material({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}});
  const int m = b.mesh(json::array({trianglePrimitive<std::uint8_t>(b, kTri, {0, 1, 2}, {}, {}, mat)}));
  b.scene({b.node({{"mesh", m}})});
  test::writeFile(dir.path / "scene.gltf", b.gltf());
  LoadOptions options;
  options.assetRoot = dir.path;
  const Scene s = loadScene(dir.path / "scene.gltf", options);
  ASSERT_EQ(s.textures.size(), 1u);
  EXPECT_EQ(s.textures[0].rgba8, texels);
}

}  // namespace
}  // namespace radiant
