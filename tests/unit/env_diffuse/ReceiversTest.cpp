// env_diffuse's receiver rule (Receivers.h): extras flag, size heuristic, request override, errors.
#include <gtest/gtest.h>

#include "api/Types.h"
#include "renderer/scene/BuiltinScenes.h"
#include "renderer/techniques/env_diffuse/Receivers.h"
#include "tests/support/SceneBuilder.h"

namespace radiant::env_diffuse {
namespace {

Scene room(bool flagSphere) {
  testing::SceneBuilder b;
  const int white = b.material(testing::lambertian());
  b.quad({0, 0, 0}, {2, 0, 0}, {0, 0, -2}, white, "floor");
  b.quad({0, 1, -2}, {2, 0, 0}, {0, 1, 0}, white, "back_wall");
  b.sphere({0.3f, 0.2f, 0.f}, 0.2f, white, 16, 8, "ball");
  b.sphere({-0.5f, 0.3f, 0.f}, 0.3f, white, 16, 8, "big_ball");
  Scene s = b.build();
  if (flagSphere) s.meshes[2].extrasJson = R"({"radiant_receiver": true})";
  return s;
}

std::vector<std::string> names(const std::vector<Receiver>& r) {
  std::vector<std::string> n;
  for (const auto& x : r) n.push_back(x.name);
  return n;
}

TEST(Receivers, SizeHeuristicPicksCompactObjectsNotWalls) {
  const auto r = selectReceivers(room(false), "", "");
  EXPECT_EQ(names(r), (std::vector<std::string>{"ball", "big_ball"}));  // smallest first; walls are flat
  EXPECT_NEAR(r[0].referencePoint.x, 0.3f, 1e-5f);
  EXPECT_NEAR(r[0].referencePoint.y, 0.2f, 1e-5f);
}

TEST(Receivers, ExtrasFlagWinsOverTheHeuristic) {
  EXPECT_EQ(names(selectReceivers(room(true), "", "")), (std::vector<std::string>{"ball"}));
}

TEST(Receivers, RequestNamesAndReferencePointsOverride) {
  const auto r = selectReceivers(room(true), "big_ball, floor", "big_ball=1,2,3");
  EXPECT_EQ(names(r), (std::vector<std::string>{"big_ball", "floor"}));
  EXPECT_EQ(r[0].referencePoint, glm::vec3(1, 2, 3));
}

TEST(Receivers, BadNamesAndPointsAreApiErrorsWithPointers) {
  try {
    selectReceivers(room(false), "ball,teapot", "");
    FAIL();
  } catch (const api::ApiError& e) {
    EXPECT_EQ(e.status, 422);
    EXPECT_EQ(e.pointer, "/passes/env_diffuse/receivers");
  }
  for (const char* bad : {"ball=1,2", "ball=1,x,3", "teapot=1,2,3", "ball"}) {
    try {
      selectReceivers(room(false), "", bad);
      FAIL() << bad;
    } catch (const api::ApiError& e) {
      EXPECT_EQ(e.pointer, "/passes/env_diffuse/reference_points") << bad;
    }
  }
}

}  // namespace
}  // namespace radiant::env_diffuse

namespace radiant::env_diffuse {
namespace {

TEST(Receivers, BuiltinCornellBoxesFlagTheirDiffuseObjects) {
  // scenes/make_scenes.py sets extras.radiant_receiver on the tall box, and on the sphere where it is
  // diffuse (not the mirror or glass sphere).
  EXPECT_EQ(names(selectReceivers(loadBuiltinScene("cornell_box"), "", "")),
            (std::vector<std::string>{"tall_box", "sphere"}));
  EXPECT_EQ(names(selectReceivers(loadBuiltinScene("cornell_mirror"), "", "")), (std::vector<std::string>{"tall_box"}));
  EXPECT_EQ(names(selectReceivers(loadBuiltinScene("cornell_glass"), "", "")), (std::vector<std::string>{"tall_box"}));
}

}  // namespace
}  // namespace radiant::env_diffuse
