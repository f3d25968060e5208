// One owner of the media AOV per frame (FramePlanner, TechniqueInfo::exclusive): every media technique
// writes the media AOVs and composes them into beauty, so exactly one runs. spherical_billboards
// (first in the planner's ownership policy) owns the light-path class "media" by default; a media
// technique the request names (claimsWhenNamed) owns it instead, and the others are skipped with
// "media is owned by X".
// Naming two media techniques is a 422 whose pointer is the one the policy ranks later. Stand-ins
// for depth_impostors and illumination_network, registered after spherical_billboards as the registry
// has them.
#include <algorithm>

#include <gtest/gtest.h>

#include "renderer/frame/FramePlanner.h"
#include "renderer/techniques/gbuffer/GBuffer.h"
#include "renderer/techniques/spherical_billboards/SphericalBillboards.h"
#include "tests/support/SceneBuilder.h"
#include "tests/support/StandInTechnique.h"

namespace radiant {
namespace {

// depth_impostors or illumination_network as the planner sees them: exclusive owners of "media" when named.
testing::StandInTechnique mediaStandIn(std::string name, bool runs) {
  return testing::StandInTechnique({std::move(name), "stand-in", {}, {"gbuffer_position"}, {"media", "media_transmittance"},
                                    true, false, {"media"}, /*claimsWhenNamed=*/true, /*exclusive=*/true},
                                   runs);
}

api::RenderRequest withMedia(std::vector<std::string> named, std::vector<std::string> aovs = {"beauty"}) {
  api::RenderRequest r;
  api::ParticleSystem s;
  s.particles.push_back(api::Particle{});
  r.media.push_back(s);
  for (const auto& n : named) r.passes[n] = nlohmann::json::object();
  r.outputs = {api::OutputSpec{api::ImageFormat::Exr, std::move(aovs), false}};
  return r;
}

bool planned(const FramePlan& p, const std::string& name) {
  return std::any_of(p.passes.begin(), p.passes.end(), [&](Technique* t) { return t->info().name == name; });
}

struct MediaRegistry {
  GBufferPass gbuffer;
  SphericalBillboardsPass billboards;
  testing::StandInTechnique impostors = mediaStandIn("depth_impostors", true);
  testing::StandInTechnique network = mediaStandIn("illumination_network", true);
  std::vector<Technique*> all() { return {&gbuffer, &billboards, &impostors, &network}; }
};

TEST(MediaOwnership, SphericalBillboardsByDefault) {
  MediaRegistry reg;
  const Scene scene = testing::SceneBuilder().build("empty");
  FramePlan p = planFrame(reg.all(), scene, withMedia({}));
  EXPECT_EQ(p.lightPaths.at("media"), "spherical_billboards");
  EXPECT_TRUE(planned(p, "spherical_billboards"));
  EXPECT_FALSE(planned(p, "depth_impostors"));  // neither named nor on by default
  // Asking for the media AOV wants every producer of it; still only the default owner runs.
  p = planFrame(reg.all(), scene, withMedia({}, {"beauty", "media", "media_transmittance"}));
  EXPECT_EQ(p.lightPaths.at("media"), "spherical_billboards");
  EXPECT_TRUE(planned(p, "spherical_billboards"));
  EXPECT_FALSE(planned(p, "depth_impostors"));
  EXPECT_FALSE(planned(p, "illumination_network"));
  EXPECT_EQ(p.skipped.at("depth_impostors"), "media is owned by spherical_billboards");
  EXPECT_EQ(p.skipped.at("illumination_network"), "media is owned by spherical_billboards");
}

TEST(MediaOwnership, TheNamedMediaTechniqueOwnsItAndTheOthersAreSkipped) {
  MediaRegistry reg;
  const Scene scene = testing::SceneBuilder().build("empty");
  for (const std::string name : {"depth_impostors", "illumination_network"}) {
    const FramePlan p = planFrame(reg.all(), scene, withMedia({name}, {"beauty", "media"}));
    EXPECT_EQ(p.lightPaths.at("media"), name);
    EXPECT_TRUE(planned(p, name));
    EXPECT_FALSE(planned(p, "spherical_billboards"));
    EXPECT_EQ(p.skipped.at("spherical_billboards"), "media is owned by " + name);
    EXPECT_EQ(std::count_if(p.passes.begin(), p.passes.end(),
                            [](Technique* t) {
                              const auto& o = t->info().outputs;
                              return std::find(o.begin(), o.end(), "media") != o.end();
                            }),
              1);
  }
  // Naming the default owner is the same as not naming a media technique.
  const FramePlan p = planFrame(reg.all(), scene, withMedia({"spherical_billboards"}, {"beauty", "media"}));
  EXPECT_EQ(p.lightPaths.at("media"), "spherical_billboards");
  EXPECT_EQ(p.skipped.at("depth_impostors"), "media is owned by spherical_billboards");
}

TEST(MediaOwnership, NamingTwoMediaTechniquesIsA422NamingTheSecond) {
  MediaRegistry reg;
  const Scene scene = testing::SceneBuilder().build("empty");
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"depth_impostors", "illumination_network"}, "/passes/illumination_network"},
      {{"spherical_billboards", "depth_impostors"}, "/passes/depth_impostors"},
      {{"spherical_billboards", "illumination_network", "depth_impostors"}, "/passes/depth_impostors"},
  };
  for (const auto& [named, pointer] : cases) {
    try {
      planFrame(reg.all(), scene, withMedia(named));
      ADD_FAILURE() << "accepted " << pointer;
    } catch (const api::ApiError& e) {
      EXPECT_EQ(e.status, 422);
      EXPECT_EQ(e.pointer, pointer);
      EXPECT_NE(std::string(e.what()).find("media"), std::string::npos) << e.what();
    }
  }
  // A media technique turned off does not conflict: passes.spherical_billboards = false is not named.
  api::RenderRequest off = withMedia({"depth_impostors"});
  off.disabledPasses.insert("spherical_billboards");
  const FramePlan p = planFrame(reg.all(), scene, off);
  EXPECT_EQ(p.lightPaths.at("media"), "depth_impostors");
}

TEST(MediaOwnership, ANamedTechniqueThatCannotRunLeavesTheMediaToTheDefault) {
  GBufferPass gbuffer;
  SphericalBillboardsPass billboards;
  testing::StandInTechnique impostors = mediaStandIn("depth_impostors", false);
  const std::vector<Technique*> all{&gbuffer, &billboards, &impostors};
  const Scene scene = testing::SceneBuilder().build("empty");
  const FramePlan p = planFrame(all, scene, withMedia({"depth_impostors"}));
  EXPECT_EQ(p.skipped.at("depth_impostors"), "stand-in skips");
  EXPECT_EQ(p.lightPaths.at("media"), "spherical_billboards");
  EXPECT_TRUE(planned(p, "spherical_billboards"));
  // No media at all: every media technique is skipped for that reason, and no one owns the class.
  api::RenderRequest none;
  none.passes["depth_impostors"] = nlohmann::json::object();
  const FramePlan q = planFrame(all, scene, none);
  EXPECT_FALSE(q.lightPaths.count("media"));
  EXPECT_NE(q.skipped.at("spherical_billboards").find("no participating media"), std::string::npos);
}

}  // namespace
}  // namespace radiant
