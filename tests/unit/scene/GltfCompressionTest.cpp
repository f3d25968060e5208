// Compressed meshes decoded at load: a mesh encoded here with the real encoders (Draco, meshoptimizer)
// loads with exactly the positions, normals and triangles it was encoded from.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <random>

#include <tuple>

#include <gtest/gtest.h>

#include <draco/compression/encode.h>
#include <draco/mesh/triangle_soup_mesh_builder.h>
#include <meshoptimizer.h>
#include <tiny_gltf.h>  // shared library: no TINYGLTF_IMPLEMENTATION

#include "renderer/scene/GltfCompression.h"
#include "renderer/scene/GltfLimits.h"
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

// The cube as a KHR_draco_mesh_compression primitive: POSITION (float x3) and a NORMAL attribute of
// `normalType` with `normalComponents` per corner, `normal(face, corner)` its value; the GLB with
// POSITION and NORMAL accessors (float VEC3) and, when `indexed`, the cube's index accessor, as a builder.
GltfBuilder encodeDracoCube(const Cube& cube, draco::DataType normalType, int normalComponents,
                          const std::function<const void*(std::size_t face, int corner)>& normal, bool indexed,
                          int method = -1, bool metadata = false) {
  draco::TriangleSoupMeshBuilder builder;
  builder.Start(int(cube.idx.size() / 3));
  const int pos = builder.AddAttribute(draco::GeometryAttribute::POSITION, 3, draco::DT_FLOAT32);
  const int nrm = builder.AddAttribute(draco::GeometryAttribute::NORMAL, std::int8_t(normalComponents), normalType);
  for (std::size_t f = 0; f < cube.idx.size() / 3; ++f) {
    const auto* i = &cube.idx[f * 3];
    builder.SetAttributeValuesForFace(pos, draco::FaceIndex(std::uint32_t(f)), &cube.p[i[0]], &cube.p[i[1]], &cube.p[i[2]]);
    builder.SetAttributeValuesForFace(nrm, draco::FaceIndex(std::uint32_t(f)), normal(f, 0), normal(f, 1), normal(f, 2));
  }
  if (metadata) {  // a geometry entry with a sub-metadata, and an attribute's entry
    auto geometry = std::make_unique<draco::GeometryMetadata>();
    geometry->AddEntryString("author", "radiant tests");
    auto sub = std::make_unique<draco::Metadata>();
    sub->AddEntryInt("level", 3);
    geometry->AddSubMetadata("nested", std::move(sub));
    builder.AddMetadata(std::move(geometry));
    auto attribute = std::make_unique<draco::AttributeMetadata>();
    attribute->AddEntryString("space", "object");
    builder.AddAttributeMetadata(pos, std::move(attribute));
  }
  std::unique_ptr<draco::Mesh> mesh = builder.Finalize();
  EXPECT_TRUE(mesh);
  draco::Encoder encoder;  // no quantization set: floats are stored losslessly
  if (method >= 0) encoder.SetEncodingMethod(method);
  draco::EncoderBuffer encoded;
  EXPECT_TRUE(encoder.EncodeMeshToBuffer(*mesh, &encoded).ok());
  GltfBuilder b;
  const int view = b.view(encoded.data(), encoded.size());
  const int posAcc = b.push("accessors", {{"componentType", 5126}, {"count", mesh->num_points()}, {"type", "VEC3"},
                                          {"min", {-0.5, -0.5, -0.5}}, {"max", {0.5, 0.5, 0.5}}});
  const int nrmAcc = b.push("accessors", {{"componentType", 5126}, {"count", mesh->num_points()}, {"type", "VEC3"}});
  const json draco = {{"bufferView", view},
                      {"attributes", {{"POSITION", mesh->GetNamedAttribute(draco::GeometryAttribute::POSITION)->unique_id()},
                                      {"NORMAL", mesh->GetNamedAttribute(draco::GeometryAttribute::NORMAL)->unique_id()}}}};
  json primitive = {{"attributes", {{"POSITION", posAcc}, {"NORMAL", nrmAcc}}},
                    {"extensions", {{"KHR_draco_mesh_compression", draco}}}};
  if (indexed)
    primitive["indices"] = b.push("accessors", {{"componentType", 5125}, {"count", cube.idx.size()}, {"type", "SCALAR"}});
  const int m = b.mesh(json::array({primitive}));
  b.scene({b.node({{"name", "cube"}, {"mesh", m}})});
  b.doc["extensionsUsed"] = {"KHR_draco_mesh_compression"};
  b.doc["extensionsRequired"] = {"KHR_draco_mesh_compression"};
  return b;
}

TEST(GltfCompression, DracoPrimitiveDecodesToTheEncodedMesh) {
  const Cube cube;
  GltfBuilder b = encodeDracoCube(cube, draco::DT_FLOAT32, 3,
                                  [&](std::size_t f, int k) { return static_cast<const void*>(&cube.n[cube.idx[f * 3 + k]]); }, true);
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

// Issue 30, validate before decoding: libdraco sizes its corner table and attribute arrays from the
// stream's face and vertex counts alone (a 150-byte Draco 1.1 stream found by tests/fuzz/draco_fuzzer.cpp
// made it allocate 5.4 GB). decodeDraco() reads the header first: any version but 2.2, the one
// KHR_draco_mesh_compression specifies, is refused, and the counts are charged against the decode budget
// (44 bytes per face, 8 + 16 per attribute per vertex for edgebreaker) before libdraco allocates.
GltfBuilder dracoStream(const std::string& bytes) {
  GltfBuilder b;
  const int view = b.view(bytes.data(), bytes.size());
  const int posAcc = b.push("accessors", {{"componentType", 5126}, {"count", 3}, {"type", "VEC3"},
                                          {"min", {0, 0, 0}}, {"max", {1, 1, 1}}});
  const json draco = {{"bufferView", view}, {"attributes", {{"POSITION", 0}}}};
  const int m = b.mesh(json::array({{{"attributes", {{"POSITION", posAcc}}},
                                     {"extensions", {{"KHR_draco_mesh_compression", draco}}}}}));
  b.scene({b.node({{"mesh", m}})});
  b.doc["extensionsUsed"] = {"KHR_draco_mesh_compression"};
  b.doc["extensionsRequired"] = {"KHR_draco_mesh_compression"};
  return b;
}

std::string varint(std::uint32_t v) {
  std::string out;
  do {
    out.push_back(char((v & 127u) | (v > 127 ? 128u : 0u)));
    v >>= 7;
  } while (v);
  return out;
}

// limit: a SceneLimitError naming --max-decode-bytes (422 limit-exceeded), else 422 invalid-scene.
void expectRefused(const std::string& file, const std::string& says, bool limit = false) {
  try {
    loadSceneFromMemory(file);
    ADD_FAILURE() << "accepted; expected: " << says;
  } catch (const SceneError& e) {
    const auto* l = dynamic_cast<const SceneLimitError*>(&e);
    EXPECT_EQ(l != nullptr, limit) << e.what();
    if (l) {
      EXPECT_EQ(l->flag, "--max-decode-bytes");
    }
    EXPECT_EQ(e.pointer, "/meshes/0/primitives/0/extensions/KHR_draco_mesh_compression");
    EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
  }
}

TEST(GltfCompression, DracoStreamsOtherThanBitstream22AreRefusedBeforeDecoding) {
  std::ifstream in(RADIANT_SOURCE_DIR "/tests/data/crashers/draco/corner_table_5gb_bitstream_1_1.drc", std::ios::binary);
  const std::string crasher((std::istreambuf_iterator<char>(in)), {});
  ASSERT_EQ(crasher.size(), 150u);
  expectRefused(dracoStream(crasher).glb(), "Draco bitstream version 1.1 is not 2.2");
  std::string pointCloud = std::string("DRACO\x02\x02\x00\x00\x00\x00", 11) + varint(3) + std::string(16, '\0');
  expectRefused(dracoStream(pointCloud).glb(), "point cloud");
  expectRefused(dracoStream("DRACO\x02\x02\x01").glb(), "ends inside its header");
  expectRefused(dracoStream("NOTDRACO").glb(), "does not hold a Draco stream");
}

TEST(GltfCompression, DracoCountsAreChargedAgainstTheDecodeBudgetBeforeDecoding) {
  // Edgebreaker, standard traversal: 100 million faces over 60 million vertices (libdraco's own checks
  // pass: faces <= symbols * 4/3, vertices <= 3 * faces) in a 40-byte stream.
  const std::uint32_t faces = 100'000'000, vertices = 60'000'000;
  const std::string header = std::string("DRACO\x02\x02\x01\x01\x00\x00\x00", 12) + varint(vertices) +
                             varint(faces) + std::string(1, '\x01') + varint(faces) + varint(0) + std::string(16, '\0');
  const std::size_t need = std::size_t(faces) * 44 + std::size_t(vertices) * (8 + 16);
  expectRefused(dracoStream(header).glb(), "need " + std::to_string(need) + " bytes", true);

  // The same counts on a real cube, charged by decodeDraco itself: its stream (12 faces, 8 to 24
  // vertices, two attributes) decodes within its charge and is refused one byte below it.
  const Cube cube;
  GltfBuilder b = encodeDracoCube(cube, draco::DT_FLOAT32, 3,
                                  [&](std::size_t f, int k) { return static_cast<const void*>(&cube.n[cube.idx[f * 3 + k]]); },
                                  false, draco::MESH_EDGEBREAKER_ENCODING);
  auto model = [&] {
    tinygltf::Model m;
    tinygltf::TinyGLTF loader;
    std::string err, warn;
    const std::string glb = b.glb();
    EXPECT_TRUE(loader.LoadBinaryFromMemory(&m, &err, &warn, reinterpret_cast<const unsigned char*>(glb.data()),
                                            unsigned(glb.size())))
        << err;
    return m;
  };
  std::size_t charge = 0;
  try {
    tinygltf::Model m = model();
    gltf::decodeDraco(m, 1);
    ADD_FAILURE() << "decoded within 1 byte";
  } catch (const SceneLimitError& e) {
    const std::string what = e.what();
    const auto at = what.find("need ");
    ASSERT_NE(at, std::string::npos) << what;
    charge = std::stoull(what.substr(at + 5));
  }
  EXPECT_GE(charge, 12u * 44 + 8u * (8 + 32));
  EXPECT_LE(charge, 12u * 44 + 24u * (8 + 32));
  tinygltf::Model m = model();
  EXPECT_THROW(gltf::decodeDraco(m, charge - 1), SceneLimitError);
  m = model();
  EXPECT_NO_THROW(gltf::decodeDraco(m, 1u << 20));
}

// Metadata sits between the header and the counts; sequential streams count faces and points. Both
// decode to the cube (the header reader must not refuse what libdraco decodes).
TEST(GltfCompression, DracoStreamsWithMetadataDecodeByEitherMethod) {
  const Cube cube;
  for (int method : {draco::MESH_SEQUENTIAL_ENCODING, draco::MESH_EDGEBREAKER_ENCODING}) {
    SCOPED_TRACE(method);
    GltfBuilder b = encodeDracoCube(cube, draco::DT_FLOAT32, 3,
                                    [&](std::size_t f, int k) { return static_cast<const void*>(&cube.n[cube.idx[f * 3 + k]]); },
                                    true, method, true);
    const Scene s = loadSceneFromMemory(b.glb());
    ASSERT_EQ(s.meshes.size(), 1u);
    EXPECT_EQ(triangles(s.meshes[0].positions, s.meshes[0].indices), triangles(cube.p, cube.idx));
  }
}

// Issue 30, validate before decoding: a Draco attribute is checked against its accessor before any value
// is read: its data type must be a glTF component type (a DT_BOOL attribute holding other bytes than 0
// and 1 was undefined behaviour inside Draco's conversion, tests/fuzz/draco_fuzzer.cpp) and its
// component count the accessor's. Both are 422 invalid-scene at the attribute's pointer.
TEST(GltfCompression, DracoAttributesOfAnotherTypeOrComponentCountAreRefused) {
  const Cube cube;
  auto file = [&](draco::DataType normalType, int normalComponents) {
    const std::int32_t ints[3] = {1, 2, 3};
    const float floats[3] = {0.f, 0.f, 1.f};
    const void* n = normalType == draco::DT_INT32 ? static_cast<const void*>(ints) : static_cast<const void*>(floats);
    return encodeDracoCube(cube, normalType, normalComponents, [&](std::size_t, int) { return n; }, false).glb();
  };
  const std::string pointer = "/meshes/0/primitives/0/extensions/KHR_draco_mesh_compression/attributes/NORMAL";
  EXPECT_NO_THROW(loadSceneFromMemory(file(draco::DT_FLOAT32, 3)));
  for (const auto& [type, comps, says] : {std::tuple{draco::DT_INT32, 3, "not a glTF component type"},
                                          std::tuple{draco::DT_FLOAT32, 2, "has 2 components, its accessor 3"}}) {
    try {
      loadSceneFromMemory(file(type, comps));
      ADD_FAILURE() << "accepted " << says;
    } catch (const SceneError& e) {
      EXPECT_EQ(e.pointer, pointer);
      EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
    }
  }
}

std::string encodeVertices(const void* data, std::size_t count, std::size_t stride) {
  std::string out(meshopt_encodeVertexBufferBound(count, stride), '\0');
  out.resize(meshopt_encodeVertexBuffer(reinterpret_cast<unsigned char*>(out.data()), out.size(), data, count, stride));
  return out;
}
std::string encodeIndexSequence(const std::vector<std::uint32_t>& idx, std::size_t vertexCount) {
  std::string out(meshopt_encodeIndexSequenceBound(idx.size(), vertexCount), '\0');
  out.resize(meshopt_encodeIndexSequence(reinterpret_cast<unsigned char*>(out.data()), out.size(), idx.data(), idx.size()));
  return out;
}
std::string encodeTriangles(const std::vector<std::uint32_t>& idx, std::size_t vertexCount) {
  std::string out(meshopt_encodeIndexBufferBound(idx.size(), vertexCount), '\0');
  out.resize(meshopt_encodeIndexBuffer(reinterpret_cast<unsigned char*>(out.data()), out.size(), idx.data(), idx.size()));
  return out;
}

// The cube's positions (ATTRIBUTES, stride 12) and indices (TRIANGLES, stride 4) as meshopt streams.
struct MeshoptCube {
  Cube cube;
  GltfBuilder b;
  int positions = -1, indices = -1;
  MeshoptCube() {
    positions = b.meshoptView(encodeVertices(cube.p.data(), cube.p.size(), 12), cube.p.size(), 12, {{"mode", "ATTRIBUTES"}}, true);
    indices = b.meshoptView(encodeTriangles(cube.idx, cube.p.size()), cube.idx.size(), 4, {{"mode", "TRIANGLES"}});
    const int posAcc = b.push("accessors", {{"bufferView", positions}, {"componentType", 5126}, {"count", cube.p.size()},
                                            {"type", "VEC3"}, {"min", {-0.5, -0.5, -0.5}}, {"max", {0.5, 0.5, 0.5}}});
    const int idxAcc = b.push("accessors", {{"bufferView", indices}, {"componentType", 5125}, {"count", cube.idx.size()}, {"type", "SCALAR"}});
    const int m = b.mesh(json::array({{{"attributes", {{"POSITION", posAcc}}}, {"indices", idxAcc}}}));
    b.scene({b.node({{"name", "cube"}, {"mesh", m}})});
  }
};

TEST(GltfCompression, MeshoptBufferViewsDecodeToTheEncodedBytes) {
  MeshoptCube c;
  // GLB: buffer 0 is the BIN chunk with the compressed streams, buffer 1 the uri-less fallback.
  const std::string glb = c.b.glb();
  const Scene s = loadSceneFromMemory(glb);
  ASSERT_EQ(s.meshes.size(), 1u);
  EXPECT_EQ(s.meshes[0].positions, c.cube.p);  // meshopt is lossless: bit-exact
  EXPECT_EQ(s.meshes[0].indices, c.cube.idx);
  EXPECT_FALSE(s.digest.empty());

  // A corrupt stream is a SceneError naming the bufferView's extension.
  std::string broken = glb;
  const std::size_t binStart = broken.size() - ((c.b.bin.size() + 3) & ~std::size_t(3));
  const json& stream = c.b.doc["bufferViews"][c.positions]["extensions"]["EXT_meshopt_compression"];
  for (std::size_t i = 0; i < stream["byteLength"].get<std::size_t>(); ++i)
    broken[binStart + stream["byteOffset"].get<std::size_t>() + i] = char(0xA5);
  try {
    loadSceneFromMemory(broken);
    ADD_FAILURE() << "a corrupt meshopt stream loaded";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.pointer, "/bufferViews/" + std::to_string(c.positions) + "/extensions/EXT_meshopt_compression");
  }
}

// The bytes of bufferView `view` of a GLB whose data all lie in its BIN chunk.
std::string glbViewBytes(const std::string& glb, int view) {
  auto le32 = [&](std::size_t at) {
    std::uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v |= std::uint32_t(std::uint8_t(glb[at + i])) << (8 * i);
    return std::size_t(v);
  };
  const std::size_t jsonLength = le32(12);
  const json doc = json::parse(glb.substr(20, jsonLength));
  const json& v = doc["bufferViews"][std::size_t(view)];
  EXPECT_EQ(v.value("buffer", -1), 0);
  return glb.substr(20 + jsonLength + 8 + v["byteOffset"].get<std::size_t>(), v["byteLength"].get<std::size_t>());
}

// Filters whose stride fits decode as the spec's Appendix B says: values encoded with meshoptimizer's
// own filter encoders come back (octahedral normals and quaternions to their quantisation, exponential
// values exactly), and each view's count x byteStride is charged against the budget.
TEST(GltfCompression, MeshoptFiltersWithAFittingStrideDecode) {
  const std::vector<float> normals = {0.f, 0.f, 1.f, 0.f, 1.f, 0.f, 0.f, 0.f};  // +z and +x, (x, y, z, w) each
  std::vector<std::int8_t> oct(8);
  meshopt_encodeFilterOct(oct.data(), 2, 4, 8, normals.data());
  const std::vector<float> quats = {0.f, 0.f, 0.f, 1.f, 0.f, 0.70710678f, 0.f, 0.70710678f};
  std::vector<std::int16_t> quat(8);
  meshopt_encodeFilterQuat(quat.data(), 2, 8, 16, quats.data());
  const std::vector<float> values = {1.5f, -256.f, 0.f, 3.f};
  std::vector<std::uint32_t> exp(4);
  meshopt_encodeFilterExp(exp.data(), 4, 4, 24, values.data());
  GltfBuilder b;
  const int octView = b.meshoptView(encodeVertices(oct.data(), 2, 4), 2, 4, {{"mode", "ATTRIBUTES"}, {"filter", "OCTAHEDRAL"}});
  const int quatView = b.meshoptView(encodeVertices(quat.data(), 2, 8), 2, 8, {{"mode", "ATTRIBUTES"}, {"filter", "QUATERNION"}}, true);
  const int expView = b.meshoptView(encodeVertices(exp.data(), 4, 4), 4, 4, {{"mode", "ATTRIBUTES"}, {"filter", "EXPONENTIAL"}});
  DecodeBudget budget(1 << 20);
  const std::string decoded = gltf::decodeMeshopt(b.glb(), budget);
  EXPECT_EQ(budget.remaining(), (1u << 20) - 2 * 4 - 2 * 8 - 4 * 4);
  EXPECT_EQ(decoded.find("EXT_meshopt_compression"), std::string::npos);

  const std::string o = glbViewBytes(decoded, octView);
  ASSERT_EQ(o.size(), 8u);
  const std::vector<int> octExpected = {0, 0, 127, 0, 127, 0, 0, 0};  // snorm8 (x, y, z), w kept
  for (int i = 0; i < 8; ++i) EXPECT_EQ(int(std::int8_t(o[std::size_t(i)])), octExpected[std::size_t(i)]) << i;
  const std::string q = glbViewBytes(decoded, quatView);
  ASSERT_EQ(q.size(), 16u);
  for (int i = 0; i < 8; ++i) {
    std::int16_t v;
    std::memcpy(&v, q.data() + 2 * i, 2);
    EXPECT_NEAR(v / 32767.0, quats[std::size_t(i)], 1e-4) << i;
  }
  const std::string e = glbViewBytes(decoded, expView);
  ASSERT_EQ(e.size(), 16u);
  std::vector<float> back(4);
  std::memcpy(back.data(), e.data(), 16);
  EXPECT_EQ(back, values);
}

// Every field meshoptimizer's decoders rely on is checked before they run: Debian's meshoptimizer
// keeps its asserts, so a filter that does not fit its stride used to abort radiantd (issue 30). Each
// case runs first in a child process (a SIGABRT fails that check instead of the whole suite), then
// in-process for its JSON pointer.
struct BadMeshopt {
  const char* name;
  const char* mode;
  json filter;  // null: omitted
  std::size_t stride;
  const char* pointer;  // after "/bufferViews/1/extensions/EXT_meshopt_compression"
};

class MeshoptValidation : public ::testing::TestWithParam<BadMeshopt> {};

std::string badMeshoptGlb(const BadMeshopt& c) {
  GltfBuilder b;
  json fields = {{"mode", c.mode}};
  if (!c.filter.is_null()) fields["filter"] = c.filter;
  // A valid stream of the mode and stride where meshoptimizer can encode one, so that a filter the old
  // loader applied before checking the stride did run (and abort).
  const std::string mode = c.mode;
  const std::size_t count = 3;
  std::string stream(32, '\x55');
  if ((mode == "TRIANGLES" || mode == "INDICES") && (c.stride == 2 || c.stride == 4)) {
    stream = mode == "TRIANGLES" ? encodeTriangles({0, 1, 2}, 3) : encodeIndexSequence({0, 1, 2}, 3);
  } else if (c.stride % 4 == 0 && c.stride <= 256) {
    const std::vector<unsigned char> zeros(count * c.stride, 0);
    stream = encodeVertices(zeros.data(), count, c.stride);
  }
  b.meshoptView(stream, count, c.stride, fields);
  return b.glb();
}

TEST_P(MeshoptValidation, IsASceneErrorAtItsPointerBeforeAnyDecode) {
  const BadMeshopt& c = GetParam();
  const std::string glb = badMeshoptGlb(c);
  EXPECT_EXIT(
      {
        try {
          loadSceneFromMemory(glb);
        } catch (const SceneError&) {
          std::_Exit(0);
        }
        std::_Exit(1);
      },
      ::testing::ExitedWithCode(0), "");
  if (HasFailure()) return;
  try {
    loadSceneFromMemory(glb);
    ADD_FAILURE() << "loaded";
  } catch (const SceneLimitError& e) {
    ADD_FAILURE() << "a limit error: " << e.what();
  } catch (const SceneError& e) {
    EXPECT_EQ(e.pointer, std::string("/bufferViews/1/extensions/EXT_meshopt_compression") + c.pointer) << e.what();
  }
}

// The five that aborted radiantd in issue 30's hostile round, then the mode and filter of the wrong
// type (which gave a raw JSON-library message and no pointer), then the spec's other rules.
INSTANTIATE_TEST_SUITE_P(
    GltfCompression, MeshoptValidation,
    ::testing::Values(BadMeshopt{"QuaternionStride4", "ATTRIBUTES", "QUATERNION", 4, "/byteStride"},
                      BadMeshopt{"OctahedralStride12", "ATTRIBUTES", "OCTAHEDRAL", 12, "/byteStride"},
                      BadMeshopt{"OctahedralStride16", "ATTRIBUTES", "OCTAHEDRAL", 16, "/byteStride"},
                      BadMeshopt{"ExponentialOnTriangles", "TRIANGLES", "EXPONENTIAL", 2, "/filter"},
                      BadMeshopt{"OctahedralOnTriangles", "TRIANGLES", "OCTAHEDRAL", 2, "/filter"},
                      BadMeshopt{"QuaternionOnIndices", "INDICES", "QUATERNION", 4, "/filter"},
                      BadMeshopt{"FilterAnArray", "ATTRIBUTES", json::array(), 4, "/filter"},
                      BadMeshopt{"FilterANumber", "ATTRIBUTES", 1, 8, "/filter"},
                      BadMeshopt{"FilterUnknown", "ATTRIBUTES", "SPHERICAL", 8, "/filter"},
                      BadMeshopt{"ModeUnknown", "VERTICES", nullptr, 4, "/mode"},
                      BadMeshopt{"AttributesStride6", "ATTRIBUTES", nullptr, 6, "/byteStride"},
                      BadMeshopt{"AttributesStride260", "ATTRIBUTES", nullptr, 260, "/byteStride"},
                      BadMeshopt{"TrianglesStride8", "TRIANGLES", nullptr, 8, "/byteStride"},
                      BadMeshopt{"IndicesStride1", "INDICES", nullptr, 1, "/byteStride"}),
    [](const auto& info) { return std::string(info.param.name); });

// The meshopt path fuzzed directly (issue 30: it was fuzzed only through the HTTP hostile-input round,
// whose uploads rarely reach a decoder with a fitting stream): 300 bufferViews, half of random mode,
// filter, byteStride and count, half well-formed (ATTRIBUTES of finite positions at stride 12,
// TRIANGLES or INDICES at stride 2 or 4), each with the stream meshoptimizer encodes for them, or
// random bytes, and up to 8 random bytes flipped (none in half the cases), read through a POSITION
// accessor (ATTRIBUTES) or as indices. Each loads in a child process (Debian's meshoptimizer keeps its
// asserts: a SIGABRT fails the case, not the suite) and must load or be a SceneError, never another
// exception or a crash.
TEST(GltfCompression, MeshoptFuzzedViewsLoadOrAreSceneErrors) {
  std::mt19937 rng(20261205);
  auto pick = [&rng](std::size_t n) { return std::size_t(rng() % n); };
  const char* modes[] = {"ATTRIBUTES", "TRIANGLES", "INDICES", "VERTICES"};
  const json filters[] = {nullptr, "NONE", "OCTAHEDRAL", "QUATERNION", "EXPONENTIAL", "SPHERICAL", 3};
  const std::size_t strides[] = {1, 2, 3, 4, 6, 8, 12, 16, 20, 64, 252, 256, 260};
  const std::size_t counts[] = {0, 1, 3, 7, 64, 999};
  int loaded = 0, refused = 0;
  for (int i = 0; i < 300; ++i) {
    const bool wellFormed = pick(2) == 0;
    std::string mode = modes[pick(std::size(modes))];
    json filter = filters[pick(std::size(filters))];
    std::size_t stride = strides[pick(std::size(strides))], count = counts[pick(std::size(counts))];
    if (wellFormed) {
      mode = modes[pick(3)];
      filter = pick(2) == 0 ? json(nullptr) : json("NONE");
      stride = mode == "ATTRIBUTES" ? 12 : (pick(2) == 0 ? 2 : 4);
      count = pick(2) == 0 ? 3 : 999;
    }
    std::string stream;
    if (!wellFormed && pick(4) == 0) {
      stream.resize(pick(300));
      for (char& c : stream) c = char(rng());
    } else if ((mode == "TRIANGLES" || mode == "INDICES") && count % 3 == 0 && count > 0) {
      std::vector<std::uint32_t> idx(count);
      for (auto& v : idx) v = std::uint32_t(pick(3));  // the three positions below
      stream = mode == "TRIANGLES" ? encodeTriangles(idx, count) : encodeIndexSequence(idx, count);
    } else if (stride % 4 == 0 && stride <= 256) {
      std::vector<unsigned char> data(count * stride);
      for (auto& v : data) v = static_cast<unsigned char>(rng());
      if (wellFormed)  // finite positions in [-1, 1]
        for (std::size_t k = 0; k + 4 <= data.size(); k += 4) {
          const float f = float(rng() % 2001) / 1000.f - 1.f;
          std::memcpy(data.data() + k, &f, 4);
        }
      stream = encodeVertices(data.data(), count, stride);
    } else {
      stream.assign(32, '\x55');
    }
    for (std::size_t flips = pick(2) == 0 ? 0 : 1 + pick(8); flips > 0 && !stream.empty(); --flips)
      stream[pick(stream.size())] = char(rng());
    GltfBuilder b;
    json fields = {{"mode", mode}};
    if (!filter.is_null()) fields["filter"] = filter;
    const int view = b.meshoptView(stream, count, stride, fields, pick(2) == 0);
    json primitive;
    if (mode == "ATTRIBUTES") {
      const int acc = b.push("accessors", {{"bufferView", view}, {"componentType", 5126}, {"count", count},
                                           {"type", "VEC3"}, {"min", {-1, -1, -1}}, {"max", {1, 1, 1}}});
      primitive = {{"attributes", {{"POSITION", acc}}}};
    } else {
      const std::vector<float> tri = {0, 0, 0, 1, 0, 0, 0, 1, 0};
      const int pos = b.push("accessors", {{"bufferView", b.view(tri.data(), tri.size() * 4)}, {"componentType", 5126},
                                           {"count", 3}, {"type", "VEC3"}, {"min", {0, 0, 0}}, {"max", {1, 1, 0}}});
      const int idx = b.push("accessors", {{"bufferView", view}, {"componentType", stride == 2 ? 5123 : 5125},
                                           {"count", count}, {"type", "SCALAR"}});
      primitive = {{"attributes", {{"POSITION", pos}}}, {"indices", idx}};
    }
    b.scene({b.node({{"mesh", b.mesh(json::array({primitive}))}})});
    const std::string glb = b.glb();
    const std::string what = "case " + std::to_string(i) + ": " + mode + " filter " + filter.dump() + " stride " +
                             std::to_string(stride) + " count " + std::to_string(count) + ", " +
                             std::to_string(stream.size()) + " stream bytes";
    EXPECT_EXIT(
        {
          try {
            loadSceneFromMemory(glb);
          } catch (const SceneError&) {
          } catch (...) {
            std::_Exit(2);
          }
          std::_Exit(0);
        },
        ::testing::ExitedWithCode(0), "")
        << what;
    try {
      loadSceneFromMemory(glb);
      ++loaded;
    } catch (const SceneError&) {
      ++refused;
    } catch (...) {
    }
  }
  std::printf("meshopt fuzz: %d loaded, %d refused as SceneError\n", loaded, refused);
  EXPECT_GT(loaded, 10);  // the fuzz reaches the decoders with streams they accept, not only refusals
  EXPECT_GT(refused, 10);
}

// Fields of the wrong type or that contradict the parent view, each at its own pointer.
TEST(GltfCompression, MeshoptFieldsOfTheWrongKindAreSceneErrorsAtTheirPointer) {
  const std::string ext = "/bufferViews/1/extensions/EXT_meshopt_compression";
  std::string detail;  // the last error's message, for the failure output
  auto pointerOf = [&detail](const GltfBuilder& b) -> std::string {
    try {
      loadSceneFromMemory(b.glb());
    } catch (const SceneError& e) {
      detail = e.what();
      return e.pointer;
    }
    return "(loaded)";
  };
  const std::vector<unsigned char> zeros(3 * 8, 0);
  const std::string stream = encodeVertices(zeros.data(), 3, 8);
  auto build = [&](const json& fields, bool parentStride = false) {
    GltfBuilder b;
    b.meshoptView(stream, 3, 8, fields, parentStride);
    return b;
  };
  EXPECT_EQ(pointerOf(build({{"mode", 5}})), ext + "/mode");  // "mode": 5 gave nlohmann's type_error text
  EXPECT_EQ(pointerOf(build({{"mode", nullptr}})), ext + "/mode");
  EXPECT_EQ(pointerOf(build({{"mode", "ATTRIBUTES"}, {"count", -3}})), ext + "/count");
  EXPECT_EQ(pointerOf(build({{"mode", "ATTRIBUTES"}, {"count", 1.5}})), ext + "/count");
  EXPECT_EQ(pointerOf(build({{"mode", "ATTRIBUTES"}, {"byteStride", "8"}})), ext + "/byteStride");
  EXPECT_EQ(pointerOf(build({{"mode", "ATTRIBUTES"}, {"byteStride", 0}})), ext + "/byteStride");
  EXPECT_EQ(pointerOf(build({{"mode", "ATTRIBUTES"}, {"byteLength", -1}})), ext + "/byteLength");
  EXPECT_EQ(pointerOf(build({{"mode", "TRIANGLES"}, {"byteStride", 4}, {"count", 4}})), ext + "/count");  // not a multiple of 3
  // The parent view must hold count x byteStride bytes and, when it has a stride, the same one.
  GltfBuilder longer = build({{"mode", "ATTRIBUTES"}});
  longer.doc["bufferViews"][1]["byteLength"] = 3 * 8 - 4;
  EXPECT_EQ(pointerOf(longer), "/bufferViews/1/byteLength") << detail;
  GltfBuilder strided = build({{"mode", "ATTRIBUTES"}}, true);
  strided.doc["bufferViews"][1]["byteStride"] = 12;
  EXPECT_EQ(pointerOf(strided), "/bufferViews/1/byteStride");
  // A count far beyond the parent view (2^32 x 8 bytes) is refused before anything is allocated
  // (integers above 2^32 are refused by checkGltfDocument already).
  GltfBuilder huge = build({{"mode", "ATTRIBUTES"}, {"count", std::uint64_t(1) << 32}});
  EXPECT_EQ(pointerOf(huge), "/bufferViews/1/byteLength") << detail;
  // And the valid stream under the same builder loads.
  EXPECT_EQ(pointerOf(build({{"mode", "ATTRIBUTES"}})), "(loaded)");
}

// Meshopt decoding is charged against --max-decode-bytes (it was not: 3 uploads of 4 MB decoding
// 256 MiB each took radiantd to 1.8 GB), summed over views and refused before the first decode.
TEST(GltfCompression, MeshoptDecodedSizeIsChargedAgainstTheDecodeBudgetBeforeDecoding) {
  LoadOptions options;
  options.maxDecodedBytes = std::size_t(1) << 20;
  // One view of 2 MiB decoded (count x byteStride = 8192 x 256) from 64 bytes that are no stream at
  // all: refused as over the limit, not as corrupt, so nothing was decoded.
  {
    GltfBuilder b;
    b.meshoptView(std::string(64, '\x55'), 8192, 256, {{"mode", "ATTRIBUTES"}});
    try {
      loadSceneFromMemory(b.glb(), options);
      ADD_FAILURE() << "loaded";
    } catch (const SceneLimitError& e) {
      EXPECT_EQ(e.flag, "--max-decode-bytes");
      EXPECT_EQ(e.pointer, "/bufferViews/1/extensions/EXT_meshopt_compression/count");
      EXPECT_NE(std::string(e.what()).find("2097152 bytes"), std::string::npos) << e.what();
    } catch (const SceneError& e) {
      ADD_FAILURE() << "not a limit error: " << e.pointer << ": " << e.what();
    }
  }
  // Two views of 600 KiB each fit one by one, not together: the second is refused.
  {
    GltfBuilder b;
    const std::vector<unsigned char> zeros(600 * 1024, 0);
    b.meshoptView(encodeVertices(zeros.data(), zeros.size() / 4, 4), zeros.size() / 4, 4, {{"mode", "ATTRIBUTES"}});
    b.meshoptView(std::string(64, '\x55'), zeros.size() / 4, 4, {{"mode", "ATTRIBUTES"}});
    try {
      loadSceneFromMemory(b.glb(), options);
      ADD_FAILURE() << "loaded";
    } catch (const SceneLimitError& e) {
      EXPECT_EQ(e.pointer, "/bufferViews/3/extensions/EXT_meshopt_compression/count");
      EXPECT_NE(std::string(e.what()).find("614400 bytes"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(std::to_string((1u << 20) - 614400) + " of"), std::string::npos) << e.what();
    }
  }
  // Within the budget the cube loads exactly, and exactly its views' decoded bytes were charged.
  {
    MeshoptCube c;
    const std::size_t views = 24 * 12 + 36 * 4;  // count x byteStride of positions and indices
    DecodeBudget exact(views);
    EXPECT_NO_THROW(gltf::decodeMeshopt(c.b.glb(), exact));
    EXPECT_EQ(exact.remaining(), 0u);
    DecodeBudget short_(views - 1);
    EXPECT_THROW(gltf::decodeMeshopt(c.b.glb(), short_), SceneLimitError);
    EXPECT_EQ(loadSceneFromMemory(c.b.glb(), options).meshes[0].positions, c.cube.p);
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
