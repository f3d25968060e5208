// The frame's lighting stage (renderer/frame/FrameLighting.h, docs/API.md "Default lighting"), without
// GL: the studio map lights exactly the scenes without punctual lights whose request names no ambient
// or environment (and does not turn default lighting off); punctual lights are a set-up of their own;
// the request's ambient or environment always wins. stats.lighting and its reason say which.
#include <gtest/gtest.h>

#include "renderer/frame/FrameLighting.h"
#include "renderer/scene/StudioEnvironment.h"
#include "tests/support/SceneBuilder.h"

namespace radiant {
namespace {

Scene sceneWith(bool light, bool emissive) {
  testing::SceneBuilder b;
  Material m;
  if (emissive) m.emissiveFactor = glm::vec3(1.f);
  b.quad(glm::vec3(0.f), {1, 0, 0}, {0, 0, -1}, b.material(m));
  if (light) b.pointLight({0, 1, 0}, 1.f);
  return b.build(std::string("lighting-") + (light ? "l" : "") + (emissive ? "e" : ""));
}

TEST(FrameLighting, TheStudioLightsOnlyScenesWithoutPunctualLightsWhenTheRequestNamesNoLight) {
  const Image mine = Image::make("beauty", 2, 1, 3);
  struct Case {
    bool light, emissive;
    const char* ambientOrMap;  // "", "ambient", "environment"
    bool defaultLighting;
    const char* lighting;
    bool studio;
    const char* reasonHas;
  };
  const Case cases[] = {
      {false, false, "", true, "default", true, "the scene has no lights or emissive surfaces, and the request names no"},
      {false, true, "", true, "scene+default", true, "its emissive surfaces light little"},
      {true, false, "", true, "scene", false, "punctual lights, a lighting set-up of its own"},
      {true, true, "", true, "scene", false, "the scene's own lights and emissive surfaces"},
      {false, false, "", false, "none", false, "default_lighting is false, and the scene has no lights"},
      {false, true, "", false, "scene", false, "default_lighting is false: the scene's own emissive surfaces"},
      {false, false, "ambient", true, "ambient", false, "the request's ambient"},
      {true, false, "ambient", true, "scene+ambient", false, "the request's ambient; with the scene's own lights"},
      {false, false, "environment", true, "environment", false, "the request's environment map"},
      {true, true, "environment", false, "scene+environment", false, "the request's environment map; with"},
  };
  for (const Case& c : cases) {
    const Scene scene = sceneWith(c.light, c.emissive);
    api::RenderRequest r;
    r.defaultLighting = c.defaultLighting;
    const Image* given = nullptr;
    if (std::string(c.ambientOrMap) == "ambient") r.ambient = glm::vec3(0.3f);
    if (std::string(c.ambientOrMap) == "environment") r.environment = "sha256:mine", given = &mine;
    const FrameLighting f = frameLighting(scene, r, given);
    const std::string what = std::string(c.lighting) + " / " + f.reason;
    EXPECT_EQ(f.lighting, c.lighting) << what;
    EXPECT_NE(f.reason.find(c.reasonHas), std::string::npos) << what;
    if (c.studio) {
      EXPECT_EQ(f.request.environment, kStudioEnvironmentKey) << what;
      EXPECT_EQ(f.environment, &studioEnvironment()) << what;
    } else {
      EXPECT_EQ(f.request.environment, r.environment) << what;
      EXPECT_EQ(f.environment, given) << what;
    }
    EXPECT_EQ(f.request.ambient, r.ambient) << what;
  }
}

}  // namespace
}  // namespace radiant
