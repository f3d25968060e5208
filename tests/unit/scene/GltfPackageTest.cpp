// The client-side packer: a .gltf and the files it references -> one GLB that the loader reads
// without any file access, giving the same scene; bad URIs are refused with the field and the reason.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include "renderer/scene/GltfLoader.h"
#include "renderer/scene/GltfPackage.h"
#include "tests/unit/scene/GltfTestBuilder.h"

namespace radiant {
namespace {

using test::GltfBuilder;
using test::json;
using test::trianglePrimitive;

// A textured quad whose buffer and image are external files; the 2x2 texture has four distinct texels.
struct TexturedQuad {
  GltfBuilder b;
  std::vector<std::uint8_t> texels{255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 255};
  TexturedQuad() {
    const int mat = b.material({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}, {"metallicFactor", 0.0}}}});
    const int m = b.mesh(json::array({trianglePrimitive<std::uint16_t>(
        b, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}}, {0, 1, 2, 2, 1, 3}, {}, {{0, 1}, {1, 1}, {0, 0}, {1, 0}}, mat)}));
    b.scene({b.node({{"name", "quad"}, {"mesh", m}})});
    b.doc["textures"] = json::array({{{"source", 0}}});
  }
  std::string gltf(const std::string& binUri, const std::string& pngUri) {
    json d = json::parse(b.gltfExternal(binUri));
    d["images"] = json::array({{{"uri", pngUri}}});
    return d.dump();
  }
};

TEST(GltfPackage, ExternalBufferAndImageBecomeOneGlbThatLoadsTheSameScene) {
  test::TempDir dir("pack_same");
  TexturedQuad q;
  test::writeFile(dir.path / "quad.gltf", q.gltf("data/quad%20mesh.bin", "tex.png"));
  test::writeFile(dir.path / "data" / "quad mesh.bin", q.b.bin);
  test::writeFile(dir.path / "tex.png", test::encodePng(2, 2, q.texels));

  const PackResult packed = packGltfFile(dir.path / "quad.gltf");
  ASSERT_TRUE(packed.packed);
  EXPECT_EQ(packed.externalFiles, 2u);
  ASSERT_EQ(packed.bytes.substr(0, 4), "glTF");
  // The packed GLB needs no files: an empty asset root refuses every external URI.
  const Scene fromGlb = loadSceneFromMemory(packed.bytes);
  const Scene fromFiles = loadScene(dir.path / "quad.gltf");
  ASSERT_EQ(fromGlb.meshes.size(), 1u);
  ASSERT_EQ(fromFiles.meshes.size(), 1u);
  EXPECT_EQ(fromGlb.meshes[0].positions, fromFiles.meshes[0].positions);
  EXPECT_EQ(fromGlb.meshes[0].indices, (std::vector<std::uint32_t>{0, 1, 2, 2, 1, 3}));
  EXPECT_EQ(fromGlb.meshes[0].uv0, fromFiles.meshes[0].uv0);
  ASSERT_EQ(fromGlb.textures.size(), 1u);
  EXPECT_EQ(fromGlb.textures[0].width, 2);
  EXPECT_EQ(fromGlb.textures[0].rgba8, q.texels);  // every texel byte survives
  // Packing is deterministic: the same files give the same digest (what the client skips uploads by).
  EXPECT_EQ(packGltfFile(dir.path / "quad.gltf").bytes, packed.bytes);
  // Changing the .bin changes the packed bytes (and so the digest the scene is cached by).
  std::string bin = q.b.bin;
  bin[0] ^= 1;
  test::writeFile(dir.path / "data" / "quad mesh.bin", bin);
  EXPECT_NE(packGltfFile(dir.path / "quad.gltf").bytes, packed.bytes);
}

TEST(GltfPackage, FilesWithoutExternalUrisAreLeftAsTheyAre) {
  test::TempDir dir("pack_none");
  GltfBuilder b;
  const int m = b.mesh(json::array({trianglePrimitive<std::uint8_t>(b, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2})}));
  b.scene({b.node({{"mesh", m}})});
  test::writeFile(dir.path / "a.gltf", b.gltf());
  test::writeFile(dir.path / "a.glb", b.glb());
  EXPECT_FALSE(packGltfFile(dir.path / "a.gltf").packed);
  EXPECT_EQ(packGltfFile(dir.path / "a.gltf").bytes, b.gltf());
  EXPECT_EQ(packGltfFile(dir.path / "a.glb").bytes, b.glb());
}

TEST(GltfPackage, GlbThatReferencesAnExternalImageIsRepacked) {
  test::TempDir dir("pack_glb");
  TexturedQuad q;
  json d = json::parse(q.b.gltf());  // buffer as a data URI, image external
  d["images"] = json::array({{{"uri", "tex.png"}}});
  test::writeFile(dir.path / "q.gltf", d.dump());
  test::writeFile(dir.path / "tex.png", test::encodePng(2, 2, q.texels));
  const PackResult packed = packGltfFile(dir.path / "q.gltf");
  ASSERT_TRUE(packed.packed);
  EXPECT_EQ(packed.externalFiles, 1u);
  const Scene s = loadSceneFromMemory(packed.bytes);
  ASSERT_EQ(s.textures.size(), 1u);
  EXPECT_EQ(s.textures[0].rgba8, q.texels);
  EXPECT_EQ(s.meshes[0].triangleCount(), 2u);
}

// Each refusal names the field and the reason.
void expectRefused(const std::string& binUri, const std::string& reason, const std::string& tag) {
  test::TempDir dir("pack_refuse_" + tag);
  TexturedQuad q;
  test::writeFile(dir.path / "sub" / "quad.gltf", q.gltf(binUri, "tex.png"));
  test::writeFile(dir.path / "quad.bin", q.b.bin);
  test::writeFile(dir.path / "sub" / "tex.png", test::encodePng(2, 2, q.texels));
  try {
    packGltfFile(dir.path / "sub" / "quad.gltf");
    ADD_FAILURE() << binUri << " was packed";
  } catch (const PackError& e) {
    EXPECT_EQ(e.pointer, "/buffers/0/uri") << binUri;
    EXPECT_NE(std::string(e.what()).find(reason), std::string::npos) << e.what();
  }
}

TEST(GltfPackage, RefusesParentPathsAbsolutePathsSchemesAndSymlinksOut) {
  expectRefused("../quad.bin", "\"..\" is not allowed", "dotdot");
  expectRefused("a/%2E%2E/../quad.bin", "\"..\" is not allowed", "encoded");
  expectRefused("/etc/passwd", "absolute paths are not allowed", "abs");
  expectRefused("http://example.com/quad.bin", "scheme \"http:\"", "http");
  expectRefused("file:///etc/passwd", "scheme \"file:\"", "file");
  // A symlink inside the folder that points outside it.
  test::TempDir dir("pack_symlink");
  TexturedQuad q;
  test::writeFile(dir.path / "outside" / "quad.bin", q.b.bin);
  test::writeFile(dir.path / "in" / "quad.gltf", q.gltf("link.bin", "tex.png"));
  test::writeFile(dir.path / "in" / "tex.png", test::encodePng(2, 2, q.texels));
  std::filesystem::create_symlink(dir.path / "outside" / "quad.bin", dir.path / "in" / "link.bin");
  try {
    packGltfFile(dir.path / "in" / "quad.gltf");
    ADD_FAILURE() << "a symlink out of the folder was followed";
  } catch (const PackError& e) {
    EXPECT_EQ(e.pointer, "/buffers/0/uri");
    EXPECT_NE(std::string(e.what()).find("outside"), std::string::npos) << e.what();
  }
}

TEST(GltfPackage, MissingFileIsNamed) {
  test::TempDir dir("pack_missing");
  TexturedQuad q;
  test::writeFile(dir.path / "quad.gltf", q.gltf("nothere.bin", "tex.png"));
  try {
    packGltfFile(dir.path / "quad.gltf");
    ADD_FAILURE();
  } catch (const PackError& e) {
    EXPECT_EQ(e.pointer, "/buffers/0/uri");
    EXPECT_NE(std::string(e.what()).find("nothere.bin"), std::string::npos) << e.what();
  }
}

// The file a scene.asset names: what is wrong with it decides the server's answer (404 only when it
// is not there; a directory or FIFO 422; over the size limit 422 limit-exceeded), and an empty path says
// so (it was refused as "absolute").
TEST(GltfPackage, TheNamedFileSaysWhetherItIsMissingNotRegularOrTooLarge) {
  test::TempDir dir("pack_kinds");
  TexturedQuad q;
  test::writeFile(dir.path / "quad.gltf", q.gltf("data:application/octet-stream;base64,", "tex.png"));
  std::filesystem::create_directories(dir.path / "folder.gltf");
  ASSERT_EQ(::mkfifo((dir.path / "pipe.gltf").c_str(), 0600), 0);
  auto kindOf = [&](const std::string& name, std::size_t maxBytes) {
    try {
      packGltfFile(dir.path / name, dir.path, maxBytes);
    } catch (const PackError& e) {
      EXPECT_EQ(e.pointer, "") << name;
      return std::pair{e.kind, std::string(e.what())};
    }
    return std::pair{PackError::Kind::Invalid, std::string("packed")};
  };
  EXPECT_EQ(kindOf("nothere.gltf", 1u << 20).first, PackError::Kind::Missing);
  EXPECT_EQ(kindOf("folder.gltf", 1u << 20).first, PackError::Kind::NotRegular);
  const auto fifo = kindOf("pipe.gltf", 1u << 20);  // refused without opening it (no reader: it would block)
  EXPECT_EQ(fifo.first, PackError::Kind::NotRegular);
  EXPECT_NE(fifo.second.find("not a regular file"), std::string::npos) << fifo.second;
  const auto large = kindOf("quad.gltf", 16);
  EXPECT_EQ(large.first, PackError::Kind::TooLarge);
  EXPECT_NE(large.second.find("over the size limit of 16 bytes"), std::string::npos) << large.second;
  try {
    resolveRelativeUri("", "/scene/asset", dir.path, dir.path);
    ADD_FAILURE() << "an empty path was resolved";
  } catch (const PackError& e) {
    EXPECT_NE(std::string(e.what()).find("the path is empty"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace radiant
