// Who owns LS+DE and LG+DE (docs/techniques/light_volumes.md): the planner gives a light-path class to
// the planned technique its ownership policy ranks first (a class without a row, such as LG+DE here, by
// name), except that light_volumes (TechniqueInfo::claimsWhenNamed) takes its classes first when the
// request names it. A stand-in for the caustics technique that also claims LG+DE (the real one does
// not: there light_volumes owns LG+DE whenever it is planned).
#include <gtest/gtest.h>

#include "api/Validate.h"
#include "renderer/frame/FramePlanner.h"
#include "renderer/techniques/gbuffer/GBuffer.h"
#include "renderer/techniques/light_volumes/LightVolumes.h"
#include "tests/support/SceneBuilder.h"
#include "tests/support/StandInTechnique.h"

namespace radiant {
namespace {

testing::StandInTechnique causticsStandIn() {
  return testing::StandInTechnique({"caustics", "stand-in", {}, {}, {"caustics"}, true, true, {"LS+DE", "LG+DE"}});
}

Scene mirrorScene() {
  testing::SceneBuilder b;
  Material m;
  m.metallicFactor = 1.f;
  m.roughnessFactor = 0.f;
  b.quad(glm::vec3(0.f), {1, 0, 0}, {0, 0, -1}, b.material(m), "mirror");
  b.pointLight({0, 1, 0}, 1.f);
  return b.build();
}

api::RenderRequest asking(bool nameLightVolumes) {
  api::RenderRequest r;
  if (nameLightVolumes) r.passes["light_volumes"] = nlohmann::json::object();
  r.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"beauty", "light_volumes"}, false}};
  return r;
}

TEST(LightPathOwnership, CausticsOwnsByDefaultLightVolumesWhenNamed) {
  GBufferPass gbuffer;
  testing::StandInTechnique caustics = causticsStandIn();
  LightVolumesPass volumes;
  const std::vector<Technique*> registry{&gbuffer, &caustics, &volumes};
  const Scene scene = mirrorScene();
  // light_volumes planned for its AOV only: caustics owns both classes (LS+DE by the ownership policy;
  // LG+DE, which only this stand-in of caustics also claims, by name, the policy having no row for it).
  FramePlan p = planFrame(registry, scene, asking(false));
  ASSERT_EQ(p.passes.size(), 3u);
  EXPECT_EQ(p.lightPaths.at("LS+DE"), "caustics");
  EXPECT_EQ(p.lightPaths.at("LG+DE"), "caustics");
  // Named in the request: light_volumes owns them although caustics runs too.
  p = planFrame(registry, scene, asking(true));
  EXPECT_EQ(p.lightPaths.at("LS+DE"), "light_volumes");
  EXPECT_EQ(p.lightPaths.at("LG+DE"), "light_volumes");
  // caustics turned off (not planned): light_volumes owns them, named or not.
  api::RenderRequest off = asking(false);
  off.disabledPasses.insert("caustics");
  p = planFrame(registry, scene, off);
  EXPECT_EQ(p.lightPaths.at("LS+DE"), "light_volumes");
  EXPECT_EQ(p.lightPaths.at("LG+DE"), "light_volumes");
  // light_volumes is not on by default: a request that neither names it nor asks for its AOV leaves
  // the classes to caustics.
  api::RenderRequest plain;
  p = planFrame(registry, scene, plain);
  EXPECT_EQ(p.lightPaths.at("LG+DE"), "caustics");
  EXPECT_EQ(p.passes.size(), 1u);  // caustics alone (its stand-in reads no G-buffer)
}

// The subdivision budget is a request knob: validated by the schema (422 naming it) and capped by the
// server's photon-count limit (x-cost "photons", radiantd --max-photons).
TEST(LightVolumesKnobs, SubdivisionBudgetIsValidatedAndCapped) {
  auto errorOf = [](const nlohmann::json& value, const api::RequestLimits& limits = {}) -> std::pair<int, std::string> {
    const nlohmann::json body{{"scene", {{"builtin", "cornell_box"}}},
                              {"passes", {{"light_volumes", {{"max_subdivision_beams", value}}}}}};
    try {
      api::parseRenderRequest(body, limits);
    } catch (const api::ApiError& e) {
      return {e.status, e.pointer};
    }
    return {0, ""};
  };
  const std::string pointer = "/passes/light_volumes/max_subdivision_beams";
  EXPECT_EQ(errorOf(-1), std::make_pair(422, pointer));
  EXPECT_EQ(errorOf(2000000), std::make_pair(422, pointer));
  EXPECT_EQ(errorOf(1.5).second, pointer);
  EXPECT_EQ(errorOf(0).first, 0);
  EXPECT_EQ(errorOf(1048576).first, 0);
  api::RequestLimits limits;
  limits.maxPhotons = 1000;
  EXPECT_EQ(errorOf(1001, limits), std::make_pair(422, pointer));
  EXPECT_EQ(errorOf(1000, limits).first, 0);
}

}  // namespace
}  // namespace radiant
