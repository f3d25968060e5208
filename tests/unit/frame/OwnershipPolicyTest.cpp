// Light-path ownership as data (issue 33): the planner gives a class that several planned techniques
// supply to the one its ownership policy ranks first (renderer/frame/FramePlanner.h), not to the first
// in registry order. The policy must cover every class two real descriptors supply, and the plans of
// the real techniques must not change when the registry is reordered.
#include <algorithm>
#include <map>
#include <set>

#include <gtest/gtest.h>

#include "api/LightPaths.h"
#include "api/Validate.h"
#include "renderer/frame/FramePlanner.h"
#include "renderer/scene/BuiltinScenes.h"
#include "renderer/techniques/Registry.h"

namespace radiant {
namespace {

using nlohmann::json;

// Every class that two or more descriptors supply has a row, and the row lists exactly its suppliers;
// every row names a real class. A technique that starts to contest a class fails here until the
// policy says who wins.
TEST(LightPathOwnership, EveryContestedClassHasAPolicyRowListingItsSuppliers) {
  std::map<std::string, std::set<std::string>> suppliers;
  for (const auto& t : api::techniqueSchemas())
    for (const auto& cls : t.lightPaths) {
      EXPECT_NE(api::lightPathBit(cls), 0u) << t.name << ": " << cls;
      suppliers[cls].insert(t.name);
    }
  std::set<std::string> rows;
  for (const OwnershipRow& row : ownershipPolicy()) {
    const std::string cls(row.lightPath);
    EXPECT_NE(api::lightPathBit(cls), 0u) << cls;
    EXPECT_TRUE(rows.insert(cls).second) << cls << " has two rows";
    const std::set<std::string> listed(row.order.begin(), row.order.end());
    EXPECT_EQ(listed.size(), row.order.size()) << cls << " lists a technique twice";
    EXPECT_EQ(listed, suppliers[cls]) << cls;
  }
  for (const auto& [cls, names] : suppliers)
    if (names.size() > 1) { EXPECT_TRUE(rows.count(cls)) << cls << " is supplied by " << names.size() << " techniques"; }
}

// The registry, forwards and backwards, plans the same passes with the same owners: ownership is the
// policy's. Requests that move classes: the default frame, env_diffuse's AOV (LD+DE), light_volumes
// named (LS+DE, LG+DE), a media technique named.
TEST(LightPathOwnership, OwnersDoNotDependOnTheRegistrysOrder) {
  auto registry = createTechniques();
  std::vector<Technique*> forwards;
  for (auto& t : registry) forwards.push_back(t.get());
  std::vector<Technique*> backwards(forwards.rbegin(), forwards.rend());
  const std::vector<json> requests = {
      json{{"scene", {{"builtin", "cornell_glass"}}}},
      json{{"scene", {{"builtin", "cornell_glass"}}}, {"passes", {{"light_volumes", json::object()}}}},
      json{{"scene", {{"builtin", "cornell_box"}}}, {"passes", {{"env_diffuse", {{"receivers", "*"}}}}},
           {"outputs", {{{"format", "exr"}, {"aovs", {"beauty", "indirect_diffuse"}}}}}},
      json{{"scene", {{"builtin", "cornell_box"}}}, {"ambient", {0.5, 0.5, 0.5}}},
      json{{"scene", {{"builtin", "explosion"}}}},
      json{{"scene", {{"builtin", "explosion"}}}, {"passes", {{"illumination_network", json::object()}}}},
  };
  int checked = 0;
  for (const json& body : requests) {
    const api::RenderRequest request = api::parseRenderRequest(body);
    const Scene scene = loadBuiltinScene(body["scene"]["builtin"]);
    const FramePlan a = planFrame(forwards, scene, request), b = planFrame(backwards, scene, request);
    EXPECT_EQ(a.lightPaths, b.lightPaths) << body.dump();
    EXPECT_EQ(a.owned, b.owned) << body.dump();
    EXPECT_EQ(a.skipped, b.skipped) << body.dump();
    std::set<std::string> pa, pb;
    for (Technique* t : a.passes) pa.insert(t->info().name);
    for (Technique* t : b.passes) pb.insert(t->info().name);
    EXPECT_EQ(pa, pb) << body.dump();
    // The masks are the classes' bits.
    for (const auto& [cls, owner] : a.lightPaths)
      if (api::lightPathBit(cls)) { EXPECT_TRUE(a.owned.at(owner) & api::lightPathBit(cls)) << cls; }
    checked += !a.lightPaths.empty();
  }
  EXPECT_EQ(checked, static_cast<int>(requests.size()));
  // What the requests moved, as the policy says.
  const auto plan = [&](const json& body) {
    return planFrame(backwards, loadBuiltinScene(body["scene"]["builtin"]), api::parseRenderRequest(body));
  };
  EXPECT_EQ(plan(requests[0]).lightPaths.at("LS+DE"), "caustics");
  EXPECT_EQ(plan(requests[1]).lightPaths.at("LS+DE"), "light_volumes");
  EXPECT_EQ(plan(requests[2]).lightPaths.at("LD+DE"), "env_diffuse");
  EXPECT_EQ(plan(requests[3]).lightPaths.at("L(sky)DE"), "photon_gi");
  EXPECT_EQ(plan(requests[3]).lightPaths.at("L(sky)GE"), "direct");
  EXPECT_EQ(plan(requests[4]).lightPaths.at("media"), "spherical_billboards");
  EXPECT_EQ(plan(requests[5]).lightPaths.at("media"), "illumination_network");
}

}  // namespace
}  // namespace radiant
