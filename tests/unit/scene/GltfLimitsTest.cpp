// The glTF loader's limits (renderer/scene/GltfLimits.h): nesting before any parser, UTF-8,
// numbers that fit, bounded transforms and world positions, and one decode budget over every
// image format and over accessor expansion, charged before anything is allocated (issue #13).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

#include "renderer/scene/GltfLimits.h"
#include "renderer/scene/GltfLoader.h"
#include "tests/unit/scene/GltfTestBuilder.h"

namespace radiant {
namespace {

using test::GltfBuilder;
using test::json;
using test::trianglePrimitive;

using test::triangle;
const std::vector<glm::vec3>& kTri = test::kTriangle;

std::string repeat(const std::string& s, std::size_t n) {
  std::string out;
  for (std::size_t i = 0; i < n; ++i) out += s;
  return out;
}

// Inserts raw JSON text as the document's first member (for documents nlohmann cannot build).
std::string withRawMember(const std::string& gltf, const std::string& member) {
  return "{" + member + "," + gltf.substr(1);
}

struct Caught {
  bool thrown = false, limit = false;
  std::string pointer, message, flag;
};

template <class F>
Caught catchScene(F load) {
  Caught c;
  try {
    load();
  } catch (const SceneLimitError& e) {
    c = {true, true, e.pointer, e.what(), e.flag};
  } catch (const SceneError& e) {
    c = {true, false, e.pointer, e.what(), ""};
  }
  return c;
}

void expectLimit(const Caught& c, const std::string& pointer, const std::string& flag, const std::string& text) {
  ASSERT_TRUE(c.thrown) << "loaded";
  EXPECT_TRUE(c.limit) << c.message;
  EXPECT_EQ(c.pointer, pointer) << c.message;
  EXPECT_EQ(c.flag, flag);
  EXPECT_NE(c.message.find(text), std::string::npos) << c.message;
  EXPECT_NE(c.message.find(flag), std::string::npos) << c.message;
}

void expectInvalid(const Caught& c, const std::string& pointer, const std::string& text) {
  ASSERT_TRUE(c.thrown) << "loaded";
  EXPECT_FALSE(c.limit) << c.message;
  EXPECT_EQ(c.pointer, pointer) << c.message;
  EXPECT_NE(c.message.find(text), std::string::npos) << c.message;
}

}  // namespace

// ---- nesting: tinygltf copied extras recursively and died from ~14k levels ------------------

TEST(GltfLimits, DeepExtrasOfEveryShapeAreRefusedBeforeParsing) {
  const std::string base = triangle().gltf();
  LoadOptions o;
  o.maxJsonDepth = 64;
  // 100000 levels of arrays at the top level: the 64th array is the first too deep.
  expectLimit(catchScene([&] { loadSceneFromMemory(withRawMember(base, "\"extras\":" + repeat("[", 100000) + repeat("]", 100000)), o); }),
              "/extras" + repeat("/0", 63), "--max-json-depth", "nested deeper than 64");
  // Objects inside a node's extras.
  json doc = json::parse(base);
  std::string nodeExtras = "{\"extras\":" + repeat("{\"k\":", 100000) + "1" + repeat("}", 100000) + ",";
  std::string text = doc.dump();
  text.replace(text.find("{\"mesh\":0"), 1, nodeExtras);
  expectLimit(catchScene([&] { loadSceneFromMemory(text, o); }), "/nodes/0/extras" + repeat("/k", 61),
              "--max-json-depth", "nested deeper");
  // The same inside a GLB's JSON chunk.
  GltfBuilder b = triangle();
  b.doc["extras"] = 0;
  std::string glb = b.glb();
  const std::string deep = repeat("[", 70);
  const std::size_t at = glb.find("\"extras\":0") + 9;
  glb.replace(at, 1, deep.substr(0, 1));  // "[" keeps the chunk length; the parser never gets there
  glb.insert(at + 1, deep.substr(1));
  // fix the chunk and file lengths after inserting 69 bytes
  auto le32 = [&](std::size_t off, std::uint32_t v) { for (int i = 0; i < 4; ++i) glb[off + i] = char((v >> (8 * i)) & 255); };
  std::uint32_t total, jsonLen;
  std::memcpy(&total, glb.data() + 8, 4);
  std::memcpy(&jsonLen, glb.data() + 12, 4);
  le32(8, total + 69);
  le32(12, jsonLen + 69);
  expectLimit(catchScene([&] { loadSceneFromMemory(glb, o); }), "/extras" + repeat("/0", 63), "--max-json-depth",
              "nested deeper");
  // Just under the limit loads.
  EXPECT_NO_THROW(loadSceneFromMemory(withRawMember(base, "\"extras\":" + repeat("[", 63) + repeat("]", 63)), o));
}

// ---- bytes that are not UTF-8 (a 500 before: the parser's message quoted them) ---------------

TEST(GltfLimits, A0xFFByteInGltfOrGlbJsonIsAnInvalidSceneWithItsPointer) {
  GltfBuilder b = triangle();
  b.doc["nodes"][0]["name"] = "NAME";
  std::string text = b.gltf();
  text.replace(text.find("NAME"), 4, "N\xff" "ME");
  expectInvalid(catchScene([&] { loadSceneFromMemory(text); }), "/nodes/0/name", "not valid UTF-8");
  std::string glb = b.glb();
  glb.replace(glb.find("NAME"), 4, "N\xff" "ME");  // same length: the chunk stays valid
  expectInvalid(catchScene([&] { loadSceneFromMemory(glb); }), "/nodes/0/name", "not valid UTF-8");
}

// ---- numbers and transforms --------------------------------------------------------------

TEST(GltfLimits, TranslationsThatOverflowAFloatOrExceedTheBoundAreRefused) {
  GltfBuilder b = triangle();
  b.doc["nodes"][0]["translation"] = {1e39, 0, 0};  // +inf as a float
  expectInvalid(catchScene([&] { loadSceneFromMemory(b.gltf()); }), "/nodes/0/translation/0", "does not fit a 32-bit float");
  b.doc["nodes"][0]["translation"] = {0, 2e9, 0};
  expectInvalid(catchScene([&] { loadSceneFromMemory(b.gltf()); }), "/nodes/0/translation/1", "beyond +-1e+09");
  b.doc["nodes"][0]["translation"] = {0, 0, 1e9};  // the bound itself is fine
  EXPECT_NO_THROW(loadSceneFromMemory(b.gltf()));
  b.doc["nodes"][0].erase("translation");
  b.doc["nodes"][0]["rotation"] = {0, 0, 0, 0};
  expectInvalid(catchScene([&] { loadSceneFromMemory(b.gltf()); }), "/nodes/0/rotation", "zero quaternion");
}

TEST(GltfLimits, ACameraNodeAt1e39IsRefusedAtItsNode) {
  GltfBuilder b = triangle();
  b.push("cameras", {{"type", "perspective"}, {"perspective", {{"yfov", 0.7}, {"znear", 0.1}}}});
  const int cam = b.node({{"camera", 0}, {"translation", {1e39, 0, 0}}});
  b.scene({0, cam});
  expectInvalid(catchScene([&] { loadSceneFromMemory(b.gltf()); }), "/nodes/1/translation/0", "32-bit float");
  // Each factor within bounds, their product not: the world position is checked after composition.
  b.doc["nodes"][1] = {{"camera", 0}, {"translation", {0, 0, 1e9}}};
  const int parent = b.node({{"scale", {1e9, 1e9, 1e9}}, {"children", {cam}}});
  b.scene({0, parent});
  expectInvalid(catchScene([&] { loadSceneFromMemory(b.gltf()); }), "/nodes/1", "camera node's world position");
}

TEST(GltfLimits, NestedScalesThatPlaceVerticesOutOfRangeNameTheNode) {
  GltfBuilder b;
  const int m = b.mesh(json::array({trianglePrimitive<std::uint8_t>(b, kTri, {0, 1, 2})}));
  const int child = b.node({{"mesh", m}, {"scale", {1e6, 1e6, 1e6}}});
  const int root = b.node({{"scale", {1e6, 1e6, 1e6}}, {"children", {child}}});
  b.scene({root});
  expectInvalid(catchScene([&] { loadSceneFromMemory(b.gltf()); }), "/nodes/0", "beyond +-1e+09");
}

TEST(GltfLimits, ALightPlacedOutOfRangeByNestedScalesNamesItsNode) {
  GltfBuilder b = triangle();
  b.doc["extensions"]["KHR_lights_punctual"]["lights"] = {{{"type", "point"}, {"intensity", 1}}};
  const int light = b.node({{"translation", {0, 0, 1e9}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  const int parent = b.node({{"scale", {1e3, 1e3, 1e3}}, {"children", {light}}});
  b.scene({0, parent});
  expectInvalid(catchScene([&] { loadSceneFromMemory(b.gltf()); }), "/nodes/1", "in world space: not finite or beyond");
}

TEST(GltfLimits, NonFinitePositionDataIsRefusedAtTheAttribute) {
  GltfBuilder b;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const int m = b.mesh(json::array({trianglePrimitive<std::uint8_t>(b, {{0, 0, 0}, {nan, 0, 0}, {0, 1, 0}}, {0, 1, 2})}));
  b.scene({b.node({{"mesh", m}})});
  expectInvalid(catchScene([&] { loadSceneFromMemory(b.gltf()); }), "/meshes/0/primitives/0/attributes/POSITION",
                "positions must be finite");
}

TEST(GltfLimits, LightValuesMustBeFiniteAndNonNegative) {
  GltfBuilder b = triangle();
  b.doc["extensions"]["KHR_lights_punctual"]["lights"] = {{{"type", "point"}, {"intensity", -1}}};
  b.doc["nodes"][0]["extensions"]["KHR_lights_punctual"]["light"] = 0;
  expectInvalid(catchScene([&] { loadSceneFromMemory(b.gltf()); }), "/extensions/KHR_lights_punctual/lights/0/intensity",
                "outside [0, 1e15]");
  b.doc["extensions"]["KHR_lights_punctual"]["lights"][0]["intensity"] = 10;
  b.doc["extensions"]["KHR_lights_punctual"]["lights"][0]["color"] = {1, 1e300, 1};
  expectInvalid(catchScene([&] { loadSceneFromMemory(b.gltf()); }), "/extensions/KHR_lights_punctual/lights/0/color/1",
                "32-bit float");
}

// ---- accessor expansion: 481 bytes that asked for 2.7 GB ---------------------------------

TEST(GltfLimits, AnAccessorWithoutBufferViewIsChargedBeforeItIsFilled) {
  GltfBuilder b;
  const int acc = b.push("accessors", {{"componentType", 5126}, {"count", 20000001}, {"type", "VEC3"}});
  const int m = b.mesh(json::array({{{"attributes", {{"POSITION", acc}}}}}));
  b.scene({b.node({{"mesh", m}})});
  // 2e7 vertices x (24 bytes read + 28 generated + 8 of indices) = 1.2 GB > 512 MiB.
  expectLimit(catchScene([&] { loadSceneFromMemory(b.gltf()); }), "/accessors/0/count", "--max-decode-bytes",
              "20000001 vertices");
}

TEST(GltfLimits, InstancesOfOneMeshAddUpAgainstTheBudget) {
  GltfBuilder b;
  const int acc = b.push("accessors", {{"componentType", 5126}, {"count", 999999}, {"type", "VEC3"}});
  const int m = b.mesh(json::array({{{"attributes", {{"POSITION", acc}}}}}));
  std::vector<int> roots;
  for (int i = 0; i < 20; ++i) roots.push_back(b.node({{"mesh", m}}));
  b.scene(roots);
  // 60 bytes a vertex: 59999940 per instance; the 9th (node 8) passes 512 MiB = 536870912.
  const Caught c = catchScene([&] { loadSceneFromMemory(b.gltf()); });
  expectLimit(c, "/accessors/0/count", "--max-decode-bytes", "node 8 ");
  EXPECT_NE(c.message.find(std::to_string(9ull * 59999940)), std::string::npos) << c.message;
  // One instance fits.
  GltfBuilder one;
  const int a1 = one.push("accessors", {{"componentType", 5126}, {"count", 999999}, {"type", "VEC3"}});
  one.scene({one.node({{"mesh", one.mesh(json::array({{{"attributes", {{"POSITION", a1}}}}}))}})});
  LoadOptions small;
  small.maxDecodedBytes = 59999940;
  EXPECT_NO_THROW(loadSceneFromMemory(one.gltf(), small));
  small.maxDecodedBytes = 59999939;
  expectLimit(catchScene([&] { loadSceneFromMemory(one.gltf(), small); }), "/accessors/0/count", "--max-decode-bytes",
              "needs 59999940 bytes");
}

// ---- images: every format's header is read before stb allocates -------------------------

namespace {

std::string le16(unsigned v) { return {char(v & 255), char(v >> 8 & 255)}; }
std::string le32s(unsigned v) { return le16(v & 0xffff) + le16(v >> 16); }
std::string be16(unsigned v) { return {char(v >> 8 & 255), char(v & 255)}; }

// Headers claiming 16384 x 16384 pixels (1 GiB as RGBA8), each a few dozen bytes.
std::string bmpHeader() {
  std::string dib = le32s(40) + le32s(16384) + le32s(16384) + le16(1) + le16(24) + le32s(0) + le32s(0) +
                    le32s(2835) + le32s(2835) + le32s(0) + le32s(0);
  return "BM" + le32s(54 + 16) + le32s(0) + le32s(54) + dib + std::string(16, '\0');
}
std::string tgaHeader() {
  return std::string("\0\0\x02", 3) + std::string(5, '\0') + le16(0) + le16(0) + le16(16384) + le16(16384) +
         std::string("\x18\x00", 2) + std::string(16, '\0');
}
std::string gifHeader() { return "GIF89a" + le16(16384) + le16(16384) + std::string("\x00\x00\x00", 3) + std::string(16, '\0'); }
std::string jpegHeader() {
  std::string sof = std::string("\xFF\xC0", 2) + be16(17) + std::string("\x08", 1) + be16(16384) + be16(16384) +
                    std::string("\x03\x01\x11\x00\x02\x11\x00\x03\x11\x00", 10);
  return std::string("\xFF\xD8", 2) + sof + std::string("\xFF\xD9", 2);
}
std::string hdrHeader() { return "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 16384 +X 16384\n" + std::string(16, '\0'); }
std::string pngHeader() {
  std::string png = test::encodePng(1, 1, {0, 0, 0, 255});
  for (int k : {16, 20}) { png[k] = 0; png[k + 1] = 0; png[k + 2] = char(0x40); png[k + 3] = 0; }  // 16384
  return png;
}

// The image in a bufferView (as a GLB embeds it): tinygltf hands any mimeType to the decoder,
// while data URIs are only taken for PNG, JPEG, BMP and GIF.
std::string withImage(const std::string& image, const char* mime) {
  GltfBuilder b = triangle();
  b.push("images", {{"bufferView", b.view(image.data(), image.size())}, {"mimeType", mime}});
  b.push("textures", {{"source", 0}});
  return b.glb();
}

}  // namespace

TEST(GltfLimits, ImagesOfEveryFormatClaiming16384SquaredAreRefusedFromTheirHeader) {
  LoadOptions o;
  o.maxDecodedBytes = 256u << 20;
  const std::pair<const char*, std::string> cases[] = {{"image/bmp", bmpHeader()}, {"image/x-tga", tgaHeader()},
                                                       {"image/gif", gifHeader()}, {"image/jpeg", jpegHeader()},
                                                       {"image/vnd.radiance", hdrHeader()}, {"image/png", pngHeader()}};
  for (const auto& [mime, bytes] : cases) {
    SCOPED_TRACE(mime);
    const auto header = readImageHeader(reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size());
    ASSERT_TRUE(header);
    EXPECT_EQ(header->width, 16384);
    EXPECT_EQ(header->height, 16384);
    // Only PNG and JPEG (and WebP) are glTF image formats: the others are refused before their header is
    // read for the budget (stb_image's readers of those are not hardened: an HDR image's zero RLE run
    // looped for good, tests/data/crashers/gltf/hdr_image_whose_rle_hangs_stb.glb).
    const auto bytesU = reinterpret_cast<const unsigned char*>(bytes.data());
    const bool gltfFormat = std::string(mime) == "image/png" || std::string(mime) == "image/jpeg";
    EXPECT_EQ(isGltfImageFormat(bytesU, bytes.size()), gltfFormat);
    if (gltfFormat) {
      expectLimit(catchScene([&] { loadSceneFromMemory(withImage(bytes, mime), o); }), "/images/0", "--max-decode-bytes",
                  "16384x16384");
    } else {
      try {
        loadSceneFromMemory(withImage(bytes, mime), o);
        ADD_FAILURE() << "accepted";
      } catch (const SceneLimitError& e) {
        ADD_FAILURE() << "refused as over a limit, not as a format: " << e.what();
      } catch (const SceneError& e) {
        EXPECT_EQ(e.pointer, "/images/0");
        EXPECT_NE(std::string(e.what()).find("not a PNG, JPEG or WebP image"), std::string::npos) << e.what();
      }
    }
  }
  // A real image within the budget loads: 2x2 RGBA8 = 16 bytes + its 16-byte copy.
  std::vector<std::uint8_t> px(16, 255);
  o.maxDecodedBytes = 1u << 20;
  const Scene s = loadSceneFromMemory(withImage(test::encodePng(2, 2, px), "image/png"), o);
  ASSERT_EQ(s.textures.size(), 1u);
  EXPECT_EQ(s.textures[0].width, 2);
}

TEST(GltfLimits, DecodeBudgetCountsImageBytesExactly) {
  // 2x2 RGBA8: 16 decoded bytes plus the Scene's 16-byte copy.
  const std::string png = test::encodePng(2, 2, std::vector<std::uint8_t>(16, 7));
  DecodeBudget exact(32), short1(31);
  std::string err;
  EXPECT_TRUE(exact.chargeImage(reinterpret_cast<const unsigned char*>(png.data()), png.size(), 0, &err)) << err;
  EXPECT_EQ(exact.remaining(), 0u);
  EXPECT_FALSE(short1.chargeImage(reinterpret_cast<const unsigned char*>(png.data()), png.size(), 0, &err));
  EXPECT_THROW(short1.rethrowImageError(), SceneLimitError);
}

// The daemon's shared decode memory (LoadOptions::reserveDecoded, radiantd --decode-memory-bytes): every
// byte the budget charges is reserved first, accessor expansion and image pixels alike, and what the
// reservation throws (the server's 503 decode-busy) leaves the load unchanged, also from inside
// tinygltf's image callback.
struct NoDecodeMemory : std::runtime_error {
  using std::runtime_error::runtime_error;
};
TEST(GltfLimits, EveryChargedByteIsReservedAndTheReservationsRefusalPassesThrough) {
  // An image: 2x2 RGBA8, 16 decoded bytes plus the Scene's 16-byte copy.
  const std::string gltf = withImage(test::encodePng(2, 2, std::vector<std::uint8_t>(16, 9)), "image/png");
  LoadOptions o;
  std::vector<std::size_t> reserved;
  o.reserveDecoded = [&](std::size_t n) { reserved.push_back(n); };
  const Scene s = loadSceneFromMemory(gltf, o);
  ASSERT_EQ(s.textures.size(), 1u);
  ASSERT_FALSE(reserved.empty());
  EXPECT_EQ(reserved.back(), 32u);
  o.reserveDecoded = [](std::size_t n) {
    if (n == 32) throw NoDecodeMemory("no decode memory");
  };
  EXPECT_THROW(loadSceneFromMemory(gltf, o), NoDecodeMemory);
  // Accessor expansion: one instance of 999999 float3 positions, 59999940 bytes charged and reserved.
  GltfBuilder one;
  const int a1 = one.push("accessors", {{"componentType", 5126}, {"count", 999999}, {"type", "VEC3"}});
  one.scene({one.node({{"mesh", one.mesh(json::array({{{"attributes", {{"POSITION", a1}}}}}))}})});
  std::size_t total = 0;
  o.reserveDecoded = [&](std::size_t n) { total += n; };
  EXPECT_NO_THROW(loadSceneFromMemory(one.gltf(), o));
  EXPECT_EQ(total, 59999940u);
  o.reserveDecoded = [](std::size_t) { throw NoDecodeMemory("no decode memory"); };
  EXPECT_THROW(loadSceneFromMemory(one.gltf(), o), NoDecodeMemory);
  // Over the per-decode limit, the limit's own error comes first and nothing is reserved.
  total = 0;
  o.maxDecodedBytes = 59999939;
  o.reserveDecoded = [&](std::size_t n) { total += n; };
  EXPECT_THROW(loadSceneFromMemory(one.gltf(), o), SceneLimitError);
  EXPECT_EQ(total, 0u);
}

}  // namespace radiant
