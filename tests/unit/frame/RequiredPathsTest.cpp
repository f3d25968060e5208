// A technique that must own a light-path class to run (TechniqueInfo::requiredPaths: photon_gi's
// LD+DE, which its photons carry whatever owns it) is dropped by the planner where another planned
// technique owns that class ("LD+DE is owned by env_diffuse"), and the classes are handed out again
// without it: what it would have supplied goes to the next claimant. A request naming both is a 422
// from the planner, not from a pass. Stand-ins, owning as the planner's ownership policy says
// (env_diffuse, then photon_gi, for LD+DE; photon_gi, then ambient_occlusion, for L(sky)DE), and a pass
// that reads photon_gi's output.
#include <algorithm>

#include <gtest/gtest.h>

#include "renderer/frame/FramePlanner.h"
#include "tests/support/SceneBuilder.h"
#include "tests/support/StandInTechnique.h"

namespace radiant {
namespace {

using testing::StandInTechnique;

TechniqueInfo info(std::string name, std::vector<std::string> outputs, std::vector<std::string> paths, bool onByDefault,
                   std::vector<std::string> required = {}, std::vector<std::string> inputs = {}) {
  TechniqueInfo i{std::move(name), "stand-in", std::move(inputs), {}, std::move(outputs), true, onByDefault,
                  std::move(paths)};
  i.requiredPaths = std::move(required);
  return i;
}

struct Registry {
  explicit Registry(bool envRuns = true)
      : env(info("env_diffuse", {"indirect_diffuse"}, {"LD+DE"}, false), envRuns),
        photons(info("photon_gi", {"indirect", "photon_grid"}, {"LD+DE", "L(sky)DE"}, true, {"LD+DE"})),
        ao(info("ambient_occlusion", {"ao"}, {"L(sky)DE"}, true)),
        reader(info("grid_reader", {"grid_view"}, {}, false, {}, {"photon_grid"})) {}
  StandInTechnique env, photons, ao, reader;
  std::vector<Technique*> all() { return {&env, &photons, &ao, &reader}; }
};

api::RenderRequest asking(std::vector<std::string> named, std::vector<std::string> aovs = {"beauty"}) {
  api::RenderRequest r;
  for (const auto& n : named) r.passes[n] = nlohmann::json::object();
  r.outputs = {api::OutputSpec{api::ImageFormat::Exr, std::move(aovs), false}};
  return r;
}

bool planned(const FramePlan& p, const std::string& name) {
  return std::any_of(p.passes.begin(), p.passes.end(), [&](Technique* t) { return t->info().name == name; });
}

TEST(RequiredPaths, TheTechniqueThatLosesAClassItRequiresIsDroppedAndItsOtherClassesGoToTheNextClaimant) {
  const Scene scene = testing::SceneBuilder().build("empty");
  Registry reg;
  // By default photon_gi owns both of its classes; ambient_occlusion would own nothing and nothing reads
  // its AOV: culled (below).
  FramePlan p = planFrame(reg.all(), scene, asking({}));
  EXPECT_TRUE(planned(p, "photon_gi"));
  EXPECT_FALSE(planned(p, "ambient_occlusion"));
  EXPECT_EQ(p.lightPaths.at("LD+DE"), "photon_gi");
  EXPECT_EQ(p.lightPaths.at("L(sky)DE"), "photon_gi");
  // env_diffuse planned (here for its AOV, not named): it owns LD+DE, photon_gi goes, and the sky's
  // first bounce, which photon_gi held, is ambient_occlusion's.
  p = planFrame(reg.all(), scene, asking({}, {"beauty", "indirect_diffuse"}));
  EXPECT_FALSE(planned(p, "photon_gi"));
  EXPECT_EQ(p.skipped.at("photon_gi"), "LD+DE is owned by env_diffuse");
  EXPECT_EQ(p.lightPaths.at("LD+DE"), "env_diffuse");
  EXPECT_EQ(p.lightPaths.at("L(sky)DE"), "ambient_occlusion");
  // Named: the same.
  p = planFrame(reg.all(), scene, asking({"env_diffuse"}));
  EXPECT_EQ(p.skipped.at("photon_gi"), "LD+DE is owned by env_diffuse");
  // A pass that needs what the dropped one produces is dropped with it, saying why.
  p = planFrame(reg.all(), scene, asking({"env_diffuse", "grid_reader"}));
  EXPECT_FALSE(planned(p, "grid_reader"));
  EXPECT_EQ(p.skipped.at("grid_reader"),
            "needs 'photon_grid', which photon_gi does not produce: LD+DE is owned by env_diffuse");
}

TEST(RequiredPaths, ANamedTechniqueThatCannotRunLeavesTheClassToTheOther) {
  const Scene scene = testing::SceneBuilder().build("empty");
  Registry reg(/*envRuns=*/false);
  const FramePlan p = planFrame(reg.all(), scene, asking({"env_diffuse"}));
  EXPECT_EQ(p.skipped.at("env_diffuse"), "stand-in skips");
  EXPECT_TRUE(planned(p, "photon_gi"));
  EXPECT_EQ(p.lightPaths.at("LD+DE"), "photon_gi");
}

TEST(RequiredPaths, NamingBothIsA422FromThePlannerNamingTheLaterOne) {
  const Scene scene = testing::SceneBuilder().build("empty");
  Registry reg;
  try {
    planFrame(reg.all(), scene, asking({"photon_gi", "env_diffuse"}));
    ADD_FAILURE() << "accepted";
  } catch (const api::ApiError& e) {
    EXPECT_EQ(e.status, 422);
    EXPECT_EQ(e.type, "conflicting-passes");
    EXPECT_EQ(e.pointer, "/passes/photon_gi");
    EXPECT_NE(std::string(e.what()).find("LD+DE"), std::string::npos) << e.what();
  }
  // Turned off is not named: passes.photon_gi = false beside env_diffuse is fine.
  api::RenderRequest off = asking({"env_diffuse"});
  off.disabledPasses.insert("photon_gi");
  const FramePlan p = planFrame(reg.all(), scene, off);
  EXPECT_EQ(p.lightPaths.at("LD+DE"), "env_diffuse");
  // Two techniques that share a class neither requires do not conflict (ambient_occlusion, photon_gi).
  EXPECT_NO_THROW(planFrame(reg.all(), scene, asking({"photon_gi", "ambient_occlusion"})));
}

// The frame graph culls what nothing reads: a planned pass that the request does not name, whose outputs
// neither the request nor a kept pass reads, and that adds nothing to beauty (it owns none of the
// classes it supplies) is dropped with the reason; asked for, read or named, it runs.
TEST(RequiredPaths, APassThatOwnsNothingAndWhoseOutputsNothingReadsIsCulled) {
  const Scene scene = testing::SceneBuilder().build("empty");
  Registry reg;
  FramePlan p = planFrame(reg.all(), scene, asking({}));
  EXPECT_FALSE(planned(p, "ambient_occlusion"));
  EXPECT_EQ(p.skipped.at("ambient_occlusion"),
            "culled: nothing in the frame reads what it writes (ao) and its light paths are owned (L(sky)DE by "
            "photon_gi)");
  EXPECT_EQ(p.owned.count("ambient_occlusion"), 0u);
  // Its AOV asked for: it runs (owning nothing).
  p = planFrame(reg.all(), scene, asking({}, {"beauty", "ao"}));
  EXPECT_TRUE(planned(p, "ambient_occlusion"));
  EXPECT_EQ(p.owned.at("ambient_occlusion"), 0u);
  // Named: it runs.
  p = planFrame(reg.all(), scene, asking({"ambient_occlusion"}));
  EXPECT_TRUE(planned(p, "ambient_occlusion"));
  // Read by a kept pass: it runs.
  StandInTechnique reader(info("ao_reader", {"ao_view"}, {}, false, {}, {"ao"}));
  std::vector<Technique*> withReader = reg.all();
  withReader.push_back(&reader);
  p = planFrame(withReader, scene, asking({"ao_reader"}));
  EXPECT_TRUE(planned(p, "ao_reader"));
  EXPECT_TRUE(planned(p, "ambient_occlusion"));
  // photon_gi turned off: ambient_occlusion owns the sky's first bounce and runs for beauty.
  api::RenderRequest off = asking({});
  off.disabledPasses.insert("photon_gi");
  p = planFrame(reg.all(), scene, off);
  EXPECT_TRUE(planned(p, "ambient_occlusion"));
  EXPECT_EQ(p.lightPaths.at("L(sky)DE"), "ambient_occlusion");
}

}  // namespace
}  // namespace radiant
