// The request validator: every error names its field with a JSON pointer, the status follows the
// documented mapping (400 shape, 422 content), and defaults come from the schema files.
#include <gtest/gtest.h>

#include "api/Validate.h"

using nlohmann::json;
using radiant::api::ApiError;
using radiant::api::parseRenderRequest;
using radiant::api::RequestLimits;

namespace {

// Runs the parser and returns the error it throws (fails the test if none).
ApiError errorOf(const json& body, const RequestLimits& limits = {}) {
  try {
    parseRenderRequest(body, limits);
  } catch (const ApiError& e) {
    return e;
  }
  ADD_FAILURE() << "no error for " << body.dump();
  return ApiError(0, "", "", "");
}

json minimal() { return json{{"scene", {{"builtin", "cornell_box"}}}}; }

}  // namespace

TEST(Validate, MinimalRequestGetsEveryDefault) {
  json v = radiant::api::normaliseRenderRequest(minimal());
  EXPECT_EQ(v["width"], 256);
  EXPECT_EQ(v["height"], 256);
  EXPECT_EQ(v["exposure"], 0);
  EXPECT_EQ(v["seed"], 0);
  EXPECT_EQ(v["async"], false);
  EXPECT_EQ(v["ambient"], json::array({0, 0, 0}));
  ASSERT_EQ(v["outputs"].size(), 1u);
  EXPECT_EQ(v["outputs"][0]["format"], "png");
  EXPECT_EQ(v["outputs"][0]["aovs"], json::array({"beauty"}));
  EXPECT_EQ(v["outputs"][0]["half"], true);
  // The default passes object is {"direct": {}}, and direct's parameters are filled in too.
  ASSERT_TRUE(v["passes"].contains("direct"));
  EXPECT_EQ(v["passes"]["direct"]["pcf_radius"], 1);
  EXPECT_FALSE(v.contains("camera"));
  EXPECT_FALSE(v.contains("compare"));
}

// The raster's anti-aliasing is on by default (issue 12's 30 dB goal, issue 29's fidelity goal,
// docs/PERFORMANCE.md): enough samples per pixel axis for about 512 x 512 raster samples, 2 to 4;
// except under a quality preset or a time budget, whose table (api/presets.json) was measured at one
// sample per pixel; an explicit value always wins.
TEST(Validate, SupersamplingDefaultsByFrameSizeAndToOneUnderPresetsUnlessGiven) {
  EXPECT_EQ(parseRenderRequest(minimal()).supersampling, 2);  // 256 x 256
  auto sized = [](int w, int h) {
    json r = minimal();
    r["width"] = w;
    r["height"] = h;
    return parseRenderRequest(r).supersampling;
  };
  EXPECT_EQ(sized(128, 128), 4);   // 512 / 128 = 4
  EXPECT_EQ(sized(32, 32), 4);     // capped at 4
  EXPECT_EQ(sized(200, 200), 3);   // ceil(2.56)
  EXPECT_EQ(sized(171, 171), 3);   // ceil(2.994)
  EXPECT_EQ(sized(170, 170), 4);   // ceil(3.01)
  EXPECT_EQ(sized(256, 256), 2);   // exactly 2
  EXPECT_EQ(sized(512, 128), 2);   // sqrt(512 128) = 256: by pixel count, not the short side
  EXPECT_EQ(sized(1920, 1080), 2);  // floored at 2
  EXPECT_EQ(radiant::api::defaultSupersampling(1, 1), 4);
  EXPECT_EQ(radiant::api::defaultSupersampling(4096, 4096), 2);
  json q = minimal();
  q["quality"] = "final";
  EXPECT_EQ(parseRenderRequest(q).supersampling, 1);
  json b = minimal();
  b["time_budget_ms"] = 500;
  EXPECT_EQ(parseRenderRequest(b).supersampling, 1);
  q["supersampling"] = 3;
  EXPECT_EQ(parseRenderRequest(q).supersampling, 3);
  b["supersampling"] = 2;
  EXPECT_EQ(parseRenderRequest(b).supersampling, 2);
}

TEST(Validate, TechniqueDefaultsFilledFromTheirSchemaFiles) {
  json body = minimal();
  body["passes"] = {{"shadow_maps", {{"shadow_map_size", 2048}}}, {"reference", json::object()}};
  auto r = parseRenderRequest(body);
  ASSERT_EQ(r.passes.size(), 2u);
  EXPECT_EQ(r.passes["shadow_maps"]["shadow_map_size"], 2048);
  EXPECT_DOUBLE_EQ(r.passes["shadow_maps"]["shadow_bias"].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(r.passes["shadow_maps"]["normal_offset"].get<double>(), 1.5);
  EXPECT_EQ(r.passes["reference"]["spp"], 64);
  EXPECT_EQ(r.passes["reference"]["max_bounces"], 1024);  // a safety cap: roulette ends paths (issue 32)
  EXPECT_EQ(r.passes["reference"]["russian_roulette"], true);
}

TEST(Validate, CameraAndCompareDefaultsInsideGivenObjects) {
  json body = minimal();
  body["camera"] = {{"position", {0, 2, 5}}};
  body["compare"] = json::object();
  auto r = parseRenderRequest(body);
  ASSERT_TRUE(r.camera.has_value());
  EXPECT_FLOAT_EQ(r.camera->position.y, 2.f);
  // Fields not given keep the scene's camera (FrameView fills them in), so none is defaulted here.
  EXPECT_TRUE(r.camera->hasPosition);
  EXPECT_FALSE(r.camera->hasTarget);
  EXPECT_FALSE(r.camera->hasUp);
  EXPECT_FALSE(r.camera->hasYfov);
  ASSERT_TRUE(r.compare.has_value());
  EXPECT_EQ(r.compare->against, "reference");
  EXPECT_EQ(r.compare->spp, 256);
  EXPECT_EQ(r.compare->maxBounces, 1024);
}

TEST(Validate, FullRequestConverts) {
  json body = {{"scene", {{"digest", "sha256:" + std::string(64, 'a')}}},
               {"width", 640},
               {"height", 480.0},  // an integral number is an integer
               {"passes", {{"direct", {{"pcf_radius", 3}}}, {"gbuffer", json::object()}}},
               {"outputs", {{{"format", "exr"}, {"aovs", {"beauty", "albedo", "depth"}}, {"half", false}},
                            {{"format", "png"}}}},
               {"exposure", -1.5},
               {"seed", 42},
               {"ambient", {0.1, 0.2, 0.3}},
               {"async", true}};
  auto r = parseRenderRequest(body);
  EXPECT_EQ(r.scene.kind, radiant::api::SceneRef::Kind::Digest);
  EXPECT_EQ(r.width, 640);
  EXPECT_EQ(r.height, 480);
  EXPECT_EQ(r.passes["direct"]["pcf_radius"], 3);
  ASSERT_EQ(r.outputs.size(), 2u);
  EXPECT_EQ(r.outputs[0].format, radiant::api::ImageFormat::Exr);
  EXPECT_EQ(r.outputs[0].aovs, (std::vector<std::string>{"beauty", "albedo", "depth"}));
  EXPECT_FALSE(r.outputs[0].halfFloat);
  EXPECT_EQ(r.outputs[1].format, radiant::api::ImageFormat::Png);
  EXPECT_EQ(r.outputs[1].aovs, (std::vector<std::string>{"beauty"}));
  EXPECT_FLOAT_EQ(r.exposure, -1.5f);
  EXPECT_EQ(r.seed, 42u);
  EXPECT_FLOAT_EQ(r.ambient.z, 0.3f);
  EXPECT_TRUE(r.async);
}

TEST(Validate, UnknownTopLevelKeyIs422WithPointer) {
  json body = minimal();
  body["widht"] = 3;
  ApiError e = errorOf(body);
  EXPECT_EQ(e.status, 422);
  EXPECT_EQ(e.type, "unknown-field");
  EXPECT_EQ(e.pointer, "/widht");
}

TEST(Validate, UnknownTechniqueAndUnknownParameterNamed) {
  json body = minimal();
  body["passes"] = {{"no_such_technique", json::object()}};
  ApiError e = errorOf(body);
  EXPECT_EQ(e.status, 422);
  EXPECT_EQ(e.pointer, "/passes/no_such_technique");

  body["passes"] = {{"direct", {{"pcf_radiu", 2}}}};
  e = errorOf(body);
  EXPECT_EQ(e.status, 422);
  EXPECT_EQ(e.type, "unknown-field");
  EXPECT_EQ(e.pointer, "/passes/direct/pcf_radiu");
  EXPECT_NE(e.detail().find("pcf_radius"), std::string::npos) << "the detail lists the known keys: " << e.detail();
}

TEST(Validate, OutOfRangeIs422WithPointer) {
  json body = minimal();
  body["passes"] = {{"shadow_maps", {{"shadow_map_size", 8192}}}};
  ApiError e = errorOf(body);
  EXPECT_EQ(e.status, 422);
  EXPECT_EQ(e.type, "out-of-range");
  EXPECT_EQ(e.pointer, "/passes/shadow_maps/shadow_map_size");
  EXPECT_NE(e.detail().find("4096"), std::string::npos);

  body = minimal();
  body["passes"] = {{"direct", {{"pcf_radius", -1}}}};
  e = errorOf(body);
  EXPECT_EQ(e.pointer, "/passes/direct/pcf_radius");
  EXPECT_EQ(e.type, "out-of-range");

  body = minimal();
  body["ambient"] = {0.5, -0.1, 0};
  e = errorOf(body);
  EXPECT_EQ(e.status, 422);
  EXPECT_EQ(e.pointer, "/ambient/1");

  body = minimal();
  body["width"] = 0;
  EXPECT_EQ(errorOf(body).pointer, "/width");
  body["width"] = 4097;
  EXPECT_EQ(errorOf(body).pointer, "/width");
}

TEST(Validate, WrongTypeIs400WithPointer) {
  json body = minimal();
  body["width"] = "wide";
  ApiError e = errorOf(body);
  EXPECT_EQ(e.status, 400);
  EXPECT_EQ(e.type, "type-mismatch");
  EXPECT_EQ(e.pointer, "/width");

  body = minimal();
  body["width"] = 12.5;
  EXPECT_EQ(errorOf(body).pointer, "/width");
  EXPECT_EQ(errorOf(body).status, 400);

  body = minimal();
  body["passes"] = {{"reference", {{"russian_roulette", 1}}}};
  e = errorOf(body);
  EXPECT_EQ(e.status, 400);
  EXPECT_EQ(e.pointer, "/passes/reference/russian_roulette");

  e = errorOf(json::array({1, 2}));
  EXPECT_EQ(e.status, 400);
  EXPECT_EQ(e.pointer, "");
}

TEST(Validate, EnumPatternAndCounts) {
  json body = minimal();
  body["outputs"] = {{{"format", "tiff"}}};
  ApiError e = errorOf(body);
  EXPECT_EQ(e.status, 422);
  EXPECT_EQ(e.type, "invalid-value");
  EXPECT_EQ(e.pointer, "/outputs/0/format");

  body["outputs"] = {{{"format", "exr"}, {"aovs", {"beauty", "sparkle"}}}};
  EXPECT_EQ(errorOf(body).pointer, "/outputs/0/aovs/1");

  body["outputs"] = {{{"format", "png"}, {"aovs", {"beauty", "albedo"}}}};
  e = errorOf(body);
  EXPECT_EQ(e.status, 422);
  EXPECT_EQ(e.pointer, "/outputs/0/aovs");

  body["outputs"] = {{{"aovs", {"beauty"}}}};
  e = errorOf(body);
  EXPECT_EQ(e.type, "missing-field");
  EXPECT_EQ(e.pointer, "/outputs/0/format");

  body = json{{"scene", {{"digest", "sha256:xyz"}}}};
  EXPECT_EQ(errorOf(body).pointer, "/scene/digest");
  body = json{{"scene", json::object()}};
  EXPECT_EQ(errorOf(body).pointer, "/scene");
  body = json{{"scene", {{"builtin", "a"}, {"digest", "sha256:" + std::string(64, '0')}}}};
  EXPECT_EQ(errorOf(body).pointer, "/scene");
  body = minimal();
  body["camera"] = {{"position", {1, 2}}};
  EXPECT_EQ(errorOf(body).pointer, "/camera/position");
}

TEST(Validate, MissingSceneIs422) {
  ApiError e = errorOf(json{{"width", 64}});
  EXPECT_EQ(e.status, 422);
  EXPECT_EQ(e.type, "missing-field");
  EXPECT_EQ(e.pointer, "/scene");
}

TEST(Validate, MalformedJsonIs400) {
  try {
    parseRenderRequest(std::string_view("{\"scene\": {\"builtin\": \"x\"}"));
    FAIL() << "no error";
  } catch (const ApiError& e) {
    EXPECT_EQ(e.status, 400);
    EXPECT_EQ(e.type, "malformed-json");
    EXPECT_EQ(e.pointer, "");
    EXPECT_NE(e.detail().find("byte"), std::string::npos);
  }
}

TEST(Validate, ServerLimitsAreLowerThanTheSchema) {
  RequestLimits limits;
  limits.maxWidth = 512;
  limits.maxSamples = 100;
  json body = minimal();
  body["width"] = 1024;
  ApiError e = errorOf(body, limits);
  EXPECT_EQ(e.status, 422);
  EXPECT_EQ(e.type, "limit-exceeded");
  EXPECT_EQ(e.pointer, "/width");

  body = minimal();
  body["passes"] = {{"reference", {{"spp", 1000}}}};
  EXPECT_EQ(errorOf(body, limits).pointer, "/passes/reference/spp");
  body = minimal();
  body["compare"] = {{"spp", 101}};
  EXPECT_EQ(errorOf(body, limits).pointer, "/compare/spp");
  body = minimal();
  body["passes"] = {{"reference", json::object()}};  // default 64 is within 100
  EXPECT_NO_THROW(parseRenderRequest(body, limits));
}

// Without Russian roulette the reference runs every path to max_bounces: spp x max_bounces path
// segments per pixel are capped at --max-samples x 64 (the old schema's worst case, 64 bounces).
TEST(Validate, ReferenceWithoutRouletteIsChargedItsBounces) {
  RequestLimits limits;
  limits.maxSamples = 100;
  json body = minimal();
  body["passes"] = {{"reference", {{"spp", 100}, {"max_bounces", 64}, {"russian_roulette", false}}}};
  EXPECT_NO_THROW(parseRenderRequest(body, limits));  // 6400 = 100 x 64
  body["passes"]["reference"]["max_bounces"] = 65;
  ApiError e = errorOf(body, limits);
  EXPECT_EQ(e.status, 422);
  EXPECT_EQ(e.type, "limit-exceeded");
  EXPECT_EQ(e.pointer, "/passes/reference/max_bounces");
  EXPECT_NE(e.detail().find("6500 path segments per pixel is above this server's limit 6400"), std::string::npos) << e.detail();
  body["passes"]["reference"]["russian_roulette"] = true;  // roulette ends the paths: the cap is a safety net
  body["passes"]["reference"]["max_bounces"] = 4096;
  EXPECT_NO_THROW(parseRenderRequest(body, limits));
  body["passes"]["reference"] = {{"spp", 7}, {"russian_roulette", false}};  // default max_bounces 1024: 7168
  EXPECT_EQ(errorOf(body, limits).pointer, "/passes/reference/max_bounces");
}

TEST(Validate, PointerEscaping) {
  EXPECT_EQ(radiant::api::pointerAppend("/passes", "a/b~c"), "/passes/a~1b~0c");
  json body = minimal();
  body["passes"] = {{"a/b", json::object()}};
  EXPECT_EQ(errorOf(body).pointer, "/passes/a~1b");
}

TEST(Schema, EveryTechniqueFileIsMergedWithDocumentedParams) {
  const auto& techniques = radiant::api::techniqueSchemas();
  std::vector<std::string> names;
  for (const auto& t : techniques) names.push_back(t.name);
  for (const char* expected : {"direct", "gbuffer", "reference", "shadow_maps", "ambient_occlusion", "env_diffuse", "specular"})
    EXPECT_NE(std::find(names.begin(), names.end(), expected), names.end()) << expected;
  for (const auto& t : techniques) {
    EXPECT_FALSE(t.description.empty()) << t.name;
    for (const auto& [name, p] : t.params.items()) {
      EXPECT_TRUE(p.contains("default")) << t.name << "." << name;
      EXPECT_TRUE(p.contains("description")) << t.name << "." << name;
      // A default always passes its own schema.
      EXPECT_NO_THROW(radiant::api::validate(p, p["default"], "/x")) << t.name << "." << name;
    }
  }
  // The AOV enum is the union of every technique's outputs.
  const json& aovEnum =
      radiant::api::renderRequestSchema()["properties"]["outputs"]["items"]["properties"]["aovs"]["items"]["enum"];
  for (const char* aov : {"beauty", "direct", "albedo", "depth", "normal"})
    EXPECT_NE(std::find(aovEnum.begin(), aovEnum.end(), aov), aovEnum.end()) << aov;
}

TEST(Validate, PassesTrueAndFalseTurnTechniquesOnAndOff) {
  json body = minimal();
  body["passes"] = {{"photon_gi", false}, {"specular", true}, {"direct", {{"pcf_radius", 2}}}};
  const auto r = parseRenderRequest(body);
  EXPECT_EQ(r.disabledPasses, (std::set<std::string>{"photon_gi"}));
  EXPECT_EQ(r.passes.count("photon_gi"), 0u);
  ASSERT_EQ(r.passes.count("specular"), 1u);
  EXPECT_TRUE(r.passes.at("specular").is_object());
  EXPECT_EQ(r.passes.at("direct")["pcf_radius"], 2);
  // The normalised form keeps the false (a sweep record or the stats show what was asked).
  EXPECT_EQ(radiant::api::normaliseRenderRequest(body)["passes"]["photon_gi"], false);
  // An unknown technique is still named, whatever its value.
  json bad = minimal();
  bad["passes"] = {{"photon_splat", false}};
  const ApiError e = errorOf(bad);
  EXPECT_EQ(e.status, 422);
  EXPECT_EQ(e.pointer, "/passes/photon_splat");
  // A number is not a switch.
  json num = minimal();
  num["passes"] = {{"photon_gi", 0}};
  EXPECT_EQ(errorOf(num).pointer, "/passes/photon_gi");
}

// issue 29, item 8: the view transform and the background of PNG output.
TEST(Validate, ToneMapDefaultsToAcesAndUnknownNamesAre422) {
  json v = radiant::api::normaliseRenderRequest(minimal());
  EXPECT_EQ(v["tone_map"], "aces");
  EXPECT_EQ(v["background"], "environment");
  auto r = parseRenderRequest(minimal());
  EXPECT_EQ(r.toneMap, radiant::api::ToneMap::Aces);
  ASSERT_EQ(r.outputs.size(), 1u);
  EXPECT_EQ(r.outputs[0].toneMap, radiant::api::ToneMap::Aces);
  EXPECT_EQ(r.background.kind, radiant::api::Background::Kind::Environment);

  json body = minimal();
  body["outputs"] = {{{"format", "png"}}, {{"format", "exr"}}};
  for (const char* name : {"standard", "aces", "khronos_pbr_neutral", "agx"}) {
    body["tone_map"] = name;
    r = parseRenderRequest(body);
    EXPECT_STREQ(radiant::api::toString(r.toneMap), name);
    for (const auto& o : r.outputs) EXPECT_EQ(o.toneMap, r.toneMap) << name;  // copied into every output
  }
  for (const json& bad : {json("filmic"), json("ACES"), json("")}) {
    body["tone_map"] = bad;
    ApiError e = errorOf(body);
    EXPECT_EQ(e.status, 422) << bad;
    EXPECT_EQ(e.pointer, "/tone_map");
  }
  body["tone_map"] = 1;
  EXPECT_EQ(errorOf(body).status, 400);  // the wrong type, as for every field
  EXPECT_EQ(errorOf(body).pointer, "/tone_map");
}

TEST(Validate, BackgroundIsANameOrALinearColour) {
  json body = minimal();
  body["background"] = "transparent";
  EXPECT_EQ(parseRenderRequest(body).background.kind, radiant::api::Background::Kind::Transparent);
  body["background"] = {0.25, 0.5, 2};
  auto r = parseRenderRequest(body);
  EXPECT_EQ(r.background.kind, radiant::api::Background::Kind::Colour);
  EXPECT_EQ(r.background.colour, glm::vec3(0.25f, 0.5f, 2.f));

  body["background"] = "black";
  ApiError e = errorOf(body);
  EXPECT_EQ(e.status, 422);
  EXPECT_EQ(e.pointer, "/background");
  body["background"] = {0.1, 0.2};
  e = errorOf(body);
  EXPECT_EQ(e.status, 422);
  EXPECT_EQ(e.pointer, "/background");
  body["background"] = {0.1, -0.2, 0.3};
  e = errorOf(body);
  EXPECT_EQ(e.status, 422);
  EXPECT_EQ(e.pointer, "/background/1");
  body["background"] = {0.1, "x", 0.3};
  EXPECT_EQ(errorOf(body).pointer, "/background/1");
  body["background"] = 0.5;  // neither a name nor a colour
  e = errorOf(body);
  EXPECT_EQ(e.status, 400);
  EXPECT_EQ(e.pointer, "/background");
  EXPECT_NE(e.detail().find("a string or an array"), std::string::npos) << e.detail();
}
