// The API schema is the single source of truth for technique names, parameters and AOVs; the
// renderer's registry must say the same thing, or a valid request could name a pass nothing runs.
#include <algorithm>
#include <set>

#include <gtest/gtest.h>

#include "api/Validate.h"
#include "renderer/Renderer.h"

namespace radiant {
namespace {

TEST(SchemaConsistency, EveryTechniqueHasASchemaAndEverySchemaATechnique) {
  std::set<std::string> registry, schema;
  for (const auto& t : Renderer::techniques()) registry.insert(t.name);
  for (const auto& t : api::techniqueSchemas()) schema.insert(t.name);
  EXPECT_EQ(registry, schema);
}

TEST(SchemaConsistency, EveryAovTheSchemaOffersHasAProducer) {
  std::set<std::string> produced{"beauty"};
  for (const auto& t : Renderer::techniques()) produced.insert(t.outputs.begin(), t.outputs.end());
  for (const auto& t : api::techniqueSchemas())
    for (const auto& aov : t.outputs) EXPECT_TRUE(produced.count(aov)) << t.name << " offers " << aov;
}

TEST(SchemaConsistency, DefaultsComeFromTheSchema) {
  const auto ao = api::techniqueParams("ambient_occlusion");
  EXPECT_EQ(ao.at("radius").get<double>(), 0.5);
  EXPECT_EQ(ao.at("method").get<std::string>(), "volumetric");
  const auto given = api::techniqueParams("shadow_maps", {{"shadow_map_size", 512}});
  EXPECT_EQ(given.at("shadow_map_size").get<int>(), 512);
  EXPECT_EQ(given.at("normal_offset").get<double>(), 1.5);
  try {
    api::techniqueParams("shadow_maps", {{"shadow_map_size", 1}});
    FAIL() << "out of range accepted";
  } catch (const api::ApiError& e) {
    EXPECT_EQ(e.status, 422);
    EXPECT_EQ(e.pointer, "/passes/shadow_maps/shadow_map_size");
  }
}

}  // namespace
}  // namespace radiant
