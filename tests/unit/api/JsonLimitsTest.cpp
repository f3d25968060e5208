// The pre-parse JSON scanner and the UTF-8 helpers (api/JsonLimits.h), and the request validator's
// hardening: every input class that crashed radiantd or gave a 500 (issue #13) becomes a 4xx with
// the pointer of the field, before any recursive code runs.
#include <gtest/gtest.h>

#include <chrono>

#include "api/JsonLimits.h"
#include "api/Validate.h"

using nlohmann::json;
using radiant::api::ApiError;
using radiant::api::JsonScanProblem;
using radiant::api::scanJson;
using Kind = radiant::api::JsonScanProblem::Kind;

namespace {

std::string repeat(const std::string& s, std::size_t n) {
  std::string out;
  out.reserve(s.size() * n);
  for (std::size_t i = 0; i < n; ++i) out += s;
  return out;
}

ApiError errorOfText(const std::string& text, const radiant::api::RequestLimits& limits = {}) {
  try {
    radiant::api::parseRenderRequest(std::string_view(text), limits);
  } catch (const ApiError& e) {
    return e;
  }
  ADD_FAILURE() << "no error for " << text.substr(0, 200);
  return ApiError(0, "", "", "");
}

ApiError errorOf(const json& body, const radiant::api::RequestLimits& limits = {}) { return errorOfText(body.dump(), limits); }

json request() { return json{{"scene", {{"builtin", "cornell_box"}}}}; }

}  // namespace

// ---- nesting --------------------------------------------------------------------------------

TEST(JsonScan, ExactlyTheLimitPassesOneMoreIsRefusedWithItsPointer) {
  EXPECT_FALSE(scanJson(repeat("[", 64) + repeat("]", 64), 64));
  const auto p = scanJson(repeat("[", 65) + repeat("]", 65), 64);
  ASSERT_TRUE(p);
  EXPECT_EQ(p->kind, Kind::TooDeep);
  EXPECT_EQ(p->pointer, repeat("/0", 64));  // the 65th array is element 0 of the 64th
  EXPECT_EQ(p->byte, 64u);
}

TEST(JsonScan, EveryNestingShapeIsCountedAndPointedAt) {
  // Objects, arrays of objects, and a later array element: the pointer follows keys and indices.
  const auto objects = scanJson(repeat("{\"a\":", 5) + "1" + repeat("}", 5), 4);
  ASSERT_TRUE(objects);
  EXPECT_EQ(objects->pointer, "/a/a/a/a");
  const auto mixed = scanJson(R"({"x":[1,2,{"y/~":[[0]]}]})", 4);
  ASSERT_TRUE(mixed);
  EXPECT_EQ(mixed->pointer, "/x/2/y~1~0/0");  // RFC 6901 escapes of '/' and '~'
  EXPECT_FALSE(scanJson(R"({"x":[1,2,{"y":[0]}],"z":{}})", 4));
  // Brackets inside strings (and escaped quotes) are text, not structure.
  EXPECT_FALSE(scanJson("[\"" + repeat("[", 1000) + "\\\"[[[\"]", 2));
}

TEST(JsonScan, HundredThousandLevelsAreRefusedInLinearTime) {
  const std::string deep = repeat("[", 100000) + repeat("]", 100000);
  const auto start = std::chrono::steady_clock::now();
  const auto p = scanJson(deep, 64);
  ASSERT_TRUE(p);
  EXPECT_EQ(p->kind, Kind::TooDeep);
  EXPECT_EQ(p->byte, 64u);  // it stops at the first byte over the limit
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(1));
  // The same through the request parser: a 422 naming the flag, never a stack overflow.
  const ApiError e = errorOfText(deep);
  EXPECT_EQ(e.status, 422);
  EXPECT_EQ(e.type, "limit-exceeded");
  EXPECT_EQ(e.pointer, repeat("/0", 64));
  EXPECT_NE(e.detail().find("--max-json-depth"), std::string::npos) << e.detail();
  const ApiError inScene = errorOfText(R"({"scene":{"builtin":)" + repeat("{\"a\":", 200));
  EXPECT_EQ(inScene.type, "limit-exceeded");
  EXPECT_EQ(inScene.pointer, "/scene/builtin" + repeat("/a", 62));
}

TEST(JsonScan, AParsedTreeIsHeldToTheSameDepth) {
  json deep = 1;
  for (int i = 0; i < 5000; ++i) deep = json::array({std::move(deep)});
  EXPECT_EQ(radiant::api::jsonDepth(deep, 100), 101u);  // stops counting past the limit
  json body = request();
  body["camera"] = deep;
  try {
    radiant::api::parseRenderRequest(body);
    ADD_FAILURE() << "accepted";
  } catch (const ApiError& e) {
    EXPECT_EQ(e.type, "limit-exceeded");
  }
}

// ---- UTF-8 ----------------------------------------------------------------------------------

TEST(JsonScan, InvalidUtf8IsFoundWithItsPointerAndByte) {
  const std::string text = "{\"scene\":{\"builtin\":\"ab\xff\"}}";
  const auto p = scanJson(text, 64);
  ASSERT_TRUE(p);
  EXPECT_EQ(p->kind, Kind::InvalidUtf8);
  EXPECT_EQ(p->pointer, "/scene/builtin");
  EXPECT_EQ(p->byte, text.find('\xff'));
  const auto key = scanJson("{\"k\xc0\xaf\":1}", 64);  // an overlong '/' in a key
  ASSERT_TRUE(key);
  EXPECT_EQ(key->pointer, "/k\xEF\xBF\xBD\xEF\xBF\xBD");  // the pointer itself is valid UTF-8
  const ApiError e = errorOfText(text);
  EXPECT_EQ(e.status, 400);
  EXPECT_EQ(e.type, "invalid-utf8");
  EXPECT_EQ(e.pointer, "/scene/builtin");
}

TEST(Utf8, ValidityFollowsRfc3629) {
  using radiant::api::isValidUtf8;
  EXPECT_TRUE(isValidUtf8("plain ascii"));
  EXPECT_TRUE(isValidUtf8("\xc3\xa9\xe2\x82\xac\xf0\x9f\x98\x80"));  // é € 😀
  EXPECT_TRUE(isValidUtf8("\xf4\x8f\xbf\xbf"));                      // U+10FFFF, the last code point
  EXPECT_FALSE(isValidUtf8("\xf4\x90\x80\x80"));                     // U+110000
  EXPECT_FALSE(isValidUtf8("\xed\xa0\x80"));                         // a UTF-16 surrogate
  EXPECT_FALSE(isValidUtf8("\xc0\xaf"));                             // overlong '/'
  EXPECT_FALSE(isValidUtf8("\xe2\x82"));                             // truncated sequence
  EXPECT_FALSE(isValidUtf8("\xff"));
  EXPECT_EQ(radiant::api::validUtf8Prefix("ab\xc3\xa9\xff"), 4u);
}

TEST(Utf8, SanitizeTruncateAndDumpNeverProduceInvalidText) {
  EXPECT_EQ(radiant::api::sanitizeUtf8("a\xff" "b"), "a\xEF\xBF\xBD" "b");
  // Two-byte characters: a cut at 3 bytes steps back to the end of the first one.
  EXPECT_EQ(radiant::api::truncateUtf8("\xc3\xa9\xc3\xa9\xc3\xa9", 3), "\xc3\xa9...");
  EXPECT_EQ(radiant::api::truncateUtf8("short", 10), "short");
  EXPECT_EQ(radiant::api::dumpSafe(json("/\xff")), "\"/\xEF\xBF\xBD\"");
  EXPECT_THROW(json("/\xff").dump(), json::type_error);  // what the problem writer did before
}

TEST(Validate, ANonAsciiValueInADetailIsNeverCutInsideACharacter) {
  // "é" is two bytes: 100 of them quoted in a pattern error used to be cut after byte 77.
  json body = request();
  body["scene"]["builtin"] = repeat("\xc3\xa9", 100);
  const ApiError e = errorOf(body);
  EXPECT_EQ(e.status, 422);
  EXPECT_EQ(e.pointer, "/scene/builtin");
  EXPECT_TRUE(radiant::api::isValidUtf8(e.detail())) << e.detail();
  EXPECT_NO_THROW(json(e.detail()).dump());
}

// ---- numbers --------------------------------------------------------------------------------

TEST(JsonScan, NumbersBeyondADoubleAreOutOfRangeAtTheirPointer) {
  EXPECT_FALSE(scanJson(R"({"a":1e308,"b":-1.7e308,"c":1e-400})", 64));  // underflow is 0, not an error
  const auto p = scanJson(R"({"a":[0,-1e309]})", 64);
  ASSERT_TRUE(p);
  EXPECT_EQ(p->kind, Kind::NumberOverflow);
  EXPECT_EQ(p->pointer, "/a/1");
  EXPECT_TRUE(scanJson("[" + repeat("9", 400) + "]", 64));  // a 400-digit integer
  json body = request();
  const std::string text = R"({"scene":{"builtin":"cornell_box"},"exposure":1e400})";
  const ApiError e = errorOfText(text);
  EXPECT_EQ(e.status, 422);
  EXPECT_EQ(e.type, "out-of-range");
  EXPECT_EQ(e.pointer, "/exposure");
}

TEST(Validate, CameraCoordinatesAreBoundedSoNoRayIsInvalid) {
  json body = request();
  body["camera"] = {{"position", {1e308, 0, 0}}};  // a float infinity once converted
  ApiError e = errorOf(body);
  EXPECT_EQ(e.status, 422);
  EXPECT_EQ(e.type, "out-of-range");
  EXPECT_EQ(e.pointer, "/camera/position/0");
  body["camera"] = {{"position", {0, 0, 0}}, {"target", {0, 0, -1.0000001e9}}};
  EXPECT_EQ(errorOf(body).pointer, "/camera/target/2");
  body["camera"] = {{"position", {1e9, 0, 0}}, {"target", {-1e9, 0, 0}}};
  EXPECT_NO_THROW(radiant::api::parseRenderRequest(body));  // the bound itself is fine
}

TEST(Validate, UpVectorIsCheckedRelativeToItsOwnLength) {
  json body = request();
  body["camera"] = {{"position", {0, 0, 3}}, {"target", {0, 0, 0}}, {"up", {0, 1e-30, 0}}};
  const auto r = radiant::api::parseRenderRequest(body);
  ASSERT_TRUE(r.camera);
  EXPECT_FLOAT_EQ(r.camera->up.y, 1.f);  // normalised in double precision
  body["camera"]["up"] = {0, 0, -5};  // along the view direction
  EXPECT_EQ(errorOf(body).pointer, "/camera/up");
  body["camera"]["up"] = {0, 0, 0};
  EXPECT_EQ(errorOf(body).pointer, "/camera/up");
  body["camera"]["up"] = {1e-6, 0, 1};  // 1e-6 rad off the view axis: still too close
  EXPECT_EQ(errorOf(body).pointer, "/camera/up");
  body["camera"]["up"] = {1e-3, 0, 1};  // 1 mrad: a valid, if tilted, camera
  EXPECT_NO_THROW(radiant::api::parseRenderRequest(body));
}

// ---- duplicate and oversized outputs --------------------------------------------------------

TEST(Validate, DuplicateAovsAndOutputsAreRefused) {
  json body = request();
  body["outputs"] = {{{"format", "exr"}, {"aovs", {"beauty", "direct", "beauty"}}}};
  ApiError e = errorOf(body);
  EXPECT_EQ(e.status, 422);
  EXPECT_EQ(e.pointer, "/outputs/0/aovs/2");
  body["outputs"] = {{{"format", "exr"}}, {{"format", "png"}}, {{"format", "exr"}, {"aovs", {"beauty"}}}};
  EXPECT_EQ(errorOf(body).pointer, "/outputs/2");  // equal to /outputs/0 once defaults are filled
}

TEST(Validate, OutputBytesAreLimitedNamingTheFlag) {
  radiant::api::RequestLimits limits;
  limits.maxOutputBytes = 64u << 20;
  json body = request();
  body["width"] = 2048;
  body["height"] = 2048;
  // 2048^2 x 2 AOVs x 4 half channels = 64 MiB: exactly the limit.
  body["outputs"] = {{{"format", "exr"}, {"aovs", {"beauty", "direct"}}}};
  EXPECT_NO_THROW(radiant::api::parseRenderRequest(body, limits));
  body["outputs"].push_back({{"format", "png"}});  // + 16 MiB
  const ApiError e = errorOf(body, limits);
  EXPECT_EQ(e.type, "limit-exceeded");
  EXPECT_EQ(e.pointer, "/outputs");
  EXPECT_NE(e.detail().find(std::to_string((64u << 20) + (16u << 20))), std::string::npos) << e.detail();
  EXPECT_NE(e.detail().find("--max-frame-bytes"), std::string::npos);
}

TEST(Validate, CompareAovIsOneTheSchemaKnows) {
  json body = request();
  body["compare"] = {{"aov", "no-such-aov"}};
  const ApiError e = errorOf(body);
  EXPECT_EQ(e.status, 422);
  EXPECT_EQ(e.type, "invalid-value");
  EXPECT_EQ(e.pointer, "/compare/aov");
  body["compare"] = {{"aov", "ao"}};
  EXPECT_NO_THROW(radiant::api::parseRenderRequest(body));
}
