// MikkTSpace tangents (renderer/scene/MikkTSpace.h): against the tangents Blender's exporter wrote into
// the Khronos sample NormalTangentMirrorTest, and on small meshes whose frames are known in closed form.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <fstream>
#include <iostream>
#include <iterator>

#include "renderer/scene/GltfLoader.h"
#include "renderer/scene/MikkTSpace.h"
#include "tests/unit/scene/GltfTestBuilder.h"

namespace radiant {
namespace {

using test::GltfBuilder;
using test::json;
using test::trianglePrimitive;

bool finite(const glm::vec4& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z) && std::isfinite(v.w);
}

float angleDegrees(const glm::vec3& a, const glm::vec3& b) {
  return glm::degrees(std::acos(std::clamp(glm::dot(glm::normalize(a), glm::normalize(b)), -1.f, 1.f)));
}

// ---- against an exporter ---------------------------------------------------------------------------

std::string readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// A GLB with its JSON chunk replaced.
std::string withJson(const std::string& glb, const std::function<void(json&)>& edit) {
  std::uint32_t jsonLength = 0;
  std::memcpy(&jsonLength, glb.data() + 12, 4);
  json doc = json::parse(glb.substr(20, jsonLength));
  edit(doc);
  std::string text = doc.dump();
  while (text.size() % 4) text.push_back(' ');
  const std::string rest = glb.substr(20 + jsonLength);
  std::string out = glb.substr(0, 12);
  const auto total = static_cast<std::uint32_t>(12 + 8 + text.size() + rest.size());
  const auto length = static_cast<std::uint32_t>(text.size());
  std::memcpy(out.data() + 8, &total, 4);
  out.append(reinterpret_cast<const char*>(&length), 4);
  out.append("JSON", 4);
  return out + text + rest;
}

// NormalTangentMirrorTest carries the tangents Blender computed with MikkTSpace (its exporter writes
// them unchanged, uvs flipped to glTF's v). With the TANGENT attribute removed the loader computes its
// own: every triangle corner must get the exporter's tangent (the corner's vertex may have been split)
// within a small angle, with the same handedness. Lengyel's per-vertex tangents (the loader's before,
// area-weighted sums of the triangles' dP/du) were up to 10.6 degrees off, mean 0.70, 2336 of the 15720
// corners more than 1 degree (the exporter had already split the vertices where the handedness changes,
// so the signs agreed); MikkTSpace is within 0.035 degrees everywhere.
TEST(MikkTSpace, RegeneratesTheTangentsBlendersExporterWroteIntoNormalTangentMirrorTest) {
  const std::string glb = readBytes(RADIANT_SOURCE_DIR "/tests/data/NormalTangentMirrorTest/NormalTangentMirrorTest.glb");
  ASSERT_GT(glb.size(), 1000u);
  const Scene file = loadSceneFromMemory(glb);
  const Scene generated = loadSceneFromMemory(withJson(glb, [](json& doc) {
    doc["meshes"][0]["primitives"][0]["attributes"].erase("TANGENT");
  }));
  ASSERT_EQ(file.meshes.size(), 1u);
  ASSERT_EQ(generated.meshes.size(), 1u);
  const MeshInstance& a = file.meshes[0];
  const MeshInstance& b = generated.meshes[0];
  ASSERT_EQ(a.tangents.size(), a.positions.size());
  ASSERT_EQ(b.tangents.size(), b.positions.size());
  ASSERT_EQ(a.indices.size(), b.indices.size());
  EXPECT_EQ(a.positions.size(), 2770u);
  std::cout << "NormalTangentMirrorTest: " << a.positions.size() << " vertices in the file, " << b.positions.size()
            << " after splitting by the generated tangents\n";

  float worst = 0.f;
  double sum = 0.0;
  int signDiffers = 0, aboveOneDegree = 0;
  for (std::size_t c = 0; c < a.indices.size(); ++c) {
    const glm::vec4 ta = a.tangents[a.indices[c]], tb = b.tangents[b.indices[c]];
    ASSERT_TRUE(finite(tb));
    // The same corner: same position, normal and uv.
    ASSERT_EQ(a.positions[a.indices[c]], b.positions[b.indices[c]]);
    ASSERT_EQ(a.uv0[a.indices[c]], b.uv0[b.indices[c]]);
    const float angle = angleDegrees(glm::vec3(ta), glm::vec3(tb));
    worst = std::max(worst, angle);
    sum += angle;
    if (angle > 1.f) ++aboveOneDegree;
    if (ta.w != tb.w) ++signDiffers;
  }
  std::cout << "NormalTangentMirrorTest, generated against the exporter's tangents over " << a.indices.size()
            << " corners: largest angle " << worst << " degrees, mean " << sum / double(a.indices.size())
            << ", above 1 degree " << aboveOneDegree << ", handedness differs " << signDiffers << "\n";
  // The file's tangents went through Blender's float uvs (v up) and were written as floats: the same
  // algorithm on the glTF's 1 - v agrees to rounding.
  EXPECT_EQ(signDiffers, 0);
  EXPECT_EQ(aboveOneDegree, 0);
  EXPECT_LT(worst, 0.1f);
}

// ---- closed forms -------------------------------------------------------------------------------------

// Two triangles sharing the edge x = 0 of the plane z = 0, their uvs mirrored across it (u = |x|, the
// mirror modelling trick): the shared vertices have one uv, so MikkTSpace welds them, but the two
// triangles map with opposite orientations, so they fall in different groups and the shared vertices
// are split: four vertices become six, and each side's tangent follows its own u (-x on the left).
TEST(MikkTSpace, MirroredUvsSplitTheSharedVerticesIntoTwoFrames) {
  const std::vector<glm::vec3> p = {{0, -1, 0}, {0, 1, 0}, {1, 0, 0}, {-1, 0, 0}};
  const std::vector<glm::vec3> n(4, glm::vec3(0, 0, 1));
  const std::vector<glm::vec2> uv = {{0, 1}, {0, 0}, {1, 0.5f}, {1, 0.5f}};  // u = |x|, v = (1 - y) / 2
  const std::vector<std::uint32_t> idx = {0, 2, 1, 0, 1, 3};                  // both counter-clockwise about +z
  const auto corners = gltfMikkTSpaceCornerTangents(p, n, uv, idx);
  ASSERT_EQ(corners.size(), 6u);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(glm::distance(glm::vec3(corners[std::size_t(c)]), glm::vec3(1, 0, 0)), 0.f, 1e-6f) << c;
    EXPECT_EQ(corners[std::size_t(c)].w, 1.f) << c;  // glTF: bitangent cross(n, t) w = +y = image up
    EXPECT_NEAR(glm::distance(glm::vec3(corners[std::size_t(3 + c)]), glm::vec3(-1, 0, 0)), 0.f, 1e-6f) << c;
    EXPECT_EQ(corners[std::size_t(3 + c)].w, -1.f) << c;  // the mirror: cross(n, -x) w = +y needs w = -1
  }
  const TangentSplit split = splitVerticesByTangent(corners, idx);
  EXPECT_EQ(split.vertexOf.size(), 6u);
  // The right triangle keeps the first three new vertices, the left one shares none of them.
  EXPECT_EQ(split.indices[0], 0u);
  for (int c = 3; c < 6; ++c)
    for (int d = 0; d < 3; ++d) EXPECT_NE(split.indices[std::size_t(c)], split.indices[std::size_t(d)]);
  for (std::size_t c = 0; c < idx.size(); ++c) EXPECT_EQ(split.vertexOf[split.indices[c]], idx[c]);
}

// The same mirrored pair through the loader, as a file that shares the seam's vertices (no TANGENT): the
// loader splits them, and each side's frame follows its own u. Lengyel's per-vertex sums cancelled on
// the seam (dP/du of +x and -x) and fell back to an arbitrary perpendicular there.
TEST(MikkTSpace, LoaderSplitsTheVerticesWhereMirroredUvsMeet) {
  const std::string png = test::encodePng(1, 1, {128, 128, 255, 255});
  GltfBuilder b;
  b.push("images", {{"uri", "data:image/png;base64," + test::base64(png)}});
  b.push("textures", {{"source", 0}});
  const int mat = b.material({{"normalTexture", {{"index", 0}}}});
  const int m = b.mesh(json::array({trianglePrimitive<std::uint8_t>(
      b, {{0, -1, 0}, {0, 1, 0}, {1, 0, 0}, {-1, 0, 0}}, {0, 2, 1, 0, 1, 3}, {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}},
      {{0, 1}, {0, 0}, {1, 0.5}, {1, 0.5}}, mat)}));
  b.scene({b.node({{"mesh", m}})});
  const Scene s = loadSceneFromMemory(b.gltf());
  const MeshInstance& mi = s.meshes[0];
  ASSERT_EQ(mi.positions.size(), 6u);
  ASSERT_EQ(mi.tangents.size(), 6u);
  for (std::size_t c = 0; c < 6; ++c) {
    const glm::vec4 t = mi.tangents[mi.indices[c]];
    const bool right = c < 3;
    EXPECT_LT(angleDegrees(glm::vec3(t), right ? glm::vec3(1, 0, 0) : glm::vec3(-1, 0, 0)), 1e-3f) << c;
    EXPECT_EQ(t.w, right ? 1.f : -1.f) << c;
  }
}

// A smooth vertex is averaged over its corners by their angles (Mikkelsen's weighting), not by areas
// and not per triangle: a fan of a 90-degree and a 45-degree triangle around the origin, uv sheared
// differently in each, gives the angle-weighted mean direction projected into the normal plane.
TEST(MikkTSpace, AVertexAveragesItsCornersByTheirAngles) {
  // Triangle A: (0,0), (1,0), (0,1) -- corner angle 90 at the origin, u along x.
  // Triangle B: (0,0), (0,1), (-1,1) -- corner angle 45 at the origin, u along x + y.
  const std::vector<glm::vec3> p = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {-1, 1, 0}};
  const std::vector<glm::vec3> n(4, glm::vec3(0, 0, 1));
  // u = x in A; in B the far vertex's uv turns dP/du to (1, 1, 0) / sqrt(2), same orientation.
  const std::vector<glm::vec2> uv = {{0, 0}, {1, 0}, {0, -1}, {-1, -2}};
  const std::vector<std::uint32_t> idx = {0, 1, 2, 0, 2, 3};
  // Expected per triangle (uv v flipped as glTF's loader feeds it, w = +1): dP/du of each triangle.
  auto dPdu = [&](int t) {
    const glm::vec3 d1 = p[idx[3 * t + 1]] - p[idx[3 * t]], d2 = p[idx[3 * t + 2]] - p[idx[3 * t]];
    const glm::vec2 a = uv[idx[3 * t]], b = uv[idx[3 * t + 1]], c = uv[idx[3 * t + 2]];
    const glm::vec2 t1(b.x - a.x, (1 - b.y) - (1 - a.y)), t2(c.x - a.x, (1 - c.y) - (1 - a.y));
    return glm::normalize(t2.y * d1 - t1.y * d2);
  };
  const glm::vec3 expected = glm::normalize(glm::radians(90.f) * dPdu(0) + glm::radians(45.f) * dPdu(1));
  const auto corners = gltfMikkTSpaceCornerTangents(p, n, uv, idx);
  EXPECT_LT(angleDegrees(glm::vec3(corners[0]), expected), 1e-3f);
  EXPECT_LT(angleDegrees(glm::vec3(corners[3]), expected), 1e-3f);  // the same welded vertex, one frame
  EXPECT_EQ(corners[0], corners[3]);
  EXPECT_GT(angleDegrees(dPdu(0), dPdu(1)), 10.f);  // the two triangles do disagree
  EXPECT_LT(angleDegrees(glm::vec3(corners[1]), dPdu(0)), 1e-3f);  // a corner of A alone
}

// Degenerate input never gives NaN or Inf: zero-area triangles, all-equal uvs, zero and non-finite
// normals. Corners no healthy triangle reaches get mikktspace.c's default (1, 0, 0), w = -1; corners
// of a zero-area triangle copy a healthy corner welded to them.
TEST(MikkTSpace, DegenerateTrianglesAndUvsGiveFiniteDefaultFrames) {
  const std::vector<glm::vec3> p = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 0, 0}, {2, 0, 0}, {0, 0, 1}};
  const std::vector<glm::vec3> n = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 0}, {NAN, 0, 0}};
  const std::vector<glm::vec2> uv = {{0, 1}, {1, 1}, {0, 0}, {1, 1}, {0.5f, 0.5f}, {0.5f, 0.5f}};
  // A healthy triangle; a zero-area one (vertices 1 and 3 coincide and weld); one with no uv area and no
  // healthy neighbour (a zero and a NaN normal); one with a repeated index.
  const std::vector<std::uint32_t> idx = {0, 1, 2, 1, 3, 4, 4, 5, 2, 0, 0, 2};
  const auto corners = gltfMikkTSpaceCornerTangents(p, n, uv, idx);
  ASSERT_EQ(corners.size(), idx.size());
  for (const auto& t : corners) {
    ASSERT_TRUE(finite(t));
    EXPECT_NEAR(glm::length(glm::vec3(t)), 1.f, 1e-5f);
    EXPECT_TRUE(t.w == 1.f || t.w == -1.f);
  }
  EXPECT_EQ(corners[3], corners[1]);  // the zero-area triangle's corner at vertex 1 copies the healthy one
  for (int c = 6; c < 9; ++c) EXPECT_EQ(corners[std::size_t(c)], glm::vec4(1, 0, 0, -1));  // no group reaches it: the default
  // Nothing at all: an empty mesh, mismatched attribute counts, out-of-range indices.
  EXPECT_TRUE(gltfMikkTSpaceCornerTangents({}, {}, {}, {}).empty());
  EXPECT_EQ(gltfMikkTSpaceCornerTangents(p, n, {}, idx).size(), idx.size());
  EXPECT_EQ(gltfMikkTSpaceCornerTangents(p, n, uv, {0, 1, 99}).front(), glm::vec4(1, 0, 0, -1));
}

// The loader: a normal-mapped primitive without TANGENT gets tangents perpendicular to its normals,
// finite, whatever its uvs (all equal here) and with a zero-area triangle in it.
TEST(MikkTSpace, LoaderGivesDegenerateNormalMappedMeshesAFiniteFallbackFrame) {
  const std::string png = test::encodePng(1, 1, {128, 128, 255, 255});
  GltfBuilder b;
  b.push("images", {{"uri", "data:image/png;base64," + test::base64(png)}});
  b.push("textures", {{"source", 0}});
  const int mat = b.material({{"normalTexture", {{"index", 0}}}});
  // Normals along +x: mikktspace.c's default tangent (1, 0, 0) is parallel to them.
  const std::vector<glm::vec3> p = {{0, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0, 1, 0}};
  const int m = b.mesh(json::array({trianglePrimitive<std::uint8_t>(
      b, p, {0, 1, 2, 1, 3, 2}, {{1, 0, 0}, {1, 0, 0}, {1, 0, 0}, {1, 0, 0}}, {{0.5, 0.5}, {0.5, 0.5}, {0.5, 0.5}, {0.5, 0.5}}, mat)}));
  b.scene({b.node({{"mesh", m}})});
  const Scene s = loadSceneFromMemory(b.gltf());
  const MeshInstance& mi = s.meshes[0];
  ASSERT_EQ(mi.tangents.size(), mi.positions.size());
  for (std::size_t v = 0; v < mi.tangents.size(); ++v) {
    ASSERT_TRUE(finite(mi.tangents[v]));
    EXPECT_NEAR(glm::length(glm::vec3(mi.tangents[v])), 1.f, 1e-5f);
    EXPECT_NEAR(glm::dot(glm::vec3(mi.tangents[v]), mi.normals[v]), 0.f, 1e-5f);
  }
}

}  // namespace
}  // namespace radiant
