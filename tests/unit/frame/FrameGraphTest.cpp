// The frame graph's order (issue 33): the planner orders the planned passes from their declarations
// (executionOrder in renderer/frame/FramePlanner.h), not from the registry: a pass runs after the
// producers of what it reads (not of what a producer publishes in prepare()), and beauty's writers run
// Add, then Over, then Transmit. The registry only breaks ties. Stand-ins for the rules, then the real
// descriptors planned with the registry forwards, backwards and rotated.
#include <algorithm>
#include <map>
#include <string>

#include <gtest/gtest.h>

#include "api/Validate.h"
#include "renderer/frame/FramePlanner.h"
#include "renderer/scene/BuiltinScenes.h"
#include "renderer/techniques/Registry.h"
#include "tests/support/StandInTechnique.h"

namespace radiant {
namespace {

using nlohmann::json;
using testing::StandInTechnique;

TechniqueInfo pass(std::string name, std::vector<std::string> inputs, std::vector<std::string> outputs,
                   bool addsToBeauty = false, BeautyBlend blend = BeautyBlend::Add) {
  TechniqueInfo i{std::move(name), "stand-in", std::move(inputs), {}, std::move(outputs), addsToBeauty, true};
  i.beautyBlend = blend;
  return i;
}

std::vector<std::string> names(const std::vector<Technique*>& passes) {
  std::vector<std::string> out;
  for (const Technique* t : passes) out.push_back(t->info().name);
  return out;
}

TEST(FrameGraph, ReadersRunAfterTheirProducersWhateverTheRegistryOrder) {
  StandInTechnique reader(pass("reader", {"maps"}, {"shaded"}, true));
  TechniqueInfo optional = pass("optional_reader", {}, {"extra"}, true);
  optional.optionalInputs = {"maps", "shaded"};
  StandInTechnique second(optional);
  StandInTechnique producer(pass("producer", {}, {"maps"}));
  EXPECT_EQ(names(executionOrder({&reader, &second, &producer})),
            (std::vector<std::string>{"producer", "reader", "optional_reader"}));
  EXPECT_EQ(names(executionOrder({&second, &producer, &reader})),
            (std::vector<std::string>{"producer", "reader", "optional_reader"}));
}

// What a producer publishes in prepare() is there before any execute: its readers keep their place.
TEST(FrameGraph, AProductPublishedInPrepareOrdersNothing) {
  TechniqueInfo photons = pass("photons", {}, {"indirect", "grid"}, true);
  photons.prepareOutputs = {"grid"};
  TechniqueInfo maps = pass("maps", {}, {"specular"}, true);
  maps.optionalInputs = {"grid"};
  StandInTechnique p(photons), m(maps);
  EXPECT_EQ(names(executionOrder({&m, &p})), (std::vector<std::string>{"maps", "photons"}));
  // Published in execute (no prepareOutputs), the grid orders its reader after it.
  photons.prepareOutputs.clear();
  StandInTechnique late(photons);
  EXPECT_EQ(names(executionOrder({&m, &late})), (std::vector<std::string>{"photons", "maps"}));
}

// beauty = a Ls + (1 - a) beauty and beauty = beauty T + C do not commute with the adds: every add
// first, then the blended surfaces, then the media; adds keep the registry's order among themselves.
TEST(FrameGraph, BeautyWritersRunAddThenOverThenTransmit) {
  StandInTechnique media(pass("media", {}, {"m"}, true, BeautyBlend::Transmit));
  StandInTechnique glass(pass("glass", {}, {}, true, BeautyBlend::Over));
  StandInTechnique a(pass("a", {}, {"x"}, true)), b(pass("b", {}, {"y"}, true));
  StandInTechnique off(pass("not_beauty", {}, {"z"}, false, BeautyBlend::Transmit));  // the blend needs adds_to_beauty
  EXPECT_EQ(names(executionOrder({&media, &off, &glass, &b, &a})),
            (std::vector<std::string>{"not_beauty", "b", "a", "glass", "media"}));
}

TEST(FrameGraph, ACycleIsAProgrammerErrorNamingItsPasses) {
  StandInTechnique x(pass("x", {"from_y"}, {"from_x"})), y(pass("y", {"from_x"}, {"from_y"}));
  StandInTechnique free(pass("free", {}, {"f"}));
  try {
    executionOrder({&free, &x, &y});
    FAIL() << "no throw";
  } catch (const std::logic_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("x, y"), std::string::npos) << what;
    EXPECT_EQ(what.find("free"), std::string::npos) << what;
  }
}

// The real descriptors: whatever the registry's order, the planned passes are the same, every pass runs
// after the planned producers of what it reads in execute(), and beauty's blends come in order. With
// the registry as it stands the order is the registry's own (so frames stay bit-identical).
TEST(FrameGraph, RealPlansFollowTheDeclarationsInEveryRegistryOrder) {
  auto registry = createTechniques();
  std::vector<Technique*> forwards;
  for (auto& t : registry) forwards.push_back(t.get());
  std::vector<std::vector<Technique*>> orders{forwards, {forwards.rbegin(), forwards.rend()}};
  for (std::size_t r = 1; r < forwards.size(); r += 4) {
    orders.push_back(forwards);
    std::rotate(orders.back().begin(), orders.back().begin() + r, orders.back().end());
  }
  const std::vector<json> requests = {
      json{{"scene", {{"builtin", "cornell_glass"}}}},
      json{{"scene", {{"builtin", "cornell_glass"}}}, {"passes", {{"light_volumes", json::object()}}}},
      json{{"scene", {{"builtin", "cornell_box"}}}, {"passes", {{"env_diffuse", {{"receivers", "*"}}}}},
           {"outputs", {{{"format", "exr"}, {"aovs", {"beauty", "indirect_diffuse", "ao"}}}}}},
      json{{"scene", {{"builtin", "cornell_box"}}}, {"passes", {{"reference", json::object()}}}},
      json{{"scene", {{"builtin", "explosion"}}}},
      json{{"scene", {{"builtin", "explosion"}}}, {"passes", {{"depth_impostors", json::object()}}}},
  };
  std::map<std::string, int> seen;
  for (const json& body : requests) {
    const api::RenderRequest request = api::parseRenderRequest(body);
    Scene scene = loadBuiltinScene(body["scene"]["builtin"]);
    // The explosion's crate blended (alphaMode BLEND): transparency runs between the adds and the media.
    if (body["scene"]["builtin"] == "explosion") scene.materials.at(2).alphaMode = AlphaMode::Blend;
    const FramePlan canonical = planFrame(forwards, scene, request);
    // Forwards: the registry's own order (its planned subsequence).
    std::vector<std::string> subsequence;
    for (Technique* t : forwards)
      if (std::count(canonical.passes.begin(), canonical.passes.end(), t)) subsequence.push_back(t->info().name);
    EXPECT_EQ(names(canonical.passes), subsequence) << body.dump();
    for (const auto& order : orders) {
      const FramePlan plan = planFrame(order, scene, request);
      std::vector<std::string> a = names(plan.passes), b = names(canonical.passes);
      std::sort(a.begin(), a.end());
      std::sort(b.begin(), b.end());
      EXPECT_EQ(a, b) << body.dump();
      std::map<std::string, std::size_t> at;
      for (std::size_t i = 0; i < plan.passes.size(); ++i) at[plan.passes[i]->info().name] = i;
      for (std::size_t i = 0; i < plan.passes.size(); ++i) {
        const TechniqueInfo& reader = plan.passes[i]->info();
        ++seen[reader.name];
        for (std::size_t k = 0; k < plan.passes.size(); ++k) {
          const TechniqueInfo& producer = plan.passes[k]->info();
          for (const std::string& out : producer.outputs) {
            const bool reads = std::count(reader.inputs.begin(), reader.inputs.end(), out) +
                                   std::count(reader.optionalInputs.begin(), reader.optionalInputs.end(), out) >
                               0;
            const bool inPrepare = std::count(producer.prepareOutputs.begin(), producer.prepareOutputs.end(), out) > 0;
            if (reads && !inPrepare && k != i) { EXPECT_LT(k, i) << reader.name << " reads " << out << ": " << body.dump(); }
          }
          if (reader.addsToBeauty && producer.addsToBeauty && producer.beautyBlend < reader.beautyBlend) {
            EXPECT_LT(k, i) << producer.name << " before " << reader.name;
          }
        }
      }
    }
  }
  // The requests plan the passes whose order matters: gbuffer, shadow maps, direct, specular before
  // caustics, photon_gi (its grid read by specular), the adds, transparency, the media.
  for (const char* name : {"gbuffer", "shadow_maps", "direct", "specular", "caustics", "photon_gi", "env_diffuse",
                           "light_volumes", "ambient_occlusion", "transparency", "spherical_billboards",
                           "depth_impostors", "reference"})
    EXPECT_GT(seen[name], 0) << name;
}

}  // namespace
}  // namespace radiant
