// The shadow maps' overdraw estimate (ShadowMapsPass::mapCoverage) against closed forms, and the size
// the fragment budget chooses (sizeWithinBudget). No GL: the estimate reads the scene's triangles only.
#include <cmath>

#include <gtest/gtest.h>

#include "renderer/techniques/shadow_maps/ShadowMaps.h"
#include "tests/support/SceneBuilder.h"

namespace radiant {
namespace {

constexpr double kPi = 3.14159265358979323846;

Light directional(glm::vec3 dir) {
  Light l;
  l.type = LightType::Directional;
  l.direction = glm::normalize(dir);
  return l;
}

// A 2 x 2 quad at y = 0 facing up: its bounding sphere's radius is sqrt(2), the orthographic map spans
// 2 sqrt(2) x 2 sqrt(2) = 8, and the quad's projected area along a direction at angle t from its
// normal is 4 cos t.
TEST(ShadowMapCost, DirectionalCoverageIsTheProjectedAreaOverTheMapArea) {
  testing::SceneBuilder b;
  b.quad({0, 0, 0}, {1, 0, 0}, {0, 0, -1}, b.material(testing::lambertian()));
  const Scene scene = b.build();
  const auto c = ShadowMapsPass::mapCoverage(scene, {directional({0, -1, 0}), directional({0, -1, std::sqrt(3.f)}),
                                                     directional({1, 0, 0})}, {});
  ASSERT_EQ(c.size(), 3u);
  EXPECT_NEAR(c[0], 0.5, 1e-6);   // 4 / 8
  EXPECT_NEAR(c[1], 0.25, 1e-6);  // 60 degrees: 4 cos 60 / 8
  EXPECT_NEAR(c[2], 0.0, 1e-6);   // edge-on
}

// Layers multiply it: N stacked quads are rasterised N times (the maps draw both faces, and nothing
// culls a hidden layer before its fragments are shaded); an excluded mesh is not drawn at all.
TEST(ShadowMapCost, StackedLayersAddUpAndExcludedMeshesDoNot) {
  testing::SceneBuilder b;
  const int white = b.material(testing::lambertian());
  for (int i = 0; i < 10; ++i) b.quad({0, -1e-4f * i, 0}, {1, 0, 0}, {0, 0, -1}, white);
  const Scene scene = b.build();
  const double r = scene.features.bounds.radius();
  const double one = 4.0 / (4.0 * r * r);
  EXPECT_NEAR(ShadowMapsPass::mapCoverage(scene, {directional({0, -1, 0})}, {})[0], 10 * one, 1e-5);
  EXPECT_NEAR(ShadowMapsPass::mapCoverage(scene, {directional({0, -1, 0})}, {0, 3, 9})[0], 7 * one, 1e-5);
}

// A point light at height h over a square of half-side h sees it under exactly one cube face's solid
// angle, 4 pi / 6: one face map's area. Tessellated finely, the per-triangle estimate (each triangle's
// solid angle from its centroid) meets it within a fraction of a percent; a square of half-side 0.5 h
// subtends 4 asin(0.25 / 1.25) (the rectangle's closed form, 4 asin(a^2 / (a^2 + h^2))).
TEST(ShadowMapCost, PointLightCoverageIsTheSolidAngleInFaceMaps) {
  const float h = 3.f;
  for (const auto& [half, expected] : {std::pair{h, 1.0}, std::pair{0.5f * h, 4.0 * std::asin(0.25 / 1.25) * 6.0 / (4.0 * kPi)}}) {
    testing::SceneBuilder b;
    b.gridY({0, 0, 0}, half, 64, true, b.material(testing::lambertian()));
    b.pointLight({0, h, 0}, 1.f);
    const Scene scene = b.build();
    const auto c = ShadowMapsPass::mapCoverage(scene, scene.lights, {});
    EXPECT_NEAR(c[0], expected, 0.005 * expected) << "half-side " << half;
  }
}

// A spot light's map spans 2 tan(fov / 2) on the plane at distance 1 (fov: the cone plus 4 degrees); a
// small quad on its axis covers its solid angle in that plane's units, and one behind it nothing.
TEST(ShadowMapCost, SpotCoverageIsTheSolidAngleOverTheMapsPlaneAndNothingBehind) {
  testing::SceneBuilder b;
  const int white = b.material(testing::lambertian());
  b.quad({0, 0, 0}, {0.01f, 0, 0}, {0, 0, -0.01f}, white);   // 4e-4 at distance 2, facing the light
  b.quad({0, 4, 0}, {0.01f, 0, 0}, {0, 0, -0.01f}, white);   // above the light: behind it
  b.spotLight({0, 2, 0}, {0, -1, 0}, 1.f, 0.f, glm::radians(30.f));
  const Scene scene = b.build();
  const double t = std::tan(glm::radians(32.0));
  const double expected = (4e-4 / 4.0) / (4.0 * t * t);  // solid angle 4e-4 / 2^2
  EXPECT_NEAR(ShadowMapsPass::mapCoverage(scene, scene.lights, {})[0], expected, 1e-3 * expected);
  EXPECT_NEAR(ShadowMapsPass::mapCoverage(scene, scene.lights, {0})[0], 0.0, 1e-12);
}

// The default size is halved until the estimated fragments fit the budget (256 Mi), never below 64.
TEST(ShadowMapCost, TheBudgetHalvesTheDefaultSizeUntilTheFragmentsFit) {
  EXPECT_EQ(ShadowMapsPass::sizeWithinBudget(1024, 3.0), 1024);  // a Cornell box: 3 Mi fragments
  EXPECT_EQ(ShadowMapsPass::sizeWithinBudget(1024, 256.0), 1024);  // exactly the budget
  EXPECT_EQ(ShadowMapsPass::sizeWithinBudget(1024, 257.0), 512);
  EXPECT_EQ(ShadowMapsPass::sizeWithinBudget(1024, 1483.0), 256);  // 1483 x 256^2 = 97 Mi
  EXPECT_EQ(ShadowMapsPass::sizeWithinBudget(2048, 1e9), 64);
  EXPECT_EQ(ShadowMapsPass::sizeWithinBudget(1024, 0.0), 1024);
  for (int size : {1024, 512, 256}) {
    const double coverage = ShadowMapsPass::kFragmentBudget / (double(size) * size);
    EXPECT_EQ(ShadowMapsPass::sizeWithinBudget(1024, coverage), size);
  }
}

}  // namespace
}  // namespace radiant
