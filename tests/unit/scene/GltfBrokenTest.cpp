// Broken and hostile glTF files: each must fail with a SceneError whose message says what is wrong
// and whose JSON pointer names the offending field.
#include <gtest/gtest.h>

#include <filesystem>

#include "renderer/scene/GltfLoader.h"
#include "tests/unit/scene/GltfTestBuilder.h"

namespace radiant {
namespace {

using test::GltfBuilder;
using test::json;
using test::trianglePrimitive;

using test::triangle;
const std::vector<glm::vec3>& kTri = test::kTriangle;

// Runs `load`, expecting a SceneError with `pointer` and a message containing `text`.
template <class F>
void expectSceneError(F load, const std::string& pointer, const std::string& text) {
  try {
    load();
    ADD_FAILURE() << "no SceneError; expected pointer '" << pointer << "' and '" << text << "'";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.pointer, pointer) << "message: " << e.what();
    EXPECT_NE(std::string(e.what()).find(text), std::string::npos)
        << "message '" << e.what() << "' lacks '" << text << "'";
  }
}

TEST(GltfBroken, TruncatedGlb) {
  const std::string glb = triangle().glb();
  expectSceneError([&] { loadSceneFromMemory(std::string_view(glb).substr(0, glb.size() / 2)); }, "",
                   "truncated GLB: the header declares");
  expectSceneError([&] { loadSceneFromMemory(std::string_view(glb).substr(0, 10)); }, "", "truncated GLB");
  // The header's length is right but the JSON chunk claims more than there is.
  std::string bad = glb;
  bad[12] = char(0xF0);
  bad[13] = char(0xFF);
  expectSceneError([&] { loadSceneFromMemory(bad); }, "", "truncated GLB: the JSON chunk");
}

TEST(GltfBroken, AccessorOutOfBounds) {
  GltfBuilder b = triangle();
  b.doc["accessors"][0]["count"] = 4;  // POSITION: 4 * 12 bytes from a 36-byte view
  expectSceneError([&] { loadSceneFromMemory(b.gltf()); }, "/accessors/0",
                   "reads bytes [0, 48) of bufferView 0, which has 36 bytes");
  GltfBuilder c = triangle();
  c.doc["accessors"][0]["byteOffset"] = 4;
  expectSceneError([&] { loadSceneFromMemory(c.gltf()); }, "/accessors/0", "reads bytes [4, 40)");
}

TEST(GltfBroken, BufferViewOutsideBuffer) {
  GltfBuilder b = triangle();
  b.doc["bufferViews"][1]["byteLength"] = 1000;
  expectSceneError([&] { loadSceneFromMemory(b.gltf()); }, "/bufferViews/1", "but buffer 0 has");
}

TEST(GltfBroken, IndexOutOfRange) {
  GltfBuilder b;
  const int m = b.mesh(json::array({trianglePrimitive<std::uint8_t>(b, kTri, {0, 1, 3})}));
  b.scene({b.node({{"mesh", m}})});
  expectSceneError([&] { loadSceneFromMemory(b.gltf()); }, "/meshes/0/primitives/0/indices",
                   "index 3 at position 2 (accessor 1) is out of range: the primitive has 3 vertices");
}

TEST(GltfBroken, UnsupportedRequiredExtension) {
  GltfBuilder b = triangle();
  b.doc["extensionsUsed"] = {"KHR_lights_punctual", "KHR_texture_basisu"};
  b.doc["extensionsRequired"] = {"KHR_lights_punctual", "KHR_texture_basisu"};
  try {
    loadSceneFromMemory(b.gltf());
    ADD_FAILURE() << "no SceneError";
  } catch (const SceneError& e) {
    // Names the extension and says how to convert the file.
    const std::string what = e.what();
    EXPECT_EQ(what.rfind("unsupported required extension KHR_texture_basisu: ", 0), 0u) << what;
    EXPECT_NE(what.find("re-encode them as PNG or JPEG"), std::string::npos) << what;
    EXPECT_EQ(e.pointer, "/extensionsRequired/1");
  }
}

TEST(GltfBroken, PointsAndLinesAreRefused) {
  GltfBuilder b;
  json prim = trianglePrimitive<std::uint8_t>(b, kTri, {0, 1});
  prim["mode"] = 1;
  b.scene({b.node({{"mesh", b.mesh(json::array({prim}))}})});
  expectSceneError([&] { loadSceneFromMemory(b.gltf()); }, "/meshes/0/primitives/0/mode",
                   "mesh 0 primitive 0 has mode LINES");
}

TEST(GltfBroken, NotGltfAtAll) {
  expectSceneError([&] { loadSceneFromMemory("this is not json"); }, "", "neither valid JSON nor GLB");
  expectSceneError([&] { loadSceneFromMemory("[1, 2]"); }, "", "must be a JSON object");
}

TEST(GltfBroken, SizeLimit) {
  LoadOptions options;
  options.maxBytes = 100;
  expectSceneError([&] { loadSceneFromMemory(triangle().gltf(), options); }, "", "over the limit of 100");
}

TEST(GltfBroken, CycleInNodeHierarchy) {
  GltfBuilder b = triangle();
  b.doc["nodes"][0]["children"] = {1};
  b.doc["nodes"].push_back({{"children", {0}}});
  expectSceneError([&] { loadSceneFromMemory(b.gltf()); }, "/nodes/0", "appears twice");
}

TEST(GltfBroken, ImageBombIsRefusedBeforeDecoding) {
  std::string png = test::encodePng(1, 1, {0, 0, 0, 255});
  // IHDR width and height (bytes 16..23) claim 60000 x 60000: 28.8 GB at 16 bits per channel.
  for (int k : {16, 20}) { png[k] = 0; png[k + 1] = 0; png[k + 2] = char(0xEA); png[k + 3] = char(0x60); }
  GltfBuilder b = triangle();
  b.push("images", {{"uri", "data:image/png;base64," + test::base64(png)}});
  expectSceneError([&] { loadSceneFromMemory(b.gltf()); }, "/images/0", "a 60000x60000 PNG decodes to more than 2^30 bytes");
}

TEST(GltfBroken, MismatchedAttributeCounts) {
  GltfBuilder b;
  json prim = trianglePrimitive<std::uint8_t>(b, kTri, {0, 1, 2});
  prim["attributes"]["NORMAL"] = b.vec3({{0, 0, 1}, {0, 0, 1}});
  b.scene({b.node({{"mesh", b.mesh(json::array({prim}))}})});
  expectSceneError([&] { loadSceneFromMemory(b.gltf()); }, "/accessors/2/count",
                   "NORMAL has 2 elements but POSITION has 3");
}

TEST(GltfBroken, WrongAccessorType) {
  GltfBuilder b = triangle();
  b.doc["accessors"][0]["type"] = "VEC2";
  expectSceneError([&] { loadSceneFromMemory(b.gltf()); }, "/accessors/0/type", "has type VEC2, expected VEC3");
}

// ---- external URIs ----------------------------------------------------------------------------

struct RootFixture : ::testing::Test {
  test::TempDir dir{"root"};
  std::filesystem::path root() const { return dir.path / "root"; }
  std::filesystem::path outside() const { return dir.path / "outside"; }
  void SetUp() override {
    test::writeFile(outside() / "secret.bin", triangle().bin);
    test::writeFile(root() / "ok.bin", triangle().bin);
  }
  LoadOptions options() const {
    LoadOptions o;
    o.assetRoot = root();
    return o;
  }
};

TEST_F(RootFixture, RelativeUriInsideRootLoads) {
  const Scene s = loadSceneFromMemory(triangle().gltfExternal("ok.bin"), options());
  EXPECT_EQ(s.meshes.size(), 1u);
}

TEST_F(RootFixture, DotDotUriIsRefused) {
  expectSceneError([&] { loadSceneFromMemory(triangle().gltfExternal("../outside/secret.bin"), options()); },
                   "/buffers/0/uri", "\"..\" is not allowed");
  // Percent-encoded dots are decoded before the check.
  expectSceneError([&] { loadSceneFromMemory(triangle().gltfExternal("%2E%2E/outside/secret.bin"), options()); },
                   "/buffers/0/uri", "\"..\" is not allowed");
  // Also for images.
  GltfBuilder b = triangle();
  b.push("images", {{"uri", "sub/../../outside/x.png"}});
  expectSceneError([&] { loadSceneFromMemory(b.gltf(), options()); }, "/images/0/uri", "\"..\" is not allowed");
}

TEST_F(RootFixture, AbsoluteUriIsRefused) {
  const std::string abs = (outside() / "secret.bin").string();
  expectSceneError([&] { loadSceneFromMemory(triangle().gltfExternal(abs), options()); }, "/buffers/0/uri",
                   "absolute paths are not allowed");
  expectSceneError([&] { loadSceneFromMemory(triangle().gltfExternal("file://" + abs), options()); },
                   "/buffers/0/uri", "only data: URIs and relative file paths");
}

TEST_F(RootFixture, SymlinkEscapingTheRootIsRefused) {
  std::filesystem::create_symlink(outside() / "secret.bin", root() / "link.bin");
  std::filesystem::create_directory_symlink(outside(), root() / "linkdir");
  expectSceneError([&] { loadSceneFromMemory(triangle().gltfExternal("link.bin"), options()); }, "/buffers/0/uri",
                   "outside the asset root");
  expectSceneError([&] { loadSceneFromMemory(triangle().gltfExternal("linkdir/secret.bin"), options()); },
                   "/buffers/0/uri", "outside the asset root");
  // A symlink that stays inside the root is fine.
  std::filesystem::create_symlink(root() / "ok.bin", root() / "alias.bin");
  EXPECT_EQ(loadSceneFromMemory(triangle().gltfExternal("alias.bin"), options()).meshes.size(), 1u);
}

TEST_F(RootFixture, NoAssetRootRefusesExternalUris) {
  expectSceneError([&] { loadSceneFromMemory(triangle().gltfExternal("ok.bin"), LoadOptions{}); }, "/buffers/0/uri",
                   "no asset root is configured");
}

TEST_F(RootFixture, SceneFileOutsideTheRootIsRefused) {
  test::writeFile(outside() / "scene.gltf", triangle().gltf());
  expectSceneError([&] { loadScene(outside() / "scene.gltf", options()); }, "", "is outside the asset root");
  // ... also when reached through a symlink inside the root.
  std::filesystem::create_symlink(outside() / "scene.gltf", root() / "scene.gltf");
  expectSceneError([&] { loadScene(root() / "scene.gltf", options()); }, "", "is outside the asset root");
}

TEST_F(RootFixture, MissingExternalImageIsAnError) {
  GltfBuilder b = triangle();
  b.push("images", {{"uri", "missing.png"}});
  b.push("textures", {{"source", 0}});
  b.doc["materials"] = {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}};
  b.doc["meshes"][0]["primitives"][0]["material"] = 0;
  expectSceneError([&] { loadSceneFromMemory(b.gltf(), options()); }, "/images/0", "could not be loaded");
}

}  // namespace
}  // namespace radiant
