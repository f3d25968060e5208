// Render-core tests on the real GL device (llvmpipe in CI). Every expected value is fixed by the
// physics of the scene: glTF light units, the Lambertian BRDF, the KHR_lights_punctual falloffs.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>

#include <gtest/gtest.h>

#include "renderer/techniques/shadow_maps/ShadowMaps.h"

#include "api/Aovs.h"
#include "renderer/Renderer.h"
#include "renderer/ResidentMemory.h"
#include "renderer/scene/BuiltinScenes.h"
#include "renderer/frame/FramePlanner.h"
#include "renderer/frame/FrameResources.h"
#include "renderer/frame/GpuTypes.h"
#include "renderer/gl/ShaderLibrary.h"
#include "renderer/techniques/Registry.h"
#include "renderer/io/ImageIO.h"
#include "tests/support/Expect.h"
#include "tests/support/ImageDifference.h"
#include "tests/support/RenderTestSupport.h"
#include "tests/support/SceneBuilder.h"

namespace radiant {
namespace {

// A camera override looking from `position` at `target` (every other field at its default).
api::CameraOverride lookAt(glm::vec3 position, glm::vec3 target, glm::vec3 up, float yfovDegrees) {
  api::CameraOverride camera;
  camera.position = position;
  camera.target = target;
  camera.up = up;
  camera.yfovDegrees = yfovDegrees;
  return camera;
}

using testing::aov;
using testing::renderer;

using testing::SceneBuilder;
using testing::lambertian;
using testing::topDownPixelToWorld;


api::RenderRequest request(int size, std::vector<std::string> aovs = {"beauty", "direct"}) {
  api::RenderRequest req;
  req.width = req.height = size;
  req.outputs = {api::OutputSpec{api::ImageFormat::Exr, aovs, false}};
  req.passes["shadow_maps"] = {{"shadow_map_size", 1024}};
  return req;
}


void expectAllFinite(const RenderOutput& out) {
  for (const auto& a : out.aovs)
    for (float v : a.pixels) ASSERT_TRUE(std::isfinite(v)) << a.aov;
}

// A 40 m white plane at y = 0 seen from above.
SceneBuilder planeScene(float scale = 1.f) {
  SceneBuilder b;
  int white = b.material(lambertian());
  b.quad({0, 0, 0}, {20.f * scale, 0, 0}, {0, 0, -20.f * scale}, white, "floor");  // normal +Y
  return b;
}

TEST(RenderCore, PointLightCalibrationAndCosCubedFalloff) {
  // A point light of intensity pi at height 1: E = I cos(theta) / d^2 = pi cos^3(theta), and a white
  // Lambertian surface reflects L = E / pi = cos^3(theta): exactly 1.0 at the foot point.
  const int size = 64;
  const float half = 1.5f;
  Scene scene = planeScene().pointLight({0, 1, 0}, glm::pi<float>()).topDownOrtho(5.f, half).build("calib");
  RenderOutput out = renderer().render(scene, request(size));
  expectAllFinite(out);
  const Image& direct = aov(out, "direct");
  int checked = 0;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const glm::vec2 w = topDownPixelToWorld(x, y, size, half);
      const float d2 = 1.f + glm::dot(w, w);
      const float expected = std::pow(d2, -1.5f);  // cos^3 theta
      const float got = direct.at(x, y)[0];
      if (glm::dot(w, w) < 0.05f * 0.05f) {
        EXPECT_NEAR(got, 1.0f, 0.01f) << "foot point " << x << "," << y;
      }
      EXPECT_NEAR(got / expected, 1.0f, 0.02f) << "pixel " << x << "," << y;
      ++checked;
    }
  EXPECT_EQ(checked, size * size);
  // Beauty is direct when nothing else runs.
  EXPECT_FLOAT_EQ(aov(out, "beauty").at(10, 10)[1], direct.at(10, 10)[1]);
}

TEST(RenderCore, PointLightRangeWindowIsTheSpecsUnsquaredWindow) {
  // KHR_lights_punctual, "Range Property": attenuation = max(min(1 - (d / range)^4, 1), 0) / d^2. With
  // range 2 and the calibration light above, L = cos^3(theta) (1 - d^4 / 16): 15/16 at the foot point
  // (the squared window some engines use would give 0.879 there), 0 beyond d = 2.
  const int size = 64;
  const float half = 2.f;
  Scene scene = planeScene().pointLight({0, 1, 0}, glm::pi<float>()).topDownOrtho(5.f, half).build("range");
  scene.lights[0].range = 2.f;
  RenderOutput out = renderer().render(scene, request(size));
  expectAllFinite(out);
  const Image& direct = aov(out, "direct");
  int inside = 0, outside = 0;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const glm::vec2 w = topDownPixelToWorld(x, y, size, half);
      const float d2 = 1.f + glm::dot(w, w);
      const float window = std::max(0.f, 1.f - d2 * d2 / 16.f);
      const float expected = std::pow(d2, -1.5f) * window;
      const float got = direct.at(x, y)[0];
      if (glm::dot(w, w) < 0.05f * 0.05f) {
        EXPECT_NEAR(got, 15.f / 16.f, 0.01f) << "foot point " << x << "," << y;
      }
      if (window > 0.1f) {
        EXPECT_NEAR(got / expected, 1.0f, 0.02f) << "pixel " << x << "," << y;
        ++inside;
      } else if (d2 > 4.05f) {
        EXPECT_EQ(got, 0.f) << "beyond range, pixel " << x << "," << y;
        ++outside;
      }
    }
  EXPECT_GT(inside, 1000);
  EXPECT_GT(outside, 200);
}

TEST(RenderCore, SpotLightConeEdges) {
  // KHR_lights_punctual smooth falloff: t = clamp((cos a - cos outer) / (cos inner - cos outer)), t^2.
  const float inner = 0.3f, outer = 0.5f, I = glm::pi<float>();
  const int size = 96;
  const float half = 0.7f;
  Scene scene = planeScene().spotLight({0, 1, 0}, {0, -1, 0}, I, inner, outer).topDownOrtho(5.f, half).build("spot");
  RenderOutput out = renderer().render(scene, request(size));
  expectAllFinite(out);
  const Image& direct = aov(out, "direct");
  int inside = 0, outside = 0, ramp = 0;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const glm::vec2 w = topDownPixelToWorld(x, y, size, half);
      const float r = glm::length(w);
      const float a = std::atan(r);  // angle from the spot axis
      const float cos3 = std::pow(1.f + r * r, -1.5f);
      float t = (std::cos(a) - std::cos(outer)) / (std::cos(inner) - std::cos(outer));
      t = std::clamp(t, 0.f, 1.f);
      const float expected = cos3 * t * t;
      const float got = direct.at(x, y)[0];
      if (a < inner - 0.02f) { EXPECT_NEAR(got / cos3, 1.f, 0.02f); ++inside; }
      else if (a > outer + 0.02f) { EXPECT_EQ(got, 0.f); ++outside; }
      else if (a > inner + 0.02f && a < outer - 0.02f) { EXPECT_NEAR(got, expected, 0.02f * cos3); ++ramp; }
    }
  EXPECT_GT(inside, 100);
  EXPECT_GT(outside, 100);
  EXPECT_GT(ramp, 100);
}

TEST(RenderCore, DirectionalLightIsIrradiance) {
  // Directional intensity is irradiance on a surface facing it: L = E cos(45 deg) / pi.
  const float E = 2.f;
  Scene scene = planeScene().directionalLight({0, -1, -1}, E).topDownOrtho(5.f, 1.f).build("dir");
  RenderOutput out = renderer().render(scene, request(32));
  expectAllFinite(out);
  const float expected = E * std::sqrt(0.5f) / glm::pi<float>();
  const Image& direct = aov(out, "direct");
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) EXPECT_NEAR(direct.at(x, y)[2], expected, 0.01f * expected);
}

// A point light at height 1 above the plane and a 0.4 x 0.4 occluder at height 0.5 facing down.
// Seen from above, the occluder shows its back face, which glTF's single-sided rule discards, so the
// camera sees the plane through it while the shadow map still sees the occluder. The umbra is the
// occluder's projection from the light: a 0.8 x 0.8 square.
Scene umbraScene(float scale, const std::string& digest) {
  SceneBuilder b = planeScene(scale);
  int grey = b.material(lambertian(glm::vec3(0.5f)));
  b.quad(glm::vec3(0, 0.5f, 0) * scale, glm::vec3(0.2f, 0, 0) * scale, glm::vec3(0, 0, 0.2f) * scale, grey, "occluder");  // normal -Y
  b.pointLight(glm::vec3(0, 1, 0) * scale, glm::pi<float>() * scale * scale);  // same irradiance at every scale
  b.topDownOrtho(5.f * scale, 1.5f * scale);
  return b.build(digest);
}

// Whether the frame's lookup of `what` hit its cache (a failure, and false, when it did not look it up).
bool cacheHit(const RenderOutput& o, const std::string& what) {
  for (const auto& c : o.stats.cache)
    if (c.what == what) return c.hit;
  ADD_FAILURE() << "no " << what << " cache entry in the stats";
  return false;
}

// A counter of photon_gi in a frame's stats (a failure, and -1, when the pass did not run).
double photonGiCounter(const RenderOutput& o, const std::string& name) {
  for (const auto& p : o.stats.passes)
    if (p.name == "photon_gi") return p.counters.at(name);
  ADD_FAILURE() << "no photon_gi pass";
  return -1.0;
}

TEST(RenderCore, UmbraIsBlackAndLitPlaneHasNoAcne) {
  const int size = 96;
  const float half = 1.5f;
  RenderOutput out = renderer().render(umbraScene(1.f, "umbra"), request(size));
  expectAllFinite(out);
  const Image& direct = aov(out, "direct");
  int umbra = 0, lit = 0;
  double sumRel = 0, sumRel2 = 0;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const glm::vec2 w = topDownPixelToWorld(x, y, size, half);
      const float got = direct.at(x, y)[0];
      if (std::abs(w.x) < 0.34f && std::abs(w.y) < 0.34f) {  // inside the umbra, away from its edge
        EXPECT_EQ(got, 0.f) << "umbra pixel " << x << "," << y;
        ++umbra;
      } else if (std::abs(w.x) > 0.5f || std::abs(w.y) > 0.5f) {  // fully lit
        const float rel = got / std::pow(1.f + glm::dot(w, w), -1.5f);
        sumRel += rel;
        sumRel2 += rel * rel;
        ++lit;
      }
    }
  ASSERT_GT(umbra, 400);  // 0.68 m square at 32 px/m: ~21^2 pixels
  ASSERT_GT(lit, 3000);
  // Shadow acne would show as dark speckles: the lit plane's radiance relative to the analytic
  // cos^3 law must have mean 1 and a standard deviation under 0.5%.
  const double mean = sumRel / lit, var = sumRel2 / lit - mean * mean;
  EXPECT_NEAR(mean, 1.0, 0.01);
  EXPECT_LT(std::sqrt(std::max(var, 0.0)), 0.005);
}

TEST(RenderCore, SceneScaleInvariance) {
  // The same scene at 1e-3 and 1e4 scale, with the light intensity scaled by s^2, renders the same.
  const int size = 64;
  RenderOutput ref = renderer().render(umbraScene(1.f, "scale1"), request(size));
  for (float s : {1e-3f, 1e4f}) {
    RenderOutput out = renderer().render(umbraScene(s, "scale" + std::to_string(s)), request(size));
    expectAllFinite(out);
    const Image& a = aov(ref, "direct");
    const Image& b = aov(out, "direct");
    int differing = 0;
    for (std::size_t i = 0; i < a.pixels.size(); ++i)
      if (std::abs(a.pixels[i] - b.pixels[i]) > 0.01f * std::max(a.pixels[i], 0.05f)) ++differing;
    // Shadow-edge pixels may flip where the penumbra crosses a texel boundary; allow 1% of them.
    EXPECT_LT(differing, static_cast<int>(a.pixels.size() / 100)) << "scale " << s;
  }
}

TEST(RenderCore, StatsTimeEveryPassAndSkipWithReasons) {
  RenderOutput out = renderer().render(umbraScene(1.f, "stats"), request(32));
  std::vector<std::string> names;
  for (const auto& p : out.stats.passes) {
    names.push_back(p.name);
    EXPECT_GT(p.gpuMs, 0.0) << p.name;
    EXPECT_GE(p.cpuMs, 0.0) << p.name;
    EXPECT_GE(p.prepareMs, 0.0) << p.name;
  }
  // The photons are traced and splatted in photon_gi's prepare(): its prepare_ms, timed around the
  // call, holds the two builds its own counters time (this scene's first frame: both ran).
  const api::PassStats* photons = testing::pass(out, "photon_gi");
  ASSERT_NE(photons, nullptr);
  EXPECT_GT(photons->counters.at("trace_ms"), 0.0);
  EXPECT_GE(photons->prepareMs, photons->counters.at("trace_ms") + photons->counters.at("splat_build_ms"));
  EXPECT_EQ(names, (std::vector<std::string>{"gbuffer", "shadow_maps", "direct", "photon_gi"}));
  EXPECT_EQ(out.stats.triangles, 4u);
  EXPECT_EQ(out.stats.lights, 1);
  EXPECT_FALSE(out.stats.device.at("renderer").empty());

  // No lights (and the default studio lighting turned off): the shadow maps are skipped with a
  // reason and direct still runs.
  Scene dark = planeScene().topDownOrtho(5.f, 1.f).build("dark");
  api::RenderRequest unlitRequest = request(16);
  unlitRequest.defaultLighting = false;
  RenderOutput d = renderer().render(dark, unlitRequest);
  EXPECT_EQ(d.stats.lighting, "none");
  ASSERT_TRUE(d.stats.skipped.count("shadow_maps"));
  EXPECT_EQ(d.stats.skipped.at("shadow_maps"), "the scene has no punctual lights and the frame no environment map");
  for (float v : aov(d, "beauty").pixels) EXPECT_EQ(v, 0.f);
}

// Layered geometry makes the shadow maps' cost unbounded (fragments = map area x overdraw: 16,667
// stacked triangles: 2.7 billion in a default frame's 17 maps). 3000 stacked 2 x 2 quads 1e-4 apart cover a
// directional light's map 1483 times over: the default 1024^2 would rasterise 1.5 billion fragments, so
// the maps are drawn at 256^2 (97 Mi, within ShadowMapsPass::kFragmentBudget) with a warning, and the
// top layer is still lit as the light's irradiance says and not shadowed by the layers under it. A
// size the request names is not lowered: above kFragmentLimit it is a 422 naming the field.
TEST(RenderCore, ShadowMapOverdrawIsBoundedByTheFragmentBudget) {
  SceneBuilder b;
  const int white = b.material(lambertian());
  Scene scene = b.directionalLight({0, -1, 0}, 2.f).topDownOrtho(5.f, 0.9f).build("stack");
  MeshInstance stack;
  stack.material = white;
  for (int i = 0; i < 3000; ++i) {
    const float y = -1e-4f * i;
    const std::uint32_t v = static_cast<std::uint32_t>(stack.positions.size());
    for (const glm::vec3 p : {glm::vec3(-1, y, 1), glm::vec3(1, y, 1), glm::vec3(1, y, -1), glm::vec3(-1, y, -1)}) {
      stack.positions.push_back(p);
      stack.normals.push_back({0, 1, 0});
      stack.bounds.extend(p);
    }
    stack.indices.insert(stack.indices.end(), {v, v + 1, v + 2, v, v + 2, v + 3});
  }
  scene.meshes.push_back(std::move(stack));
  scene.features = computeFeatures(scene);
  api::RenderRequest req = request(32);
  req.disabledPasses = {"photon_gi"};
  const RenderOutput out = renderer().render(scene, req);
  expectAllFinite(out);
  const api::PassStats* maps = testing::pass(out, "shadow_maps");
  ASSERT_NE(maps, nullptr);
  EXPECT_EQ(maps->counters.at("map_size"), 256.0);
  EXPECT_LE(maps->counters.at("fragments_estimated"), ShadowMapsPass::kFragmentBudget);
  EXPECT_NEAR(maps->counters.at("fragments_estimated"), 3000 * 4.0 / (8.0 + 0.2999 * 0.2999) * 256 * 256,
              0.01 * maps->counters.at("fragments_estimated"));
  bool warned = false;
  for (const auto& w : out.stats.warnings) warned = warned || w.rfind("shadow_maps: the default 1024^2 maps", 0) == 0;
  EXPECT_TRUE(warned);
  const float expected = 2.f / glm::pi<float>();
  const Image& direct = aov(out, "direct");
  for (int y = 2; y < 30; ++y)
    for (int x = 2; x < 30; ++x) EXPECT_NEAR(direct.at(x, y)[1], expected, 0.01f * expected) << x << "," << y;

  req.explicitParams["shadow_maps"] = {"shadow_map_size"};
  req.passes["shadow_maps"] = {{"shadow_map_size", 2048}};  // 1483 x 2048^2 = 6.2 billion
  const api::ApiError e = testing::thrownApiError([&] { renderer().render(scene, req); });  // 6 billion fragments
  EXPECT_EQ(e.status, 422);
  EXPECT_EQ(e.pointer, "/passes/shadow_maps/shadow_map_size");
  // Refused before the job is queued (Renderer::check, on radiantd's HTTP thread, no GL): the scene's
  // own light covers the map 1483 times over, the same estimate and message as the frame's.
  const api::ApiError early = testing::thrownApiError([&] { Renderer::check(scene, req, FrameInputs{}); });
  EXPECT_EQ(early.status, 422);
  EXPECT_EQ(early.pointer, "/passes/shadow_maps/shadow_map_size");
  EXPECT_EQ(early.detail(), e.detail());
  req.passes["shadow_maps"] = {{"shadow_map_size", 1024}};  // 1483 x 1024^2 = 1.6 billion: within 4.3
  EXPECT_NO_THROW(Renderer::check(scene, req, FrameInputs{}));
}

// The maps' memory limit (ShadowMapsPass::kMaxBytes, 1 GiB) is checked before the job is queued over
// the scene's own lights: three point lights at 4096^2 are 18 cube faces of 64 MiB (1152 MiB), at
// 2048^2 a quarter of that. The environment's lights join at the frame (Environment.ShadowMaps...).
TEST(RenderCore, ShadowMapMemoryOfTheScenesLightsIsRefusedBeforeTheQueue) {
  SceneBuilder b = planeScene();
  for (float x : {-1.f, 0.f, 1.f}) b.pointLight({x, 1, 0}, 1.f);
  const Scene scene = b.topDownOrtho(5.f, 1.5f).build("three-point-lights");
  api::RenderRequest req = request(16, {"direct"});
  req.passes["shadow_maps"] = {{"shadow_map_size", 4096}};
  req.explicitParams["shadow_maps"] = {"shadow_map_size"};
  const api::ApiError e = testing::thrownApiError([&] { Renderer::check(scene, req, FrameInputs{}); });
  EXPECT_EQ(e.status, 422);
  EXPECT_EQ(e.pointer, "/passes/shadow_maps/shadow_map_size");
  EXPECT_NE(e.detail().find("3 shadow maps (3 point-light cubes) of 4096^2 need 1152 MiB"), std::string::npos) << e.detail();
  req.passes["shadow_maps"] = {{"shadow_map_size", 2048}};
  EXPECT_NO_THROW(Renderer::check(scene, req, FrameInputs{}));
}

TEST(RenderCore, DerivedDataIsCachedAcrossFrames) {
  Scene scene = umbraScene(1.f, "cache");
  renderer().render(scene, request(32));
  api::RenderRequest moved = request(48);
  moved.camera = lookAt({0.5f, 3.f, 2.f}, {0, 0, 0}, {0, 1, 0}, 50.f);
  RenderOutput second = renderer().render(scene, moved);
  bool gpuHit = false, shadowHit = false;
  for (const auto& c : second.stats.cache) {
    if (c.what == "gpu_scene") gpuHit = c.hit;
    if (c.what == "shadow_maps") shadowHit = c.hit;
  }
  EXPECT_TRUE(gpuHit);
  EXPECT_TRUE(shadowHit);
  for (const auto& p : second.stats.passes) {
    if (p.name == "shadow_maps") {
      EXPECT_EQ(p.counters.at("maps_rendered"), 0.0);
    }
  }
  // A different map size is a different derived product: rebuilt.
  moved.passes["shadow_maps"] = {{"shadow_map_size", 512}};
  RenderOutput third = renderer().render(scene, moved);
  for (const auto& c : third.stats.cache) {
    if (c.what == "shadow_maps") {
      EXPECT_FALSE(c.hit);
    }
  }
}

// The GPU scene cache keeps the `capacity` most recently used scenes: with capacity 2, A B A hits A
// again, and A B C A has evicted it (least recently used first). The scenes' derived data (here the
// shadow maps) is kept alike, so alternating between scenes rebuilds nothing.
TEST(RenderCore, GpuSceneCacheKeepsTheMostRecentlyUsedScenes) {
  // The uploaded scene is kept per scene (LRU); the shadow maps live in one shared texture, so they are
  // reused only when the frame before rendered the same scene (FrameResources::refill).
  const Scene* last = nullptr;
  auto gpuHit = [&](const Scene& s) {
    const RenderOutput o = renderer().render(s, request(8));
    EXPECT_EQ(cacheHit(o, "shadow_maps"), last == &s) << "the shadow textures hold the last scene's maps";
    last = &s;
    return cacheHit(o, "gpu_scene");
  };
  Renderer& r = renderer();
  r.setGpuSceneCapacity(2);
  Scene a = umbraScene(1.f, "lru-a"), b = umbraScene(1.f, "lru-b"), c = umbraScene(1.f, "lru-c");
  EXPECT_FALSE(gpuHit(a));
  EXPECT_FALSE(gpuHit(b));
  EXPECT_TRUE(gpuHit(a));
  EXPECT_FALSE(gpuHit(c));  // evicts b, the least recently used
  EXPECT_TRUE(gpuHit(a));
  EXPECT_FALSE(gpuHit(b));
  r.setGpuSceneCapacity(1);  // shrinking evicts at once
  EXPECT_TRUE(gpuHit(b));
  EXPECT_FALSE(gpuHit(a));
  r.setGpuSceneCapacity(4);
}

// Issue 30: photon sets and splat grids are kept within a byte budget (radiantd --derived-cache-bytes;
// 4M photons took 2.4 GB at rest when only the scene count bounded them). Under a budget of one byte
// only the frame in use keeps its own: alternating scenes re-trace their photons; under a large one
// both sets stay and the third frame traces nothing.
TEST(RenderCore, PhotonSetsAreKeptWithinTheDerivedCacheBytes) {
  auto traced = [](const RenderOutput& o) {
    for (const auto& p : o.stats.passes)
      if (p.name == "photon_gi") return p.counters.at("photons_traced");
    ADD_FAILURE() << "no photon_gi pass";
    return -1.0;
  };
  Renderer& r = renderer();
  r.setGpuSceneCapacity(4);
  api::RenderRequest req = request(8);
  req.passes["photon_gi"] = {{"photons", 20000}};
  const Scene a = umbraScene(1.f, "derived-bytes-a"), b = umbraScene(1.f, "derived-bytes-b");
  r.setDerivedCacheBytes(std::size_t(1) << 30);
  EXPECT_EQ(traced(r.render(a, req)), 20000.0);
  EXPECT_EQ(traced(r.render(b, req)), 20000.0);
  EXPECT_EQ(traced(r.render(a, req)), 0.0) << "both photon sets fit in 1 GiB";
  r.setDerivedCacheBytes(1);  // drops every set of an earlier frame at once
  EXPECT_EQ(traced(r.render(b, req)), 20000.0);
  EXPECT_EQ(traced(r.render(b, req)), 0.0) << "the set of the frame before is kept while it is the only one";
  EXPECT_EQ(traced(r.render(a, req)), 20000.0);
  EXPECT_EQ(traced(r.render(b, req)), 20000.0) << "a's set pushed b's out";
  r.setDerivedCacheBytes(std::size_t(1) << 40);
}

// Issue 30: the splat buffer is at most 12.5% over its grid (it was the next power of two: 512 MiB for
// the 4M-photon Cornell box's 325 MB, all of it resident on llvmpipe), and a large set's buffer is not
// kept for a smaller one uploaded after it (over twice its size, it is reallocated).
TEST(RenderCore, TheSplatBufferFollowsItsGrid) {
  auto counters = [](const RenderOutput& o) {
    for (const auto& p : o.stats.passes)
      if (p.name == "photon_gi") return p.counters;
    ADD_FAILURE() << "no photon_gi pass";
    return std::map<std::string, double>{};
  };
  Renderer& r = renderer();
  const Scene a = umbraScene(1.f, "splat-buffer");
  std::vector<double> sizes;
  for (int photons : {10000, 300000, 10000}) {
    api::RenderRequest req = request(8);
    req.passes["photon_gi"] = {{"photons", photons}};
    const auto c = counters(r.render(a, req));
    ASSERT_GT(c.at("splat_bytes"), 0.0);
    EXPECT_GE(c.at("splat_buffer_bytes"), c.at("splat_bytes"));
    // 12.5%, or the 4 KiB granule of a small buffer
    EXPECT_LE(c.at("splat_buffer_bytes"), std::max(c.at("splat_bytes") + 4096.0, 1.125 * c.at("splat_bytes")))
        << photons << " photons";
    sizes.push_back(c.at("splat_buffer_bytes"));
  }
  EXPECT_GT(sizes[1], 10.0 * sizes[0]);
  EXPECT_EQ(sizes[2], sizes[0]) << "the 300k-photon buffer was kept for the 10k-photon grid";
}

// Issue 30, the memory accountant (FrameResources::makeRoom): under a target the process is over,
// what a frame does not use goes — other scenes' GPU copies, their photon sets and every resource the
// frame did not touch — and what a later frame rebuilds from that is the same image. Under a target it
// is under, nothing goes.
TEST(RenderCore, TheMemoryTargetReleasesWhatTheFrameDoesNotUse) {
  Renderer& r = renderer();
  r.setGpuSceneCapacity(4);
  r.setMemoryTarget(std::size_t(1) << 40);
  api::RenderRequest req = request(16, {"beauty"});
  req.passes["photon_gi"] = {{"photons", 20000}};
  const Scene a = umbraScene(1.f, "memory-a"), b = umbraScene(1.f, "memory-b");
  r.render(a, req);
  const RenderOutput first = r.render(b, req);
  const RenderOutput kept = r.render(a, req);
  EXPECT_TRUE(cacheHit(kept, "gpu_scene"));
  EXPECT_EQ(photonGiCounter(kept, "photons_traced"), 0.0) << "under the target every scene keeps its photons";
  EXPECT_EQ(kept.stats.memory.at("released_bytes").get<double>(), 0.0);
  EXPECT_GT(kept.stats.memory.at("resident_bytes").get<double>(), 0.0);
  EXPECT_GT(kept.stats.memory.at("resource_bytes").get<double>(), 0.0);

  r.setMemoryTarget(1);  // always over: every frame's end releases what that frame did not use
  const RenderOutput released = r.render(a, req);
  EXPECT_EQ(released.stats.memory.at("target_bytes").get<double>(), 1.0);
  const RenderOutput rebuilt = r.render(b, req);
  EXPECT_FALSE(cacheHit(rebuilt, "gpu_scene")) << "b's GPU copy went with a's frame";
  EXPECT_EQ(photonGiCounter(rebuilt, "photons_traced"), 20000.0) << "b's photon set went with a's frame";
  EXPECT_LT(testing::maxAbsDifference(aov(first, "beauty"), aov(rebuilt, "beauty")), 1e-5f)
      << "b rebuilt after the release renders as before";
  const RenderOutput again = r.render(b, req);
  EXPECT_TRUE(cacheHit(again, "gpu_scene")) << "the frame's own scene stays";
  EXPECT_EQ(photonGiCounter(again, "photons_traced"), 0.0) << "the frame's own photons stay";
  r.setMemoryTarget(std::size_t(1) << 40);
}

// Issue 30: over the memory target, photon_gi lets its records go once the splat grid is built. The
// grid stays resident, so the next frame traces nothing and renders the same image; a frame that needs
// another grid (another C) traces the photons again.
TEST(RenderCore, PhotonRecordsReleasedUnderTheMemoryTargetAreTracedAgainWhenNeeded) {
  Renderer& r = renderer();
  const Scene a = umbraScene(1.f, "records-released");
  api::RenderRequest req = request(16, {"beauty"});
  req.passes["photon_gi"] = {{"photons", 20000}};
  r.setMemoryTarget(1);
  const RenderOutput first = r.render(a, req);
  EXPECT_EQ(photonGiCounter(first, "photons_traced"), 20000.0);
  EXPECT_EQ(photonGiCounter(first, "records_released"), 1.0);
  EXPECT_GT(photonGiCounter(first, "records"), 0.0);
  const RenderOutput second = r.render(a, req);
  EXPECT_EQ(photonGiCounter(second, "photons_traced"), 0.0) << "the grid was resident: nothing to trace";
  EXPECT_EQ(photonGiCounter(second, "records"), photonGiCounter(first, "records")) << "the grid's own count";
  EXPECT_LT(testing::maxAbsDifference(aov(first, "beauty"), aov(second, "beauty")), 1e-6f);
  req.passes["photon_gi"] = {{"photons", 20000}, {"C", 12.0}};
  EXPECT_EQ(photonGiCounter(r.render(a, req), "photons_traced"), 20000.0) << "another grid needs the records again";
  r.setMemoryTarget(std::size_t(1) << 40);
  req.passes["photon_gi"] = {{"photons", 20000}};
  const RenderOutput kept = r.render(a, req);
  EXPECT_EQ(photonGiCounter(kept, "records_released"), 0.0) << "under the target the records stay";
}

// Issue 30, admission: a frame whose photon records would take the process over the memory limit
// even after the release is refused before tracing — a 503 memory-busy naming the photon count — and
// the renderer goes on rendering; without a limit the same frame renders.
TEST(RenderCore, AFrameOverTheMemoryLimitIsRefusedBeforeItAllocates) {
  Renderer& r = renderer();
  const Scene a = umbraScene(1.f, "memory-limit");
  api::RenderRequest req = request(8, {"beauty"});
  req.passes["photon_gi"] = {{"photons", 20000}};
  r.render(a, req);  // compiles the shaders, allocates the frame's targets and traces 20k photons
  req.passes["photon_gi"] = {{"photons", 2000000}};  // about 380 MB of records and splats estimated
  r.setMemoryLimit(FrameResources::residentBytes() + (std::size_t(32) << 20));
  const api::ApiError e = testing::thrownApiError([&] { r.render(a, req); });  // 2M photons 32 MiB below the limit
  EXPECT_EQ(e.status, 503);
  EXPECT_EQ(e.type, "memory-busy");
  EXPECT_EQ(e.pointer, "/passes/photon_gi/photons");
  EXPECT_NE(std::string(e.what()).find("--memory-limit-bytes"), std::string::npos) << e.what();
  EXPECT_EQ(MemoryClaims::process().claimed(), 0u) << "a refused frame's claim ends with it";
  req.passes["photon_gi"] = {{"photons", 20000}};  // traced before the limit: renders
  EXPECT_NO_THROW(r.render(a, req));
  EXPECT_EQ(MemoryClaims::process().claimed(), 0u) << "a frame's claim ends with it";
  // A scene's upload is admitted like a pass's allocation: a 4096^2 texture (85 MiB with its mips)
  // is refused before it is uploaded, at /scene.
  Scene big = umbraScene(1.f, "memory-limit-texture");
  Texture t;
  t.width = t.height = 4096;
  t.rgba8.assign(std::size_t(4096) * 4096 * 4, 128);
  big.textures.push_back(std::move(t));
  r.setMemoryLimit(FrameResources::residentBytes() + (std::size_t(32) << 20));
  const api::ApiError upload = testing::thrownApiError([&] { r.render(big, req); });
  EXPECT_EQ(upload.status, 503);
  EXPECT_EQ(upload.type, "memory-busy");
  EXPECT_EQ(upload.pointer, "/scene");
  EXPECT_EQ(MemoryClaims::process().claimed(), 0u);
  r.setMemoryLimit(0);
}

TEST(RenderCore, SharedDerivedResourcesHoldTheSceneRenderedLast) {
  // Two scenes whose shadows differ (the occluder left or right of the light), rendered A, B, A with
  // both kept uploaded: the third frame must equal the first. The shadow maps live in one texture that
  // every scene renders into; a derived-data cache that kept both digests used to call the third
  // frame's maps valid and shade A with B's shadow (FrameResources::refill). Rasterisation is
  // deterministic on one device, so equal means equal to float rounding.
  auto scene = [](float x, const char* digest) {
    SceneBuilder b = planeScene();
    int grey = b.material(lambertian(glm::vec3(0.5f)));
    b.quad({x, 0.5f, 0}, {0.4f, 0, 0}, {0, 0, 0.4f}, grey, "occluder");
    b.pointLight({0, 1, 0}, glm::pi<float>());
    b.topDownOrtho(5.f, 1.5f);
    return b.build(digest);
  };
  Scene a = scene(-0.6f, "shared-a"), b = scene(0.6f, "shared-b");
  Renderer& r = renderer();
  r.setGpuSceneCapacity(4);
  const Image first = aov(r.render(a, request(32, {"direct"})), "direct");
  const Image other = aov(r.render(b, request(32, {"direct"})), "direct");
  const Image again = aov(r.render(a, request(32, {"direct"})), "direct");
  EXPECT_GT(testing::maxAbsDifference(first, other), 0.5f) << "the two scenes' shadows differ";
  EXPECT_LT(testing::maxAbsDifference(first, again), 1e-5f) << "A after B is shaded with A's shadow maps";
  // A frame that fails after every pass prepared (cancelled before the first execute): B's prepare found
  // the maps holding A's, so from then on they hold nothing (FrameResources::refill) although B's were
  // never drawn, and the next frame of B must render them.
  const std::atomic<bool> cancelled{true};
  EXPECT_THROW(r.render(b, request(32, {"direct"}), &cancelled), api::ApiError);
  const Image afterCancel = aov(r.render(b, request(32, {"direct"})), "direct");
  EXPECT_LT(testing::maxAbsDifference(other, afterCancel), 1e-5f) << "B after a cancelled B frame has B's shadows";
}

TEST(RenderCore, GrazingViewsStayFinite) {
  // A camera almost in the plane of the floor: NdotV -> 0 everywhere.
  Scene scene = planeScene().pointLight({0, 1, 0}, 3.f).build("grazing");
  api::RenderRequest req = request(64, {"beauty", "direct", "normal", "depth", "albedo"});
  req.camera = lookAt({0, 1e-4f, 15.f}, {0, 0, 0}, {0, 1, 0}, 60.f);
  RenderOutput out = renderer().render(scene, req);
  expectAllFinite(out);
  for (float v : aov(out, "direct").pixels) EXPECT_GE(v, 0.f);
}

// The AOV table (api/Aovs.cpp) is enforced, not advisory.
TEST(AovTable, CompareWithoutGroundTruthIsRefusedNotScoredAgainstBeauty) {
  Scene scene = planeScene().pointLight({0, 1, 0}, glm::pi<float>()).topDownOrtho(5.f, 1.f).build("aov-compare");
  for (const char* aov : {"specular", "albedo"}) {
    api::RenderRequest req = request(16, {"beauty"});
    req.compare = api::CompareSpec{"reference", aov, 1, 1};
    try {
      renderer().render(scene, req);
      ADD_FAILURE() << "compare.aov " << aov << " was scored";
    } catch (const api::ApiError& e) {
      EXPECT_EQ(e.status, 422) << aov;
      EXPECT_EQ(e.pointer, "/compare/aov") << aov;
      EXPECT_NE(std::string(e.what()).find("no ground truth"), std::string::npos) << e.what();
    }
  }
  // An AOV with a ground truth is scored against its own reference mode.
  api::RenderRequest req = request(16, {"direct"});
  req.compare = api::CompareSpec{"reference", "direct", 1, 1};
  const RenderOutput out = renderer().render(scene, req);
  EXPECT_EQ(out.stats.metrics.at("reference_mode"), "direct");
}

TEST(AovTable, FrameResourcesRefuseAnAovInAnotherFormatOrRespecifiedWithinAFrame) {
  renderer();  // a current GL context
  gl::ShaderLibrary shaders;
  FrameResources res(shaders);
  res.texture("beauty", GL_TEXTURE_2D, GL_RGBA32F, 8, 8);
  res.texture("beauty", GL_TEXTURE_2D, GL_RGBA32F, 8, 8);  // the same declaration: reused
  const std::string resized = testing::thrownMessage<std::logic_error>(
      [&] { res.texture("beauty", GL_TEXTURE_2D, GL_RGBA32F, 16, 16); });
  EXPECT_NE(resized.find("same frame"), std::string::npos) << resized;
  const std::string format = testing::thrownMessage<std::logic_error>(
      [&] { res.texture("ao", GL_TEXTURE_2D, GL_RGBA16F, 8, 8); });
  EXPECT_NE(format.find("R32F"), std::string::npos) << format;
  // Resources that are no AOV's are free to change.
  res.texture("scratch", GL_TEXTURE_2D, GL_RGBA16F, 8, 8);
  res.texture("scratch", GL_TEXTURE_2D, GL_RGBA16F, 8, 8);
}

// Declared resource access (FrameResources::beginPass, FramePlanner's declaredAccess): inside a pass a
// shared resource is touched only as the pass's TechniqueInfo declares, nothing is allocated in
// execute(), and a pass cannot re-declare beauty in another spec (which would drop the light earlier
// passes accumulated in it). Each breach is a std::logic_error naming the pass and the resource.
TEST(AovTable, APassThatTouchesAnUndeclaredResourceFails) {
  renderer();  // a current GL context
  gl::ShaderLibrary shaders;
  FrameResources res(shaders);
  res.setSharedResources({"beauty", "direct", "ao", "specular", kEnvironmentMap});
  // What the Renderer allocates before any pass (allocateDeclaredOutputs).
  res.texture("beauty", GL_TEXTURE_2D, GL_RGBA32F, 8, 8);
  res.texture("direct", GL_TEXTURE_2D, GL_RGBA32F, 8, 8);
  const TechniqueInfo ao{"ambient_occlusion", "", {}, {"direct"}, {"ao"}, /*addsToBeauty=*/false, false};
  res.beginPass(ao.name, declaredAccess(ao), FrameResources::Phase::Prepare);
  res.texture("ao", GL_TEXTURE_2D, GL_R32F, 8, 8);         // its output
  res.texture("direct");                                   // its optional input
  res.texture("ao_scratch", GL_TEXTURE_2D, GL_R32F, 4, 4);  // its own intermediate: not shared
  const std::string used = testing::thrownMessage<std::logic_error>([&] { res.texture("beauty"); });
  EXPECT_NE(used.find("pass ambient_occlusion used 'beauty'"), std::string::npos) << used;
  EXPECT_NE(used.find("direct:Read"), std::string::npos) << used;  // and says what it did declare
  res.endPass();

  res.beginPass(ao.name, declaredAccess(ao), FrameResources::Phase::Execute);
  res.texture("ao");
  res.markWritten("ao");
  const std::string readOnly = testing::thrownMessage<std::logic_error>([&] { res.markWritten("direct"); });
  EXPECT_NE(readOnly.find("declares Read only"), std::string::npos) << readOnly;
  const std::string undeclared = testing::thrownMessage<std::logic_error>([&] { res.markWritten("specular"); });
  EXPECT_NE(undeclared.find("pass ambient_occlusion wrote 'specular'"), std::string::npos) << undeclared;
  const std::string allocated = testing::thrownMessage<std::logic_error>(
      [&] { res.texture("ao_blurred", GL_TEXTURE_2D, GL_R32F, 8, 8); });
  EXPECT_NE(allocated.find("in execute()"), std::string::npos) << allocated;
  const std::string buffer = testing::thrownMessage<std::logic_error>([&] { res.buffer("ao_samples", 64); });
  EXPECT_NE(buffer.find("in execute()"), std::string::npos) << buffer;
  EXPECT_EQ(res.passWrites(), (std::set<std::string>{"ao"}));
  res.endPass();

  // A pass that adds to beauty sees the Renderer's beauty; asking for another size throws and keeps it.
  const TechniqueInfo caustics{"caustics", "", {}, {}, {"caustics"}, /*addsToBeauty=*/true, false};
  res.beginPass(caustics.name, declaredAccess(caustics), FrameResources::Phase::Prepare);
  const GLuint beautyId = res.texture("beauty").id();
  const std::string resized = testing::thrownMessage<std::logic_error>(
      [&] { res.texture("beauty", GL_TEXTURE_2D, GL_RGBA32F, 16, 16); });
  EXPECT_NE(resized.find("by pass caustics"), std::string::npos) << resized;
  res.endPass();
  EXPECT_EQ(res.texture("beauty").id(), beautyId);
  EXPECT_EQ(res.texture("beauty").width(), 8);
  // Outside a pass scope (the Renderer, readback) nothing is checked.
  EXPECT_NO_THROW(res.texture("specular", GL_TEXTURE_2D, GL_RGBA32F, 8, 8));
}

// The frame's typed blackboard (FrameResources::publish, product): a product that is not a texture
// (photon_gi's grid, specular's maps) travels under the publisher's declared output and the reader's
// declared input, and is read back as the type it was published as.
TEST(AovTable, ProductsTravelUnderDeclaredNamesAsTheTypeTheyWerePublishedAs) {
  renderer();  // a current GL context
  gl::ShaderLibrary shaders;
  FrameResources res(shaders);
  res.setSharedResources({"beauty", "photon_grid", "specular_maps"});
  struct Grid {
    int cells = 0;
  };
  const TechniqueInfo reader{"specular", "", {}, {"photon_grid"}, {"specular", "specular_maps"}, true, true};
  const TechniqueInfo writer{"photon_gi", "", {}, {}, {"indirect", "photon_grid"}, true, true};
  res.beginPass(reader.name, declaredAccess(reader), FrameResources::Phase::Execute);
  EXPECT_EQ(res.product<Grid>("photon_grid"), nullptr) << "nothing published yet";
  const std::string wrote = testing::thrownMessage<std::logic_error>([&] { res.publish("photon_grid", Grid{1}); });
  EXPECT_NE(wrote.find("declares Read only"), std::string::npos) << wrote;
  res.endPass();
  res.beginPass(writer.name, declaredAccess(writer), FrameResources::Phase::Prepare);
  res.publish("photon_grid", Grid{27});
  const std::string undeclared =
      testing::thrownMessage<std::logic_error>([&] { res.publish("specular_maps", Grid{1}); });
  EXPECT_NE(undeclared.find("pass photon_gi wrote 'specular_maps'"), std::string::npos) << undeclared;
  res.endPass();
  EXPECT_TRUE(res.written("photon_grid"));
  res.beginPass(reader.name, declaredAccess(reader), FrameResources::Phase::Execute);
  ASSERT_NE(res.product<Grid>("photon_grid"), nullptr);
  EXPECT_EQ(res.product<Grid>("photon_grid")->cells, 27);
  const std::string type = testing::thrownMessage<std::logic_error>([&] { res.product<int>("photon_grid"); });
  EXPECT_NE(type.find("'photon_grid' holds a"), std::string::npos) << type;
  res.endPass();
  // A pass that does not declare the name cannot read it.
  const TechniqueInfo other{"direct", "", {}, {}, {"direct"}, true, true};
  res.beginPass(other.name, declaredAccess(other), FrameResources::Phase::Execute);
  const std::string used = testing::thrownMessage<std::logic_error>([&] { res.product<Grid>("photon_grid"); });
  EXPECT_NE(used.find("pass direct used 'photon_grid'"), std::string::npos) << used;
  res.endPass();
  // Products are read in execute(): in prepare() the frame graph promises no order.
  res.beginPass(reader.name, declaredAccess(reader), FrameResources::Phase::Prepare);
  const std::string early = testing::thrownMessage<std::logic_error>([&] { res.product<Grid>("photon_grid"); });
  EXPECT_NE(early.find("in prepare()"), std::string::npos) << early;
  res.endPass();
  // A product declared as published in prepare() (prepare_outputs), whose readers the frame graph does
  // not order after its producer, cannot be written in execute().
  TechniqueInfo early_writer = writer;
  early_writer.prepareOutputs = {"photon_grid"};
  res.beginPass(writer.name, declaredAccess(early_writer), FrameResources::Phase::Prepare);
  EXPECT_NO_THROW(res.publish("photon_grid", Grid{28}));
  res.endPass();
  res.beginPass(writer.name, declaredAccess(early_writer), FrameResources::Phase::Execute);
  const std::string late = testing::thrownMessage<std::logic_error>([&] { res.publish("photon_grid", Grid{29}); });
  EXPECT_NE(late.find("in execute(), which it declares written in prepare()"), std::string::npos) << late;
  res.endPass();
}

// The frame graph orders passes from their declarations (FramePlanner's executionOrder; FrameGraph.* in
// the unit tier checks the orders): the registry reversed, which reverses every tie (the adds into
// beauty among them), renders the same frames up to the order of beauty's float sums. The frames cover
// every ordering rule: the G-buffer and shadow maps before their readers, specular's maps before
// caustics, photon_gi's grid (published in prepare) read by specular, light_volumes and env_diffuse
// among the adds, blended surfaces after the adds and the media after everything. Each frame's passes
// are the same, and no AOV moves by more than float rounding.
TEST(FrameGraph, TheRegistryReversedRendersTheSameFrames) {
  struct Case {
    std::string scene;
    nlohmann::json passes;
    std::vector<std::string> aovs;
  };
  const std::vector<Case> cases = {
      {"cornell_glass", nlohmann::json::object(), {"beauty", "direct", "specular", "caustics", "indirect"}},
      {"cornell_glass", {{"light_volumes", nlohmann::json::object()}}, {"beauty", "light_volumes"}},
      {"cornell_box", {{"env_diffuse", nlohmann::json::object()}}, {"beauty", "indirect_diffuse"}},
      {"explosion", nlohmann::json::object(), {"beauty", "media", "media_transmittance"}},
  };
  struct Restore {
    ~Restore() { renderer().setTechniques(createTechniques()); }
  } restore;
  for (const Case& c : cases) {
    Scene scene = loadBuiltinScene(c.scene);
    if (c.scene == "explosion") scene.materials.at(2).alphaMode = AlphaMode::Blend;  // the crate: transparency
    api::RenderRequest req = request(40, c.aovs);
    req.passes.erase("shadow_maps");
    for (const auto& [name, params] : c.passes.items()) req.passes[name] = params;
    renderer().setTechniques(createTechniques());
    const RenderOutput forwards = renderer().render(scene, req);
    auto reversed = createTechniques();
    std::reverse(reversed.begin(), reversed.end());
    renderer().setTechniques(std::move(reversed));
    const RenderOutput backwards = renderer().render(scene, req);
    std::set<std::string> pf, pb;
    for (const auto& p : forwards.stats.passes) pf.insert(p.name);
    for (const auto& p : backwards.stats.passes) pb.insert(p.name);
    EXPECT_EQ(pf, pb) << c.scene;
    if (c.scene == "explosion") { EXPECT_TRUE(pf.count("transparency") && pf.count("spherical_billboards")); }
    if (c.scene == "cornell_glass" && c.passes.empty()) { EXPECT_TRUE(pf.count("caustics") && pf.count("photon_gi")); }
    std::string order;
    for (const auto& p : backwards.stats.passes) order += (order.empty() ? "" : " ") + p.name;
    for (const std::string& name : c.aovs) {
      const Image& a = aov(forwards, name);
      const Image& b = aov(backwards, name);
      ASSERT_EQ(a.pixels.size(), b.pixels.size());
      double worst = 0, peak = 0;
      for (std::size_t i = 0; i < a.pixels.size(); ++i) {
        worst = std::max(worst, std::abs(double(a.pixels[i]) - b.pixels[i]) / (1e-3 + std::abs(double(a.pixels[i]))));
        peak = std::max(peak, std::abs(double(a.pixels[i])));
      }
      EXPECT_GT(peak, 0.0) << c.scene << " " << name;
      EXPECT_LT(worst, 1e-4) << c.scene << " " << name << " (backwards order: " << order << ")";
    }
  }
}

// Beauty starts every frame at zero (allocateDeclaredOutputs): no pass initialises it. A frame without
// the direct pass, which used to, holds exactly what its other passes add (here photon_gi's indirect
// light), not that on top of the previous frame's beauty.
TEST(FrameGraph, AFrameWithoutTheDirectPassStartsFromZero) {
  const Scene scene = loadBuiltinScene("cornell_box");
  api::RenderRequest lit = request(24, {"beauty"});
  lit.passes.erase("shadow_maps");
  api::RenderRequest unlit = lit;
  unlit.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"beauty", "indirect"}, false}};
  unlit.disabledPasses.insert("direct");
  renderer().render(scene, lit);  // leaves a lit beauty in the texture
  const RenderOutput out = renderer().render(scene, unlit);
  EXPECT_FALSE(std::any_of(out.stats.passes.begin(), out.stats.passes.end(), [](const auto& p) { return p.name == "direct"; }));
  const Image& beauty = aov(out, "beauty");
  const Image& indirect = aov(out, "indirect");
  double peak = 0, worst = 0;
  for (std::size_t p = 0; p < std::size_t(beauty.width) * beauty.height; ++p)
    for (int c = 0; c < 3; ++c) {
      peak = std::max(peak, double(indirect.pixels[p * indirect.channels + c]));
      worst = std::max(worst, std::abs(double(beauty.pixels[p * beauty.channels + c]) - indirect.pixels[p * indirect.channels + c]));
    }
  EXPECT_GT(peak, 0.01);
  EXPECT_LT(worst, 1e-6 * std::max(1.0, peak));
}

// The Renderer allocates the planned passes' declared outputs and uploads the environment map as a frame
// resource once per map: a second frame with the same map is a cache hit, and the direct pass (which
// reads it, declared) shows the same sky in both.
TEST(AovTable, TheEnvironmentMapIsAFrameResourceUploadedOncePerMap) {
  Scene scene = planeScene().topDownOrtho(5.f, 1.f).build("env-frame-resource");
  Image env = Image::make("environment", 8, 4, 3);
  for (std::size_t i = 0; i < env.pixels.size(); ++i) env.pixels[i] = 0.25f + 0.01f * static_cast<float>(i % 7);
  api::RenderRequest req = request(16, {"beauty"});
  req.environment = "sha256:env-frame-resource";
  FrameInputs inputs;
  inputs.environment = &env;
  auto envEvents = [](const RenderOutput& out) {
    std::vector<bool> hits;
    for (const auto& e : out.stats.cache)
      if (e.what == "environment_map") hits.push_back(e.hit);
    return hits;
  };
  const RenderOutput first = renderer().render(scene, req, nullptr, inputs);
  const RenderOutput second = renderer().render(scene, req, nullptr, inputs);
  EXPECT_EQ(envEvents(first), std::vector<bool>{false});
  EXPECT_EQ(envEvents(second), std::vector<bool>{true});
  EXPECT_EQ(testing::maxAbsDifference(aov(first, "beauty"), aov(second, "beauty")), 0.f);
}

TEST(AovTable, MaterialAovCarriesTransmission) {
  // Two quads side by side: a rough dielectric with KHR_materials_transmission 0.75 and an opaque one.
  // The material AOV is metallic, roughness, occlusion, transmission (material.R/G/B/A), read back per
  // pixel exactly as the G-buffer stores it (RGBA16F: 0.75, 0.25, 0.5 are exact in half floats).
  SceneBuilder b;
  Material glass = lambertian();
  glass.roughnessFactor = 0.5f;
  glass.metallicFactor = 0.25f;
  glass.transmissionFactor = 0.75f;
  Material opaque = lambertian();
  b.quad({-5, 0, 0}, {5, 0, 0}, {0, 0, -10}, b.material(glass), "glass");
  b.quad({5, 0, 0}, {5, 0, 0}, {0, 0, -10}, b.material(opaque), "opaque");
  b.directionalLight({0, -1, 0}, 1.f);
  api::RenderRequest req = request(32, {"beauty", "material"});
  req.camera = lookAt({0, 10, 0}, {0, 0, 0}, {0, 0, -1}, 90.f);
  const RenderOutput out = renderer().render(b.build("material-aov"), req);
  const Image& m = aov(out, "material");
  ASSERT_EQ(m.channels, 4);
  EXPECT_EQ(m.at(8, 16)[0], 0.25f);   // metallic
  EXPECT_EQ(m.at(8, 16)[1], 0.5f);    // roughness
  EXPECT_EQ(m.at(8, 16)[2], 1.f);     // occlusion (none)
  EXPECT_EQ(m.at(8, 16)[3], 0.75f);   // transmission
  EXPECT_EQ(m.at(24, 16)[3], 0.f);
  // And the EXR names it material.A.
  const std::string exr = io::encodeExr({m}, false);
  const std::string path = ::testing::TempDir() + "/material.exr";
  io::writeFile(path, exr);
  auto in = OIIO::ImageInput::open(path);
  ASSERT_TRUE(in);
  const auto& names = in->spec().channelnames;
  EXPECT_EQ(std::set<std::string>(names.begin(), names.end()),
            (std::set<std::string>{"material.R", "material.G", "material.B", "material.A"}));
}

TEST(ImageIO, ExrChannelNamesComeFromTheAovTable) {
  Image ao = Image::make("ao", 2, 1, 1), normal = Image::make("normal", 2, 1, 3), beauty = Image::make("beauty", 2, 1, 3);
  const std::string exrPath = ::testing::TempDir() + "/names.exr";
  io::writeFile(exrPath, io::encodeExr({beauty, ao, normal}, false));
  auto in = OIIO::ImageInput::open(exrPath);
  ASSERT_TRUE(in);
  const auto& stored = in->spec().channelnames;
  // EXR keeps channels sorted by name; compare as sets.
  EXPECT_EQ(std::set<std::string>(stored.begin(), stored.end()),
            (std::set<std::string>{"R", "G", "B", "ao.Y", "normal.R", "normal.G", "normal.B"}));
}

TEST(ImageIO, PngClampsAndExrKeepsLayers) {
  Image img = Image::make("beauty", 4, 1, 3);
  const float values[4] = {-1.f, 0.5f, 2.f, 1e30f};
  for (int x = 0; x < 4; ++x)
    for (int c = 0; c < 3; ++c) img.at(x, 0)[c] = values[x];
  const std::string png = io::encodePng(img, 0.f);
  const std::string path = ::testing::TempDir() + "/clamp.png";
  io::writeFile(path, png);
  Image back = io::readImage(path);
  EXPECT_EQ(back.at(0, 0)[0], 0.f);                                   // negative clamps to 0
  EXPECT_NEAR(back.at(1, 0)[0], io::linearToSrgb(0.5f), 1.f / 255);  // sRGB transfer
  EXPECT_EQ(back.at(2, 0)[0], 1.f);                                   // over-range saturates, never wraps
  EXPECT_EQ(back.at(3, 0)[0], 1.f);
  // Exposure +1 EV doubles the linear value before the transfer.
  io::writeFile(path, io::encodePng(img, 1.f));
  EXPECT_EQ(io::readImage(path).at(1, 0)[0], 1.f);

  Image depth = Image::make("depth", 4, 1, 1);
  depth.pixels = {1.f, 2.f, 3.f, 4.f};
  const std::string exrPath = ::testing::TempDir() + "/layers.exr";
  io::writeFile(exrPath, io::encodeExr({img, depth}, false));
  Image exr = io::readImage(exrPath);
  EXPECT_EQ(exr.at(1, 0)[0], 0.5f);  // float EXR is exact
  EXPECT_EQ(exr.at(2, 0)[1], 2.f);   // and keeps values above 1
}

}  // namespace
}  // namespace radiant

namespace radiant {
namespace {

TEST(ImageIO, PngQuantisationIsTheRoundedSrgbTransfer) {
  // Every code the threshold search produces equals lround(255 sRGB(v)), on a dense ramp over [0, 1]
  // and through every boundary's neighbourhood.
  Image img = Image::make("beauty", 4096, 1, 3);
  for (int x = 0; x < 4096; ++x)
    for (int c = 0; c < 3; ++c) img.at(x, 0)[c] = (x + 0.37f * c) / 4095.f;
  const std::string path = ::testing::TempDir() + "/ramp.png";
  io::writeFile(path, io::encodePng(img, 0.f));
  const Image back = io::readImage(path);
  int mismatches = 0;
  for (int x = 0; x < 4096; ++x)
    for (int c = 0; c < 3; ++c) {
      const float v = std::min(img.at(x, 0)[c], 1.f);
      const long expected = std::lround(io::linearToSrgb(v) * 255.f);
      const long got = std::lround(back.at(x, 0)[c] * 255.f);
      // Exactly at a threshold, float rounding may land either side: allow that, and only that.
      if (got != expected) {
        ++mismatches;
        EXPECT_LE(std::abs(got - expected), 1);
      }
    }
  EXPECT_LE(mismatches, 2);
}

}  // namespace
}  // namespace radiant

namespace radiant {
namespace {

// Real progress: the frame's progress follows the passes and, inside the reference pass, its tiles;
// it never decreases and ends at 1.
TEST(RenderCore, ProgressFollowsPassesAndReferenceTiles) {
  std::mutex m;
  std::vector<double> seen;
  FrameInputs in;
  in.progress = [&](double f) {
    std::lock_guard lock(m);
    seen.push_back(f);
  };
  api::RenderRequest req = request(64, {"beauty", "reference"});
  req.passes["reference"] = {{"spp", 4}};  // 64x64 = 16 tiles of 16x16
  renderer().render(umbraScene(1.f, "progress"), req, nullptr, in);
  ASSERT_FALSE(seen.empty());
  for (std::size_t i = 1; i < seen.size(); ++i) EXPECT_GE(seen[i], seen[i - 1]) << i;
  EXPECT_EQ(seen.back(), 1.0);
  // The reference pass alone reports 16 tile fractions: many distinct values inside (0, 0.95).
  std::set<double> inner;
  for (double v : seen)
    if (v > 0.0 && v < 0.95) inner.insert(v);
  EXPECT_GE(inner.size(), 12u);
}

// A frame no light reaches is flagged, with the cause; a lit one is not.
TEST(RenderCore, BlackFrameIsWarnedWithItsCause) {
  SceneBuilder b = planeScene(1.f);
  api::RenderRequest req = request(16);
  req.defaultLighting = false;
  RenderOutput dark = renderer().render(b.build("unlit-plane"), req);
  ASSERT_EQ(dark.stats.lighting, "none");
  const auto hasBlack = [](const RenderOutput& o) {
    return std::any_of(o.stats.warnings.begin(), o.stats.warnings.end(),
                       [](const std::string& w) { return w.rfind("black frame", 0) == 0; });
  };
  EXPECT_TRUE(hasBlack(dark));
  bool named = false;
  for (const auto& w : dark.stats.warnings) named = named || w.find("no lights") != std::string::npos;
  EXPECT_TRUE(named);
  RenderOutput lit = renderer().render(umbraScene(1.f, "umbra-lit"), request(16));
  EXPECT_FALSE(hasBlack(lit));
}

// Supersampling (RenderRequest::supersampling = k): the passes render k x k samples per pixel, at the
// centres ((i + 1/2) / k) of the pixel's cells, and readback averages radiance over them, so a pixel
// half covered by an edge gets the covered fraction of the samples, as the reference's pixel integral
// gets the covered area. An unlit quad of base colour c = 0.8 (KHR_materials_unlit: radiance c,
// nothing lights it) over a black sky, its right edge at x = 0.07 inside pixel column 4, which spans
// x in [0, 0.25] (8 pixels over [-1, 1]): sample columns at x = 0.125 (k = 1), 0.0625 and 0.1875
// (k = 2), 0.03125 + 0.0625 i (k = 4) lie left of the edge 0, 1 and 1 times out of 1, 2 and 4, so the
// column's beauty is exactly 0, c/2 and c/4. Geometry is not averaged: depth is the sample nearest
// the centre, 0 (sky) or 10 (the quad, seen from z = 10), never a blend of the two.
TEST(RenderCore, SupersamplingAveragesRadianceOverThePixelAndKeepsGeometryUnblended) {
  SceneBuilder b;
  Material unlit;
  unlit.baseColorFactor = glm::vec4(0.8f, 0.8f, 0.8f, 1.f);
  unlit.unlit = true;
  const int mat = b.material(unlit);
  const float edge = 0.07f, left = -3.f;
  b.quad({0.5f * (edge + left), 0, 0}, {0.5f * (edge - left), 0, 0}, {0, 3.f, 0}, mat, "card");  // normal +z
  b.scene().camera = testing::orthoCameraAlongZ(1.f);
  const Scene scene = b.build();
  const float expected[] = {0.f, 0.4f, 0.f, 0.2f};  // by k = 1, 2, (3 unused), 4
  for (int k : {1, 2, 4}) {
    SCOPED_TRACE(k);
    api::RenderRequest req = request(8, {"beauty", "depth"});
    req.supersampling = k;
    req.defaultLighting = false;
    const RenderOutput out = renderer().render(scene, req);
    EXPECT_EQ(out.stats.supersampling, k);
    const Image& beauty = aov(out, "beauty");
    const Image& depth = aov(out, "depth");
    ASSERT_EQ(beauty.width, 8);
    ASSERT_EQ(depth.height, 8);
    for (int y = 0; y < 8; ++y) {
      EXPECT_NEAR(beauty.at(3, y)[0], 0.8f, 1e-3f) << "fully covered column";
      EXPECT_NEAR(beauty.at(4, y)[0], expected[k - 1], 1e-3f) << "the edge's column, row " << y;
      EXPECT_NEAR(beauty.at(5, y)[0], 0.f, 1e-6f) << "sky column";
      for (int x = 0; x < 8; ++x) {
        const float d = depth.at(x, y)[0];
        EXPECT_TRUE(d == 0.f || std::abs(d - 10.f) < 1e-3f) << "depth " << d << " at " << x << "," << y;
      }
    }
  }
}

// The cap: k^2 width height stays within 4096^2 (the largest frame at one sample), and a frame that
// runs the reference pass is not supersampled.
TEST(RenderCore, SupersamplingIsCappedByTheFrameMemoryAndOffForTheReferencePass) {
  EXPECT_EQ(rasterSupersampling(2, 128, 128, false), 2);
  EXPECT_EQ(rasterSupersampling(4, 1024, 1024, false), 4);
  EXPECT_EQ(rasterSupersampling(4, 2048, 2048, false), 2);
  EXPECT_EQ(rasterSupersampling(2, 4096, 4096, false), 1);
  EXPECT_EQ(rasterSupersampling(3, 4096, 1024, false), 2);
  EXPECT_EQ(rasterSupersampling(2, 128, 128, true), 1);
  EXPECT_EQ(rasterSupersampling(9, 16, 16, false), 4);
}

// Finite output (issue 30), the stats half of it (no GL: readback's results are given): an AOV whose
// NaN/Inf values readback zeroed is warned of with the passes that wrote it; every half-float EXR
// output counts, per AOV, the values beyond 65504 that io::encodeExr writes as 65504; a float EXR or a
// PNG of the same AOV counts nothing.
TEST(RenderCore, ZeroedValuesNameTheirPassesAndHalfExrClampsAreCountedPerOutputAndAov) {
  RenderOutput out;
  Image beauty = Image::make("beauty", 2, 2, 3);
  beauty.pixels = {1e6f, 2.f, 3.f, 70000.f, 65504.f, -65505.f, 0.f, 1.f, 1e15f, 5.f, 6.f, 7.f};  // 4 beyond
  Image direct = Image::make("direct", 2, 2, 3);
  direct.pixels = {1.f, 2.f, 3.f, 4.f, 5.f, 6.f, 7.f, 8.f, 9.f, 10.f, 11.f, 1e5f};  // 1 beyond
  Image depth = Image::make("depth", 2, 2, 1);
  depth.pixels = {1.f, 2.f, 3.f, 4.f};
  out.aovs = {beauty, direct, depth};
  api::RenderRequest req;
  req.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"beauty", "direct", "depth"}, true},
                 api::OutputSpec{api::ImageFormat::Exr, {"beauty"}, false},
                 api::OutputSpec{api::ImageFormat::Png, {"beauty"}, true},
                 api::OutputSpec{api::ImageFormat::Exr, {"direct"}, true}};
  const std::vector<ZeroedValues> zeroed = {{"beauty", 39, {"direct", "specular"}}, {"depth", 2, {}}};
  reportOutputRange(out, zeroed, req);

  ASSERT_EQ(out.stats.clampedValues.size(), 3u);
  const auto is = [](const api::ClampedValues& c, std::size_t output, const char* aov, std::size_t count) {
    return c.output == output && c.aov == aov && c.count == count && c.limit == 65504.0;
  };
  EXPECT_TRUE(is(out.stats.clampedValues[0], 0, "beauty", 4));
  EXPECT_TRUE(is(out.stats.clampedValues[1], 0, "direct", 1));
  EXPECT_TRUE(is(out.stats.clampedValues[2], 3, "direct", 1));
  ASSERT_EQ(out.stats.warnings.size(), 5u);
  EXPECT_EQ(out.stats.warnings[0], "beauty: 39 NaN or infinite values were written as 0; passes that wrote it: direct, specular");
  EXPECT_EQ(out.stats.warnings[1], "depth: 2 NaN or infinite values were written as 0; no pass of this frame writes it");
  EXPECT_EQ(out.stats.warnings[2],
            "output 0 (half-float EXR): 4 values of beauty beyond +-65504 were written as +-65504 (\"half\": false keeps them)");
  const nlohmann::json j = out.stats;
  ASSERT_EQ(j["clamped_values"].size(), 3u);
  EXPECT_EQ(j["clamped_values"][0], (nlohmann::json{{"output", 0}, {"aov", "beauty"}, {"count", 4}, {"limit", 65504.0}}));
  // Nothing beyond range, nothing zeroed: no key, no warning.
  RenderOutput calm;
  calm.aovs = {direct};
  calm.aovs[0].pixels.back() = 12.f;
  reportOutputRange(calm, {}, req);
  EXPECT_TRUE(calm.stats.clampedValues.empty());
  EXPECT_TRUE(calm.stats.warnings.empty());
  EXPECT_FALSE(nlohmann::json(calm.stats).contains("clamped_values"));
}

}  // namespace
}  // namespace radiant

namespace radiant {
namespace {

// Issue 31: per-pass times that are each pass's own. On a software device (llvmpipe) every pass is
// bracketed by glFinish, so its gpu_ms is the wall time from its first command issued to its last one
// executed: at least its cpu_ms (issuing is part of it), and the brackets of successive passes are
// disjoint inside the render, so they sum to at most render_ms. llvmpipe's timer queries broke the
// first (photon_gi's gpu_ms was half its cpu_ms, its tracing charged to the `direct` query). On a
// hardware device the timer queries stay (no stall) and the sum bound holds as well.
TEST(RenderCore, PassTimesAreEachPassesOwnAndSayHowTheyWereMeasured) {
  const Scene scene = loadBuiltinScene("cornell_box");
  api::RenderRequest req = request(48, {"beauty"});
  req.passes["photon_gi"] = nlohmann::json::object();
  const RenderOutput out = renderer().render(scene, req);
  const bool software = renderer().device().software;
  EXPECT_EQ(out.stats.passTiming, software ? "finish_bracketed" : "timer_query");
  ASSERT_GE(out.stats.passes.size(), 3u);
  double sum = 0;
  for (const api::PassStats& p : out.stats.passes) {
    EXPECT_TRUE(std::isfinite(p.gpuMs) && p.gpuMs >= 0) << p.name;
    if (software) {
      EXPECT_GE(p.gpuMs, p.cpuMs) << p.name << ": its time includes issuing its commands";
    }
    sum += p.gpuMs;
  }
  EXPECT_LE(sum, out.stats.renderMs) << "the passes' times are disjoint parts of the render";
}


// Texture units (common/shared.h): no two samplers share a unit, within a program or across the
// programs of a frame, so a pass binding its inputs never overwrites another pass's. (Unit 8 used to
// be both t_baseColor and t_environment.) Units below kUnitShadowCube are each full-screen pass's own
// inputs. The programs are whatever the techniques link, with no list of them here: every registered
// technique is rendered on the first built-in scene where it runs, and the renderer's shader library
// says what was linked (a new technique's shaders are checked without touching this file).
TEST(RenderCore, SamplerUnitsAreUniqueAcrossEveryTechniquesPrograms) {
  Renderer& r = renderer();
  std::vector<Scene> scenes;
  for (const char* name : {"cornell_box", "cornell_glass", "cornell_mirror", "explosion", "ao_creases"})
    scenes.push_back(loadBuiltinScene(name));
  {  // No built-in scene blends (transparency): a lit wall behind a half-covering pane.
    testing::SceneBuilder b;
    b.quad({0, 0, -1}, {3, 0, 0}, {0, 3, 0}, b.material(testing::lambertian()), "wall");
    Material pane = testing::lambertian(glm::vec3(0.5f));
    pane.baseColorFactor.a = 0.5f;
    pane.alphaMode = AlphaMode::Blend;
    b.quad({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, b.material(pane), "pane");
    b.pointLight({0, 0, 2}, 10.f);
    scenes.push_back(b.build("sampler-units-blend"));
  }
  std::set<std::string> ran;
  for (const TechniqueDescription& t : Renderer::techniques()) {
    for (const Scene& scene : scenes) {
      if (ran.count(t.name)) break;
      api::RenderRequest req = request(32, {"beauty"});
      req.passes[t.name] = nlohmann::json::object();
      try {
        for (const api::PassStats& p : r.render(scene, req).stats.passes) ran.insert(p.name);
      } catch (const api::ApiError&) {
        // Not for this scene (a requirement, or a conflict with a default pass): the next one.
      }
    }
    EXPECT_TRUE(ran.count(t.name)) << t.name << " ran on no built-in scene: its programs go unchecked";
  }

  GLint maxCombinedUnits = 0, maxStageSamplers = 0;
  glGetIntegerv(GL_MAX_COMBINED_TEXTURE_IMAGE_UNITS, &maxCombinedUnits);
  glGetIntegerv(GL_MAX_TEXTURE_IMAGE_UNITS, &maxStageSamplers);
  EXPECT_GE(maxCombinedUnits, gpu::kUnitCount);  // GL 4.5 guarantees 80
  std::map<int, std::string> sharedUnitOwner;  // unit >= kUnitShadowCube -> sampler name
  int samplers = 0;
  for (const auto& [key, program] : r.shaders().programs()) {
    GLint count = 0;
    glGetProgramiv(program.id(), GL_ACTIVE_UNIFORMS, &count);
    std::map<int, std::string> units;
    for (GLint u = 0; u < count; ++u) {
      char name[256];
      GLint size = 0;
      GLenum type = 0;
      glGetActiveUniform(program.id(), static_cast<GLuint>(u), sizeof name, nullptr, &size, &type, name);
      const bool sampler = type == GL_SAMPLER_2D || type == GL_SAMPLER_2D_ARRAY || type == GL_SAMPLER_CUBE ||
                           type == GL_SAMPLER_CUBE_MAP_ARRAY || type == GL_SAMPLER_3D;
      if (!sampler) continue;
      GLint unit = -1;
      glGetUniformiv(program.id(), glGetUniformLocation(program.id(), name), &unit);
      ++samplers;
      EXPECT_LT(unit, gpu::kUnitCount) << key << " " << name;
      EXPECT_TRUE(units.emplace(unit, name).second)
          << key << ": " << name << " and " << units[unit] << " share unit " << unit;
      if (unit >= gpu::kUnitShadowCube) {
        const auto [it, inserted] = sharedUnitOwner.emplace(unit, name);
        EXPECT_EQ(it->second, name) << key << ": unit " << unit << " is " << name << " here and " << it->second
                                    << " in another program";
      }
    }
    // A program's stage reads at most GL_MAX_TEXTURE_IMAGE_UNITS samplers (this bounds every stage).
    EXPECT_LE(static_cast<GLint>(units.size()), maxStageSamplers) << key;
  }
  gl::checkError("sampler units");
  EXPECT_GE(r.shaders().cachedPrograms(), 20u);
  EXPECT_GE(samplers, 25);  // the programs' samplers were really enumerated
}

}  // namespace
}  // namespace radiant
