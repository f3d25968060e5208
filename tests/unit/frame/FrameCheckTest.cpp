// What a request asks of its scene that no frame could render is found before the job is queued
// (issue 33, "every 4xx before the queue"): Renderer::check runs the planner, the camera, the compare
// block and each planned technique's validate() without GL (this binary has no GL context: a check
// that touched GL would crash here), and radiantd calls it on the HTTP thread, so these are 422s of
// the POST, not failed jobs. The frame itself raises the same errors through the same code.
#include <string>

#include <gtest/gtest.h>

#include "api/Validate.h"
#include "renderer/Renderer.h"
#include "renderer/scene/BuiltinScenes.h"
#include "tests/support/Expect.h"

namespace radiant {
namespace {

using nlohmann::json;

api::ApiError checked(const json& body, const FrameInputs& inputs = {}) {
  const api::RenderRequest request = api::parseRenderRequest(body);
  const Scene scene = loadBuiltinScene(body["scene"]["builtin"]);
  return testing::thrownApiError([&] { Renderer::check(scene, request, inputs); });
}

json box(json extra = json::object()) {
  json body{{"scene", {{"builtin", "cornell_box"}}}, {"width", 32}, {"height", 24}};
  body.update(extra);
  return body;
}

TEST(FrameCheck, AValidRequestPassesWithoutGl) {
  for (const json& body : {box(), box({{"passes", {{"env_diffuse", json::object()}}}}),
                           box({{"compare", {{"aov", "indirect"}}}}),
                           json{{"scene", {{"builtin", "explosion"}}}, {"passes", {{"illumination_network", json::object()}}}}}) {
    const api::RenderRequest request = api::parseRenderRequest(body);
    const Scene scene = loadBuiltinScene(body["scene"]["builtin"]);
    EXPECT_NO_THROW(Renderer::check(scene, request, {})) << body.dump();
  }
}

TEST(FrameCheck, ThePlannersConflictsAre422) {
  const api::ApiError e = checked(box({{"passes", {{"photon_gi", json::object()}, {"env_diffuse", json::object()}}}}));
  EXPECT_EQ(e.status, 422);
  EXPECT_EQ(e.type, "conflicting-passes");
}

TEST(FrameCheck, ATechniquesSceneAndParameterProblemsAre422NamingTheParameter) {
  api::ApiError e = checked(box({{"passes", {{"env_diffuse", {{"receivers", "no_such_node"}}}}}}));
  EXPECT_EQ(e.status, 422);
  EXPECT_EQ(e.pointer, "/passes/env_diffuse/receivers");
  e = checked(box({{"passes", {{"env_diffuse", {{"cube_resolution", 16}, {"downsample", 16}, {"reference_points", "x"}}}}}}));
  EXPECT_EQ(e.pointer, "/passes/env_diffuse/reference_points");
  e = checked(json{{"scene", {{"builtin", "explosion"}}},
                   {"passes", {{"illumination_network", {{"nodes", 65536}, {"directions", 512}}}}}});
  EXPECT_EQ(e.status, 422);
  EXPECT_EQ(e.pointer, "/passes/illumination_network/nodes");
}

// A limit that depends on the frame's particles, not only on parameters: illumination_network's exact
// sky costs particles x directions chords per step of the march; 1024 particles x 128 directions is
// above its 65536 and a 422 of the POST; 64 directions pass.
TEST(FrameCheck, TheNetworksExactSkyIsCheckedAgainstTheRequestsParticles) {
  const json many = {{"kind", "cloud"}, {"tau", 10.0}, {"albedo", {0.9, 0.9, 0.9}}, {"seed", 1},
                     {"generator", {{"count", 1024}, {"extent", {1, 1, 1}}, {"radius", 0.1}}}};
  auto body = [&](int directions) {
    return box({{"media", json::array({many})},
                {"passes", {{"spherical_billboards", false},
                            {"illumination_network", {{"nodes", 64}, {"directions", directions},
                                                      {"sky_single_scatter", "exact"}}}}}});
  };
  const api::ApiError e = checked(body(128));
  EXPECT_EQ(e.status, 422);
  EXPECT_EQ(e.pointer, "/passes/illumination_network/sky_single_scatter");
  EXPECT_NE(e.detail().find("131072"), std::string::npos) << e.detail();
  const api::RenderRequest fits = api::parseRenderRequest(body(64));
  EXPECT_NO_THROW(Renderer::check(loadBuiltinScene("cornell_box"), fits, {}));
}

TEST(FrameCheck, TheCameraAndTheCompareBlockAre422BeforeAnyFrame) {
  // An orbit whose eye single precision cannot place (the parser cannot tell: it needs the camera built).
  api::ApiError e = checked(box(
      {{"camera", {{"target", {1e6, 0, 0}}, {"orbit", {{"theta_deg", 90}, {"phi_deg", 90}, {"radius", 1e-3}}}}}}));
  EXPECT_EQ(e.status, 422);
  EXPECT_EQ(e.pointer, "/camera/orbit/radius");
  e = checked(box({{"compare", {{"aov", "normal"}}}}));  // data: the reference renders no ground truth of it
  EXPECT_EQ(e.type, "invalid-compare");
  EXPECT_EQ(e.pointer, "/compare/aov");
  // An uploaded target of another size than the frame.
  const Image target = Image::make("beauty", 16, 16, 3);
  FrameInputs inputs;
  inputs.compareTarget = &target;
  e = checked(box({{"compare", {{"against", "sha256:" + std::string(64, 'a')}}}}), inputs);
  EXPECT_EQ(e.type, "invalid-compare");
  EXPECT_EQ(e.pointer, "/compare/against");
  EXPECT_NE(e.detail().find("16x16"), std::string::npos) << e.detail();
  // An environment the caller did not supply.
  e = checked(box({{"environment", "sha256:" + std::string(64, 'b')}}));
  EXPECT_EQ(e.pointer, "/environment");
}

}  // namespace
}  // namespace radiant
