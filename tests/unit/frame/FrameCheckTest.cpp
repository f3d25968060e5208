// What a request asks of its scene that no frame could render is found before the job is queued
// (issue 33, "every 4xx before the queue"): Renderer::check runs the planner, the camera, the compare
// block and each planned technique's validate() without GL (this binary has no GL context: a check
// that touched GL would crash here), and radiantd calls it on the HTTP thread, so these are 422s of
// the POST, not failed jobs. The frame itself raises the same errors through the same code.
#include <string>

#include <gtest/gtest.h>

#include "api/Validate.h"
#include "renderer/Renderer.h"
#include "renderer/shading/MediaLayer.h"
#include "renderer/techniques/depth_impostors/Blocks.h"
#include "renderer/techniques/depth_impostors/DepthImpostors.h"
#include "renderer/scene/BuiltinScenes.h"
#include "tests/support/Expect.h"
#include "tests/support/SceneBuilder.h"

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
  // Particles without optical depth are no medium (mediaParticleCount, mediaParticles' rule): a second
  // system of 1024 at tau 0 adds no chords, so 64 directions still fit.
  json clear = many;
  clear["tau"] = 0.0;
  json both = body(64);
  both["media"].push_back(clear);
  EXPECT_NO_THROW(Renderer::check(loadBuiltinScene("cornell_box"), api::parseRenderRequest(both), {}));
  EXPECT_EQ(mediaParticleCount(api::parseRenderRequest(both).media), 1024u);
}

// `n` mirror quads under a point light above a lit floor (every mirror is a specular object of the
// specular pass and a generator of caustics).
Scene mirrors(int n) {
  testing::SceneBuilder b;
  Material m;
  m.name = "mirror";
  m.baseColorFactor = glm::vec4(0.9f, 0.9f, 0.9f, 1.f);
  m.metallicFactor = 1.f;
  m.roughnessFactor = 0.f;
  const int mirror = b.material(m);
  b.quad({0, 0, 0}, {0, 0, 2}, {2, 0, 0}, b.material(testing::lambertian()), "floor");  // facing +y
  for (int i = 0; i < n; ++i)
    b.quad({-1.f + 0.01f * float(i % 200), 1.f, -1.f + 0.01f * float(i / 200)}, {0, 0, 0.004f}, {0.004f, 0, 0}, mirror,
           "mirror");
  b.pointLight({0, 2, 0}, 5.f);
  b.topDownOrtho(3.f, 2.f);
  return b.build("mirrors-" + std::to_string(n));
}

api::ApiError checkedOn(const Scene& scene, const json& passes) {
  const api::RenderRequest request = api::parseRenderRequest(box({{"passes", passes}}));
  return testing::thrownApiError([&] { Renderer::check(scene, request, {}); });
}

// The layered distance maps' and the caustic cubes' memory limits (SpecularPass::kMaxBytes and
// CausticsPass::kMaxBytes, 512 MiB each) depend on the scene's specular meshes and the parameters, not
// on the view: a resolution the request gives above them, and meshes that do not fit even at 16
// texels, are 422s of the POST. The frame still halves a resolution it chose itself (the GL tests).
TEST(FrameCheck, TheSpecularMapsAndCausticCubesMemoryLimitsAreCheckedBeforeTheQueue) {
  // One glass sphere's maps at 2048 texels: 3 layers x 6 faces x 2048^2 x 32 bytes = 2304 MiB.
  api::ApiError e = checked(box({{"scene", {{"builtin", "cornell_glass"}}},
                                 {"passes", {{"specular", {{"cube_resolution", 2048}}}}}}));
  EXPECT_EQ(e.status, 422);
  EXPECT_EQ(e.type, "limit-exceeded");
  EXPECT_EQ(e.pointer, "/passes/specular/cube_resolution");
  EXPECT_NE(e.detail().find("2304 MiB"), std::string::npos) << e.detail();
  // The maps' floor: 6 layers of 6 faces at 16^2 x 32 bytes is 294,912 bytes an object, so 1820 objects
  // fit the limit (536,756,224 bytes) and 1821 do not (537,051,136), whatever resolution the view chose.
  const json sixLayers = {{"specular", {{"layers", 6}}}};
  EXPECT_NO_THROW(Renderer::check(mirrors(1820), api::parseRenderRequest(box({{"passes", sixLayers}})), {}));
  e = checkedOn(mirrors(1821), sixLayers);
  EXPECT_EQ(e.status, 422);
  EXPECT_EQ(e.pointer, "/passes/specular");
  EXPECT_NE(e.detail().find("even at 16 texels"), std::string::npos) << e.detail();
  // Caustic cubes of 1024 texels with their mip chains: 128 MiB a generator; 4 fit, 5 do not. Left to
  // the default, the frame lowers the resolution and the check passes.
  const json given = {{"caustics", {{"cube_resolution", 1024}}}};
  EXPECT_NO_THROW(Renderer::check(mirrors(4), api::parseRenderRequest(box({{"passes", given}})), {}));
  e = checkedOn(mirrors(5), given);
  EXPECT_EQ(e.status, 422);
  EXPECT_EQ(e.pointer, "/passes/caustics/cube_resolution");
  EXPECT_NO_THROW(Renderer::check(mirrors(5), api::parseRenderRequest(box()), {}));
}

// The impostor atlas holds at most 512 x 512 tiles (2048 texels a side, tiles of at least 4): a scene's
// 262,145 particles (a glTF may hold 2^20; a request at most 65536) at one particle a block do not fit,
// two a block do. The blocks are counted, not built (DepthImpostorsPass::blockCount), with
// buildBlocks' rule: ceil(n / b) per system of the particles with optical depth.
TEST(FrameCheck, TheImpostorAtlasIsCheckedAgainstTheFramesParticlesBeforeTheQueue) {
  auto system = [](std::size_t n, float tau) {
    api::ParticleSystem s;
    s.name = "cloud";
    for (std::size_t i = 0; i < n; ++i) {
      api::Particle p;
      p.position = glm::vec3(float(i % 64) * 0.01f, float((i / 64) % 64) * 0.01f, float(i / 4096) * 0.01f);
      p.radius = 0.01f;
      p.tau = tau;
      s.particles.push_back(p);
    }
    return s;
  };
  // The count is buildBlocks' (three systems, one of them without optical depth).
  const std::vector<api::ParticleSystem> media = {system(5, 1.f), system(7, 0.f), system(3, 2.f)};
  std::vector<int> systemOf;
  const auto particles = mediaParticles(media, glm::vec3(0.f), glm::vec3(0.f, 0.f, 5.f), glm::vec3(0.f, 0.f, -1.f),
                                        false, false, &systemOf);
  for (int b : {1, 2, 4, 64})
    EXPECT_EQ(DepthImpostorsPass::blockCount(media, b), impostors::buildBlocks(particles, systemOf, b).blocks.size()) << b;

  Scene scene = loadBuiltinScene("cornell_box");
  scene.media.push_back(system(262145, 1.f));
  scene.features = computeFeatures(scene);
  auto impostorsAt = [](int b) {
    return api::parseRenderRequest(box({{"passes", {{"depth_impostors", {{"particles_per_block", b}}}}}}));
  };
  const api::ApiError e = testing::thrownApiError([&] { Renderer::check(scene, impostorsAt(1), {}); });
  EXPECT_EQ(e.status, 422);
  EXPECT_EQ(e.pointer, "/passes/depth_impostors/particles_per_block");
  EXPECT_NE(e.detail().find("262145 blocks"), std::string::npos) << e.detail();
  EXPECT_NO_THROW(Renderer::check(scene, impostorsAt(2), {}));
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
