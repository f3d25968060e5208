// light_volumes on llvmpipe (Duvenhage et al.). Each test asserts a number fixed by a closed form or
// by another technique's estimate of the same light:
// - a flat mirror above a Lambertian floor is the image of the light: L = rho/pi R I cos / |F - L'|^2
//   inside the reflected footprint, 0 outside, with both traversals (they agree to float rounding);
// - a glossy plate: the culled (bvh) and linear traversals give the same image;
// - light paths are counted once with photon_gi: when light_volumes owns LG+DE, photon_gi stops
//   splatting photons that reached a diffuse surface through the glossy plate only, and the energy
//   it drops is the energy light_volumes adds (within the two estimators' agreement);
// - negative beams: direct + negative beams = 0 in the scatterer's umbra, with the scatterer out of
//   the shadow maps;
// - the tessellation report; a coarse glossy plate subdivided renders like a fine one, and falls back
//   when the budget is too small; the cache, and why it is skipped.
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "tests/support/RenderTestSupport.h"
#include "tests/support/SceneBuilder.h"

namespace radiant {
namespace {

using testing::aov;
using testing::pass;
using testing::renderer;

Material metal(float roughness, float base) {
  Material m = testing::lambertian(glm::vec3(base));
  m.metallicFactor = 1.f;
  m.roughnessFactor = roughness;
  m.ior = 1.5f;
  return m;
}

constexpr float kRho = 0.5f;
constexpr float kHalf = 1.f;  // the camera sees [-1, 1]^2 of the floor

api::RenderRequest request(int size, nlohmann::json lv = nlohmann::json::object()) {
  api::RenderRequest r;
  r.width = r.height = size;
  r.passes["light_volumes"] = std::move(lv);
  r.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"beauty", "light_volumes"}, false}};
  return r;
}

// Floor y = 0 (Lambertian kRho), a 0.3 m mirror at y = 1 facing down (32 x 32 x 2 facets, R = 1), a
// point light between them; the camera looks down from y = 0.9 (under the mirror).
const glm::vec3 kLight(0.2f, 0.5f, 0.1f);
constexpr float kMirrorX = 0.0123f, kMirrorZ = -0.0071f;
Scene mirrorScene() {
  testing::SceneBuilder b;
  const int floor = b.material(testing::lambertian(glm::vec3(kRho)));
  b.quad(glm::vec3(0.f), {1.5f, 0, 0}, {0, 0, -1.5f}, floor, "floor");
  // Off the pixel grid: a pixel centre exactly on a facet edge's plane would be counted by both
  // facets' beams (the in-beam test is inclusive; docs/TECHNIQUES.md, limits).
  b.gridY({kMirrorX, 1.f, kMirrorZ}, 0.15f, 32, false, b.material(metal(0.f, 1.f)), "mirror");
  b.pointLight(kLight, 1.f);
  b.topDownOrtho(0.9f, kHalf);
  return b.build("test:light_volumes:mirror");
}

TEST(LightVolumes, FlatMirrorIsTheImageOfTheLight) {
  const Scene scene = mirrorScene();
  const int size = 96;
  const glm::vec3 image(kLight.x, 2.f - kLight.y, kLight.z);  // L' mirrored through y = 1
  Image images[2];
  for (int t = 0; t < 2; ++t) {
    const RenderOutput out = renderer().render(scene, request(size, {{"traversal", t == 0 ? "linear" : "bvh"}}));
    ASSERT_TRUE(testing::allFinite(out));
    ASSERT_NE(pass(out, "light_volumes"), nullptr);
    EXPECT_EQ(pass(out, "light_volumes")->counters.at("beams"), 2048.0);
    images[t] = aov(out, "light_volumes");
    EXPECT_EQ(out.stats.lightPaths.at("LS+DE"), "light_volumes");
  }
  int inside = 0, outside = 0;
  double worst = 0.0, maxDiff = 0.0, peak = 0.0;
  for (int py = 0; py < size; ++py)
    for (int px = 0; px < size; ++px) {
      const glm::vec2 xz = testing::topDownPixelToWorld(px, py, size, kHalf);
      const glm::vec3 F(xz.x, 0.f, xz.y);
      const glm::vec3 d = F - image;
      const glm::vec3 hit = image + d * ((1.f - image.y) / d.y);  // where the ray from L' crosses the mirror
      const float m = std::max(std::abs(hit.x - kMirrorX), std::abs(hit.z - kMirrorZ));
      const float L = images[0].at(px, py)[0];
      peak = std::max(peak, double(L));
      maxDiff = std::max(maxDiff, double(std::abs(L - images[1].at(px, py)[0])));
      if (m < 0.14f) {  // inside, a pixel away from the footprint's edge
        const float r = glm::length(d);
        const float exact = kRho / 3.14159265f * (-d.y / r) / (r * r);
        worst = std::max(worst, std::abs(L / exact - 1.0));
        ++inside;
      } else if (m > 0.16f) {
        EXPECT_EQ(L, 0.f) << px << ", " << py;
        ++outside;
      }
    }
  EXPECT_GT(inside, 300);
  EXPECT_GT(outside, 3000);
  EXPECT_LT(worst, 0.01) << "largest relative error inside the footprint";
  EXPECT_LE(maxDiff, 1e-5 * peak) << "linear and bvh traversals differ";
}

// A glossy plate (roughness 0.3) above the floor.
Scene glossyScene(int n, float roughness = 0.3f) {
  testing::SceneBuilder b;
  const int floor = b.material(testing::lambertian(glm::vec3(kRho)));
  b.quad(glm::vec3(0.f), {1.5f, 0, 0}, {0, 0, -1.5f}, floor, "floor");
  b.gridY({0.f, 1.2f, 0.f}, 0.3f, n, false, b.material(metal(roughness, 0.9f)), "plate");
  b.pointLight({-0.5f, 0.6f, 0.f}, 2.f);
  b.topDownOrtho(1.f, kHalf);
  return b.build("test:light_volumes:glossy:" + std::to_string(n) + ":" + std::to_string(roughness));
}

double sum(const Image& img) {
  double s = 0.0;
  for (std::size_t i = 0; i < img.pixels.size(); i += img.channels) s += img.pixels[i];
  return s;
}

TEST(LightVolumes, CulledAndLinearTraversalsGiveTheSameGlossyImage) {
  const Scene scene = glossyScene(16);
  const RenderOutput lin = renderer().render(scene, request(64, {{"traversal", "linear"}}));
  const RenderOutput bvh = renderer().render(scene, request(64, {{"traversal", "bvh"}}));
  const Image& a = aov(lin, "light_volumes");
  const Image& b = aov(bvh, "light_volumes");
  double l1 = 0.0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i) l1 += std::abs(a.pixels[i] - b.pixels[i]);
  const double total = sum(a) * 3.0;
  ASSERT_GT(total, 0.0);
  EXPECT_LT(l1 / total, 1e-3) << "relative L1 between the traversals (cull_sigmas 4)";
  // The beams were cached: the second request only changed the traversal.
  EXPECT_EQ(testing::cacheEvent(bvh, "light_volumes_beams"), 1);
  const auto& c = pass(bvh, "light_volumes")->counters;
  EXPECT_EQ(c.at("beams_glossy"), 512.0);
  EXPECT_EQ(c.at("tessellation_failed"), 0.0) << "0.0375 m facets 1.2 m from the floor, sigma ~0.12";
  EXPECT_EQ(c.at("tessellation_specular_fallbacks"), 0.0);
  EXPECT_EQ(c.at("tessellation/1:plate/light0/specular_fallback"), 0.0);
  EXPECT_EQ(c.count("tessellation/0:floor/light0/checked"), 0u) << "the floor is no scatterer";
}

TEST(LightVolumes, CoarseGlossyScattererFallsBackToSpecularBeams) {
  // 2 x 2 x 2 facets of 0.3 m at 1.2 m (0.25 rad against sigma ~0.12): the condition fails and, with
  // subdivision off, the scatterer gets specular beams (stats say so).
  const RenderOutput out = renderer().render(glossyScene(2), request(32, {{"max_subdivision_beams", 0}}));
  const auto& c = pass(out, "light_volumes")->counters;
  EXPECT_GE(c.at("tessellation_failed"), 6.0) << "of 8 (two centroid rays reach the floor far out)";
  EXPECT_GT(c.at("tessellation_worst_triangle_sigma"), 2.0);
  EXPECT_EQ(c.at("tessellation_specular_fallbacks"), 1.0);
  EXPECT_EQ(c.at("beams_glossy"), 0.0);
  // The same per scatterer: mesh 1 ("plate") under light 0.
  EXPECT_EQ(c.at("tessellation/1:plate/light0/checked"), c.at("tessellation_checked"));
  EXPECT_EQ(c.at("tessellation/1:plate/light0/failed"), c.at("tessellation_failed"));
  EXPECT_EQ(c.at("tessellation/1:plate/light0/worst_triangle_sigma"), c.at("tessellation_worst_triangle_sigma"));
  EXPECT_EQ(c.at("tessellation/1:plate/light0/specular_fallback"), 1.0);
  EXPECT_EQ(c.at("subdivision_scatterers"), 0.0);
  EXPECT_EQ(c.at("subdivision_budget_exhausted"), 0.0) << "a budget of 0 asks for no subdivision";
}

TEST(LightVolumes, CoarseGlossyScattererIsSubdividedAndRendersLikeAFineOne) {
  // The same 2 x 2 x 2 plate with the default budget: its triangles are split (positions on the flat
  // facets, normals interpolated) until every child meets the condition, so it renders glossy and gives
  // the image of the 16 x 16 x 2 plate, which meets the condition by itself. What remains between them:
  // sigma and the GGX albedo are evaluated at each original triangle's centroid (incidence 0.6-0.95 over
  // the plate: sigma ~ sqrt(cos theta_i) varies by +-12%, so a coarse triangle's children share its mean).
  const int size = 48;
  const RenderOutput coarse = renderer().render(glossyScene(2), request(size));
  const RenderOutput fallback = renderer().render(glossyScene(2), request(size, {{"max_subdivision_beams", 0}}));
  const RenderOutput fine = renderer().render(glossyScene(16), request(size));
  const auto& c = pass(coarse, "light_volumes")->counters;
  EXPECT_EQ(c.at("subdivision_scatterers"), 1.0);
  EXPECT_GE(c.at("subdivision_beams_split"), 6.0);
  EXPECT_GT(c.at("subdivision_beams_added"), 0.0);
  EXPECT_EQ(c.at("subdivision_still_failing"), 0.0);
  EXPECT_EQ(c.at("subdivision_budget_exhausted"), 0.0);
  EXPECT_EQ(c.at("tessellation_specular_fallbacks"), 0.0);
  EXPECT_EQ(c.at("beams_glossy"), c.at("beams"));
  EXPECT_EQ(c.at("tessellation/1:plate/light0/beams_added"), c.at("subdivision_beams_added"));
  const Image& a = aov(coarse, "light_volumes");
  const Image& f = aov(fine, "light_volumes");
  const Image& s0 = aov(fallback, "light_volumes");
  auto relL1 = [](const Image& x, const Image& y) {
    double d = 0.0, t = 0.0;
    for (std::size_t i = 0; i < x.pixels.size(); i += x.channels) {
      d += std::abs(double(x.pixels[i]) - y.pixels[i]);
      t += std::abs(double(y.pixels[i]));
    }
    return d / t;
  };
  const double l1 = relL1(a, f), l1Fallback = relL1(s0, f);
  std::printf("coarse plate against the fine one: subdivided relL1 %.4f energy %.4f (%.0f beams); specular fallback "
              "relL1 %.4f energy %.4f\n",
              l1, sum(a) / sum(f), c.at("beams"), l1Fallback, sum(s0) / sum(f));
  EXPECT_LT(l1, 0.04) << "measured 0.012";
  EXPECT_NEAR(sum(a) / sum(f), 1.0, 0.03);
  EXPECT_GT(l1Fallback, 3.0 * l1) << "the fallback's sharp beams are what subdivision replaces";
  // A budget below what the plate needs: not subdivided, falls back, and says why.
  const RenderOutput small = renderer().render(glossyScene(2), request(32, {{"max_subdivision_beams", 10}}));
  const auto& cs = pass(small, "light_volumes")->counters;
  EXPECT_EQ(cs.at("subdivision_budget_exhausted"), 1.0);
  EXPECT_EQ(cs.at("tessellation/1:plate/light0/budget_exhausted"), 1.0);
  EXPECT_EQ(cs.at("subdivision_beams_added"), 0.0);
  EXPECT_EQ(cs.at("tessellation_specular_fallbacks"), 1.0);
  EXPECT_EQ(cs.at("beams_glossy"), 0.0);
}

TEST(LightVolumes, PathsThroughTheGlossyPlateAreCountedOnceWithPhotonGi) {
  // photon_gi alone splats the light the plate reflects onto the floor (its LD+DE estimate holds
  // L G D). With light_volumes owning LG+DE, photon_gi leaves those photons out and light_volumes
  // adds the beams: the indirect light photon_gi drops equals, within the estimators' agreement
  // (GGX against the Gaussian fit, photon noise), what light_volumes adds, and the total is kept.
  const Scene scene = glossyScene(16);
  api::RenderRequest both = request(48);
  both.passes["photon_gi"] = {{"photons", 200000}};
  both.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"beauty", "indirect", "light_volumes"}, false}};
  api::RenderRequest photonsOnly = both;
  photonsOnly.passes.erase("light_volumes");
  photonsOnly.disabledPasses.insert("light_volumes");
  photonsOnly.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"beauty", "indirect"}, false}};
  const RenderOutput a = renderer().render(scene, photonsOnly);
  const RenderOutput b = renderer().render(scene, both);
  EXPECT_EQ(a.stats.lightPaths.count("LG+DE"), 0u);
  EXPECT_EQ(b.stats.lightPaths.at("LG+DE"), "light_volumes");
  const double indirectA = sum(aov(a, "indirect")), indirectB = sum(aov(b, "indirect"));
  const double lv = sum(aov(b, "light_volumes"));
  std::printf("photon_gi alone %.4f; with light_volumes: photon_gi %.4f + light_volumes %.4f\n", indirectA, indirectB,
              lv);
  EXPECT_GT(lv, 0.5 * indirectA) << "the plate's light should dominate the indirect light";
  EXPECT_NEAR((indirectA - indirectB) / lv, 1.0, 0.15) << "what photon_gi drops against what light_volumes adds";
  EXPECT_NEAR((indirectB + lv) / indirectA, 1.0, 0.12) << "the total indirect light (a double count gives ~1.9)";
  EXPECT_NEAR(sum(aov(b, "beauty")) / sum(aov(a, "beauty")), 1.0, 0.1);
}

TEST(LightVolumes, NegativeBeamsReplaceTheScatterersShadowMapShadows) {
  // A mirror (16 x 16 x 2 facets, facing up) 0.5 m above the floor under a point light. With
  // shadows = negative_beams the mirror leaves the shadow maps (it casts no shadow-map shadow) and its
  // negative beams darken the umbra instead: direct + negative beam = 0 there (2% of the unshadowed
  // direct light; the beam's flux density is constant across its cross-section), and away from the
  // shadow's edge the two modes give the same beauty.
  testing::SceneBuilder b;
  b.quad(glm::vec3(0.f), {1.5f, 0, 0}, {0, 0, -1.5f}, b.material(testing::lambertian(glm::vec3(kRho))), "floor");
  b.gridY({0.f, 0.5f, 0.f}, 0.15f, 16, true, b.material(metal(0.f, 1.f)), "mirror");
  const glm::vec3 L(0.05f, 1.2f, 0.03f);
  b.pointLight(L, 1.f);
  b.topDownOrtho(0.4f, 0.6f);
  const Scene scene = b.build("test:light_volumes:shadow");
  const int size = 64;
  api::RenderRequest maps = request(size);
  maps.disabledPasses.insert("photon_gi");
  api::RenderRequest beams = maps;
  beams.passes["light_volumes"] = {{"shadows", "negative_beams"}};
  const RenderOutput a = renderer().render(scene, maps);
  const RenderOutput c = renderer().render(scene, beams);
  ASSERT_TRUE(testing::allFinite(c));
  EXPECT_EQ(pass(a, "shadow_maps")->counters.at("meshes_excluded"), 0.0);
  EXPECT_EQ(pass(c, "shadow_maps")->counters.at("meshes_excluded"), 1.0);
  EXPECT_EQ(pass(c, "light_volumes")->counters.at("beams_shadow"), 512.0);
  const Image& ba = aov(a, "beauty");
  const Image& bc = aov(c, "beauty");
  int umbra = 0, lit = 0;
  double worstUmbra = 0.0, worstLit = 0.0;
  for (int py = 0; py < size; ++py)
    for (int px = 0; px < size; ++px) {
      const glm::vec2 xz = testing::topDownPixelToWorld(px, py, size, 0.6f);
      const glm::vec3 F(xz.x, 0.f, xz.y), d = F - L;
      const glm::vec3 hit = L + d * ((0.5f - L.y) / d.y);
      const float m = std::max(std::abs(hit.x), std::abs(hit.z));
      const float r = glm::length(d);
      const float unshadowed = kRho / 3.14159265f * (-d.y / r) / (r * r);
      if (m < 0.13f) {
        worstUmbra = std::max(worstUmbra, std::abs(double(bc.at(px, py)[0])) / unshadowed);
        EXPECT_LT(ba.at(px, py)[0], 1e-3f * unshadowed) << "the shadow map's umbra";
        ++umbra;
      } else if (m > 0.2f) {
        worstLit = std::max(worstLit, std::abs(double(bc.at(px, py)[0] - ba.at(px, py)[0])) / unshadowed);
        ++lit;
      }
    }
  EXPECT_GT(umbra, 100);
  EXPECT_GT(lit, 1000);
  EXPECT_LT(worstUmbra, 0.02) << "|direct + negative beams| / unshadowed direct in the umbra";
  EXPECT_LT(worstLit, 1e-3) << "the two shadow modes away from the shadow";
}

// Planned only for its AOV (the request asks for it, passes does not name it), light_volumes does not
// own LS+DE: caustics or photon_gi does, and adds the mirror's reflected light to beauty. light_volumes
// owns LG+DE alone (no other technique supplies it), and beauty takes only that class's beams and its
// shadow beams: the mirror's LS+DE light is counted once. Its AOV still holds every beam. The mirror,
// above the light, shadows nothing the camera sees, so beauty is the frame without light_volumes (equal
// on llvmpipe); counted twice it was light_volumes' whole AOV above it (+6.6%).
TEST(LightVolumes, PlannedForItsAovItAddsOnlyTheClassesItOwnsToBeauty) {
  const Scene scene = mirrorScene();
  api::RenderRequest aovOnly = request(48);
  aovOnly.passes.erase("light_volumes");
  api::RenderRequest without = aovOnly;
  without.disabledPasses.insert("light_volumes");
  without.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"beauty"}, false}};
  const RenderOutput a = renderer().render(scene, without);
  const RenderOutput b = renderer().render(scene, aovOnly);
  ASSERT_TRUE(testing::allFinite(b));
  ASSERT_NE(pass(b, "light_volumes"), nullptr);
  EXPECT_NE(b.stats.lightPaths.at("LS+DE"), "light_volumes");
  EXPECT_EQ(b.stats.lightPaths.at("LG+DE"), "light_volumes");
  EXPECT_EQ(pass(b, "light_volumes")->counters.at("beauty_classes"), 2.0);
  const double lv = sum(aov(b, "light_volumes")), beautyA = sum(aov(a, "beauty")), beautyB = sum(aov(b, "beauty"));
  std::printf("beauty without light_volumes %.4f, with it for its AOV %.4f; its AOV %.4f\n", beautyA, beautyB, lv);
  EXPECT_GT(lv, 0.05 * beautyA) << "the mirror's light is a visible share of the frame (6.6% at 48 px)";
  EXPECT_NEAR(beautyB / beautyA, 1.0, 0.01) << "a double count adds the AOV: " << (beautyA + lv) / beautyA;
}

TEST(LightVolumes, SaysWhyItIsSkipped) {
  testing::SceneBuilder b;
  b.quad(glm::vec3(0.f), {1, 0, 0}, {0, 0, -1}, b.material(testing::lambertian()), "floor");
  b.pointLight({0, 1, 0}, 1.f);
  b.topDownOrtho(2.f, 1.f);
  const RenderOutput out = renderer().render(b.build("test:light_volumes:none"), request(16));
  EXPECT_NE(out.stats.skipped.at("light_volumes").find("no specular or glossy scatterer"), std::string::npos);
}

}  // namespace
}  // namespace radiant
