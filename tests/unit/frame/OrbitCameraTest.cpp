// camera.orbit (issue 29): model-viewer's camera-orbit convention, so that a scene framed in another
// viewer can be reproduced exactly: position = target + radius (sin phi sin theta, cos phi,
// sin phi cos theta), theta about +Y from +Z towards +X, phi from +Y. The closed forms below are that
// formula at the cardinal angles; bad orbits are 422s naming the field.
#include <cmath>

#include <gtest/gtest.h>
#include <glm/glm.hpp>

#include "api/Validate.h"
#include "renderer/frame/FrameView.h"
#include "tests/support/SceneBuilder.h"

using nlohmann::json;
using namespace radiant::testing;

namespace radiant {
namespace {

Scene unitBox() {
  SceneBuilder b;
  const int m = b.material(lambertian());
  b.box({-1, 0, -1}, {1, 2, 1}, m);
  return b.build("orbit-test");
}

FrameView viewFor(const Scene& scene, const json& camera) {
  json body{{"scene", {{"builtin", "cornell_box"}}}, {"width", 64}, {"height", 48}, {"camera", camera}};
  return makeFrameView(scene, api::parseRenderRequest(body));
}

void expectNear(glm::vec3 a, glm::vec3 b, float tol = 1e-5f) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

glm::vec3 forwardOf(const FrameView& v) { return -glm::normalize(glm::vec3(v.camera.world[2])); }

TEST(OrbitCamera, CardinalAnglesPlaceTheEyeAsModelViewerDoes) {
  const Scene scene = unitBox();
  const json target{0.5, 1, -0.25};
  const glm::vec3 t(0.5f, 1.f, -0.25f);
  struct Case {
    double theta, phi;
    glm::vec3 offset;  // unit direction from the target to the eye
  };
  for (const Case& c : {Case{0, 90, {0, 0, 1}}, Case{90, 90, {1, 0, 0}}, Case{180, 90, {0, 0, -1}},
                        Case{-90, 90, {-1, 0, 0}}, Case{0, 180, {0, -1, 0}}, Case{45, 60, {0, 0, 0}}}) {
    const double radius = 3.5;
    const FrameView v = viewFor(scene, {{"target", target}, {"orbit", {{"theta_deg", c.theta}, {"phi_deg", c.phi}, {"radius", radius}}}});
    glm::vec3 dir = c.offset;
    if (c.theta == 45) {  // sin 60 sin 45, cos 60, sin 60 cos 45
      const float s = std::sqrt(3.f) / 2.f, h = std::sqrt(0.5f);
      dir = {s * h, 0.5f, s * h};
    }
    expectNear(v.eye, t + float(radius) * dir);
    expectNear(forwardOf(v), -dir);  // looking at the target
    EXPECT_NEAR(glm::length(v.eye - t), radius, 1e-5);
    EXPECT_EQ(v.cameraSource, "request+auto") << "up and yfov_deg are the automatic camera's";
  }
  // phi 0: above the target looking straight down; up falls back to -Z (the image's top is away from
  // the theta-0 viewer), and the eye is exactly radius above.
  const FrameView top = viewFor(scene, {{"target", target}, {"orbit", {{"theta_deg", 0}, {"phi_deg", 0}, {"radius", 2}}}});
  expectNear(top.eye, t + glm::vec3(0, 2, 0));
  expectNear(glm::normalize(glm::vec3(top.camera.world[1])), {0, 0, -1});
}

TEST(OrbitCamera, WithoutRadiusKeepsTheSceneCamerasDistanceAndTarget) {
  const Scene scene = unitBox();
  const FrameView automatic = viewFor(scene, {{"yfov_deg", 40}});
  const float distance = glm::length(automatic.eye - automatic.target);
  const FrameView v = viewFor(scene, {{"yfov_deg", 40}, {"orbit", {{"theta_deg", 90}, {"phi_deg", 90}}}});
  expectNear(v.target, automatic.target);
  EXPECT_NEAR(glm::length(v.eye - v.target), distance, 1e-4f * distance);
  expectNear(glm::normalize(v.eye - v.target), {1, 0, 0});
}

TEST(OrbitCamera, BadOrbitsAreRefusedNamingTheField) {
  auto pointerOf = [](const json& camera) -> std::string {
    json body{{"scene", {{"builtin", "cornell_box"}}}, {"camera", camera}};
    try {
      api::parseRenderRequest(body);
    } catch (const api::ApiError& e) {
      EXPECT_TRUE(e.status == 422 || e.status == 400) << camera.dump();  // 400: wrong JSON type
      return e.pointer;
    }
    return "accepted";
  };
  EXPECT_EQ(pointerOf({{"orbit", {{"theta_deg", 0}, {"phi_deg", 90}, {"radius", 0}}}}), "/camera/orbit/radius");
  EXPECT_EQ(pointerOf({{"orbit", {{"theta_deg", 0}, {"phi_deg", 90}, {"radius", -1}}}}), "/camera/orbit/radius");
  EXPECT_EQ(pointerOf({{"orbit", {{"theta_deg", 0}, {"phi_deg", 181}}}}), "/camera/orbit/phi_deg");
  EXPECT_EQ(pointerOf({{"orbit", {{"theta_deg", 0}, {"phi_deg", -1}}}}), "/camera/orbit/phi_deg");
  EXPECT_EQ(pointerOf({{"orbit", {{"theta_deg", 361}, {"phi_deg", 90}}}}), "/camera/orbit/theta_deg");
  EXPECT_EQ(pointerOf({{"orbit", {{"theta_deg", "north"}, {"phi_deg", 90}}}}), "/camera/orbit/theta_deg");
  EXPECT_EQ(pointerOf({{"orbit", {{"phi_deg", 90}}}}), "/camera/orbit/theta_deg");
  EXPECT_EQ(pointerOf({{"orbit", {{"theta_deg", 0}, {"phi_deg", 90}, {"distance", 3}}}}), "/camera/orbit/distance");
  EXPECT_EQ(pointerOf({{"position", {0, 1, 3}}, {"orbit", {{"theta_deg", 0}, {"phi_deg", 90}}}}), "/camera/orbit");
  // Non-finite numbers cannot be written in JSON; the largest doubles are out of range.
  EXPECT_EQ(pointerOf(json::parse(R"({"orbit": {"theta_deg": 0, "phi_deg": 90, "radius": 1e308}})")), "/camera/orbit/radius");
  EXPECT_EQ(pointerOf({{"orbit", {{"theta_deg", -360}, {"phi_deg", 180}, {"radius", 1e-3}}}}), "accepted");
}

TEST(OrbitCamera, ARadiusTooSmallForTheTargetsPrecisionIsRefused) {
  const Scene scene = unitBox();
  try {
    viewFor(scene, {{"target", {1e6, 0, 0}}, {"orbit", {{"theta_deg", 90}, {"phi_deg", 90}, {"radius", 1e-3}}}});
    ADD_FAILURE() << "accepted";
  } catch (const api::ApiError& e) {
    EXPECT_EQ(e.status, 422);
    EXPECT_EQ(e.pointer, "/camera/orbit/radius");
  }
}

}  // namespace
}  // namespace radiant
