// The API schema is the single source of truth for technique names, parameters and AOVs; the
// renderer's registry must say the same thing, or a valid request could name a pass nothing runs.
#include <algorithm>
#include <map>
#include <set>

#include <gtest/gtest.h>

#include "api/Aovs.h"
#include "api/Validate.h"
#include "renderer/Renderer.h"
#include "renderer/frame/FramePlanner.h"
#include "renderer/techniques/Registry.h"

namespace radiant {
namespace {

TEST(SchemaConsistency, EveryTechniqueHasASchemaAndEverySchemaATechnique) {
  std::set<std::string> registry, schema;
  for (const auto& t : Renderer::techniques()) registry.insert(t.name);
  for (const auto& t : api::techniqueSchemas()) schema.insert(t.name);
  EXPECT_EQ(registry, schema);
}

// A technique's TechniqueInfo is its descriptor's (renderer/techniques/<name>/<name>.json): no
// technique declares its inputs, outputs, AOVs or light paths a second time in C++.
TEST(SchemaConsistency, EveryTechniqueIsWhatItsDescriptorDeclares) {
  for (const auto& t : createTechniques()) {
    const TechniqueInfo& info = t->info();
    const TechniqueInfo d = describedTechnique(info.name);
    EXPECT_EQ(info.description, d.description) << info.name;
    EXPECT_EQ(info.inputs, d.inputs) << info.name;
    EXPECT_EQ(info.optionalInputs, d.optionalInputs) << info.name;
    EXPECT_EQ(info.outputs, d.outputs) << info.name;
    EXPECT_EQ(info.addsToBeauty, d.addsToBeauty) << info.name;
    EXPECT_EQ(info.onByDefault, d.onByDefault) << info.name;
    EXPECT_EQ(info.lightPaths, d.lightPaths) << info.name;
    EXPECT_EQ(info.claimsWhenNamed, d.claimsWhenNamed) << info.name;
    EXPECT_EQ(info.exclusive, d.exclusive) << info.name;
    EXPECT_EQ(info.beautyBlend, d.beautyBlend) << info.name;
    EXPECT_EQ(info.prepareOutputs, d.prepareOutputs) << info.name;
    // Each AOV row a technique's outputs name was declared by one technique that outputs it.
    for (const std::string& out : info.outputs)
      if (const api::AovInfo* a = api::findAov(out)) {
        const api::TechniqueSchema* producer = api::findTechnique(a->producer);
        ASSERT_NE(producer, nullptr) << out;
        EXPECT_NE(std::find(producer->outputs.begin(), producer->outputs.end(), out), producer->outputs.end()) << out;
        EXPECT_FALSE(a->description.empty()) << out;
      }
  }
  EXPECT_THROW(describedTechnique("no_such_technique"), std::logic_error);
}

TEST(SchemaConsistency, EveryAovTheSchemaOffersHasAProducer) {
  std::set<std::string> produced{"beauty"};
  for (const auto& t : Renderer::techniques()) produced.insert(t.outputs.begin(), t.outputs.end());
  for (const auto& t : api::techniqueSchemas())
    for (const auto& aov : t.outputs) EXPECT_TRUE(produced.count(aov)) << t.name << " offers " << aov;
}

// The AOV table (api/Aovs.cpp) against the schema and the registry, in both directions.
std::set<std::string> schemaAovs() {
  std::set<std::string> names;
  const auto& e = api::renderRequestSchema()["properties"]["outputs"]["items"]["properties"]["aovs"]["items"]["enum"];
  for (const auto& n : e) names.insert(n.get<std::string>());
  return names;
}

// Several producers of one overwrite AOV are allowed only when at most one can run per frame: all are
// exclusive (TechniqueInfo::exclusive) and share a light-path class, and the table's producer is the one
// the ownership policy (FramePlanner.h, ownershipPolicy) gives that class when all of them are planned:
// the media techniques, whose AOVs spherical_billboards declares. Registry order plays no part.
bool oneProducerPerFrame(const std::vector<std::string>& names, const std::string& tableProducer) {
  std::vector<std::unique_ptr<Technique>> all = createTechniques();
  std::set<std::string> shared;
  bool first = true;
  for (const auto& t : all) {
    const TechniqueInfo& info = t->info();
    if (std::find(names.begin(), names.end(), info.name) == names.end()) continue;
    if (!info.exclusive) return false;
    const std::set<std::string> classes(info.lightPaths.begin(), info.lightPaths.end());
    if (first) shared = classes;
    std::erase_if(shared, [&](const std::string& c) { return !classes.count(c); });
    first = false;
  }
  // The policy's rank of `name` for `cls`: its place in the class's row, after the row if not in it.
  auto rank = [](const std::string& cls, const std::string& name) {
    for (const OwnershipRow& row : ownershipPolicy())
      if (row.lightPath == cls) {
        const auto it = std::find(row.order.begin(), row.order.end(), name);
        return static_cast<std::size_t>(it - row.order.begin());
      }
    return std::size_t{0};
  };
  for (const std::string& cls : shared) {
    std::string owner = names.front();
    for (const std::string& n : names)
      if (rank(cls, n) < rank(cls, owner) || (rank(cls, n) == rank(cls, owner) && n < owner)) owner = n;
    if (owner == tableProducer) return true;
  }
  return false;
}

TEST(SchemaConsistency, EveryAovTheSchemaNamesHasOneProducerOrAnAccumulateRule) {
  std::map<std::string, std::vector<std::string>> producers;
  for (const auto& t : Renderer::techniques())
    for (const auto& aov : t.outputs) producers[aov].push_back(t.name);
  const std::set<std::string> names = schemaAovs();
  EXPECT_GE(names.size(), 13u);
  for (const std::string& name : names) {
    const api::AovInfo* a = api::findAov(name);
    ASSERT_NE(a, nullptr) << "the schema offers AOV '" << name << "', which the AOV table does not declare";
    EXPECT_TRUE(a->requestable) << name;
    const auto it = producers.find(name);
    const std::size_t owners = it == producers.end() ? 0 : it->second.size();
    if (a->blend == api::AovBlend::Accumulate) {
      EXPECT_EQ(owners, 0u) << name << " accumulates: no technique may own it";
    } else {
      ASSERT_GE(owners, 1u) << name << " has no producer";
      if (owners > 1)
        EXPECT_TRUE(oneProducerPerFrame(it->second, a->producer))
            << name << " has several producers that could run in one frame";
      else
        EXPECT_EQ(it->second[0], a->producer) << name;
    }
  }
  // A technique output is either an AOV of the table, produced by that technique, or an internal
  // resource (depth_buffer) that no request can name.
  for (const auto& [aov, by] : producers) {
    const api::AovInfo* a = api::findAov(aov);
    if (!a) {
      EXPECT_FALSE(names.count(aov)) << by[0] << " writes " << aov;
      continue;
    }
    EXPECT_EQ(a->blend, api::AovBlend::Overwrite) << aov;
    if (by.size() > 1) EXPECT_TRUE(oneProducerPerFrame(by, a->producer)) << aov;
    else EXPECT_EQ(by, std::vector<std::string>{a->producer}) << aov;
  }
}

TEST(SchemaConsistency, EveryRequestableAovInTheTableIsInTheSchema) {
  std::set<std::string> registered;
  for (const auto& t : Renderer::techniques()) registered.insert(t.name);
  const std::set<std::string> names = schemaAovs();
  // Declared ahead of their technique (photon_gi on the lead's branch): named here, nowhere else.
  const std::set<std::string> awaitingTechnique{"indirect"};
  for (const api::AovInfo& a : api::aovTable()) {
    if (!a.requestable) {
      EXPECT_FALSE(names.count(a.name)) << a.name << " is not requestable but the schema offers it";
      continue;
    }
    if (a.blend == api::AovBlend::Overwrite && !registered.count(a.producer)) {
      EXPECT_TRUE(awaitingTechnique.count(a.name)) << a.name << ": producer " << a.producer << " is not registered";
      EXPECT_FALSE(names.count(a.name)) << a.name;
      continue;
    }
    EXPECT_TRUE(names.count(a.name)) << "the AOV table declares '" << a.name << "', the schema does not offer it";
  }
}

TEST(SchemaConsistency, AovTableIsWellFormed) {
  std::set<std::string> names, exrChannels;
  int accumulate = 0;
  for (std::size_t i = 0; i < api::aovTable().size(); ++i) {
    const api::AovInfo& a = api::aovTable()[i];
    EXPECT_EQ(a.id, static_cast<int>(i)) << a.name;
    EXPECT_TRUE(names.insert(a.name).second) << "duplicate AOV " << a.name;
    EXPECT_TRUE(a.channels == 1 || a.channels == 3 || a.channels == 4) << a.name;
    EXPECT_EQ(a.exr.size(), static_cast<std::size_t>(a.channels)) << a.name;
    for (const auto& c : a.exr) EXPECT_TRUE(exrChannels.insert(c).second) << "EXR channel " << c << " used twice";
    EXPECT_LE(a.firstChannel + a.channels, a.format == api::AovFormat::R32F ? 1 : 4) << a.name;
    accumulate += a.blend == api::AovBlend::Accumulate;
    if (a.blend == api::AovBlend::Accumulate) {
      EXPECT_TRUE(a.producer.empty()) << a.name;
    }
    if (!a.groundTruth.empty()) {
      // A ground truth is a mode of the reference pass (its schema's aov enum).
      const auto& modes = api::findTechnique("reference")->params.at("aov").at("enum");
      EXPECT_NE(std::find(modes.begin(), modes.end(), a.groundTruth), modes.end())
          << a.name << " ground truth " << a.groundTruth;
    }
  }
  EXPECT_EQ(accumulate, 1);  // beauty
  EXPECT_EQ(api::findAov("beauty")->exr, (std::vector<std::string>{"R", "G", "B"}));
  EXPECT_EQ(api::findAov("depth")->exr, std::vector<std::string>{"depth.Z"});
  // The material AOV carries all four G-buffer channels: metallic, roughness, occlusion, transmission.
  EXPECT_EQ(api::findAov("material")->exr,
            (std::vector<std::string>{"material.R", "material.G", "material.B", "material.A"}));
  EXPECT_EQ(api::findAov("specular")->groundTruth, "");  // scored against nothing rather than full beauty
  EXPECT_EQ(api::findAov("no_such_aov"), nullptr);
}

// A pass that writes what it did not declare fails the frame (the Renderer throws on it).
TEST(SchemaConsistency, UndeclaredWritesAreFound) {
  TechniqueInfo info{"specular", "", {}, {}, {"specular"}, /*addsToBeauty=*/true, false};
  EXPECT_EQ(undeclaredWrite(info, {"specular", "beauty"}), "");
  EXPECT_EQ(undeclaredWrite(info, {"specular", "direct"}), "direct");
  info.addsToBeauty = false;
  EXPECT_EQ(undeclaredWrite(info, {"specular", "beauty"}), "beauty");  // beauty needs addsToBeauty
  EXPECT_EQ(undeclaredWrite(info, {}), "");
}

// Declared access (FramePlanner's declaredAccess, enforced by FrameResources in each pass scope): every
// Read names a resource some technique writes or a frame resource the Renderer provides; Accumulate is
// beauty, for exactly the passes that add to it; the environment map is read, never written, by passes.
TEST(SchemaConsistency, EveryDeclaredReadHasAWriterAndOnlyBeautyAccumulates) {
  std::vector<std::unique_ptr<Technique>> all = createTechniques();
  std::vector<Technique*> ptrs;
  std::set<std::string> written{"beauty", kEnvironmentMap};
  for (auto& t : all) {
    ptrs.push_back(t.get());
    written.insert(t->info().outputs.begin(), t->info().outputs.end());
  }
  bool directReadsEnvironment = false;
  for (auto& t : all) {
    const TechniqueInfo& info = t->info();
    int accumulates = 0;
    for (const ResourceAccess& a : declaredAccess(info)) {
      if (a.access == Access::Read) {
        EXPECT_TRUE(written.count(a.name)) << info.name << " reads " << a.name;
      }
      if (a.access == Access::Write) {
        EXPECT_NE(a.name, kEnvironmentMap) << info.name;
      }
      if (a.access == Access::Accumulate) {
        EXPECT_EQ(a.name, "beauty") << info.name;
        ++accumulates;
      }
      directReadsEnvironment |= info.name == "direct" && a.name == kEnvironmentMap && a.access == Access::Read;
    }
    EXPECT_EQ(accumulates, info.addsToBeauty ? 1 : 0) << info.name;
  }
  EXPECT_TRUE(directReadsEnvironment);
  const std::set<std::string> shared = sharedResources(ptrs);
  for (const char* name : {"beauty", kEnvironmentMap, "gbuffer_position", "media", "specular_maps", "shadow_maps"})
    EXPECT_TRUE(shared.count(name)) << name;
  EXPECT_FALSE(shared.count("ao_raw"));  // a pass's own intermediate target
}

// Each technique declares what scores its AOVs (Technique::groundTruth); the compare block only asks.
TEST(SchemaConsistency, TechniquesDeclareTheirGroundTruth) {
  std::map<std::string, std::unique_ptr<Technique>> byName;
  for (auto& t : createTechniques()) byName[t->info().name] = std::move(t);
  // Every AOV with a producer: the producer's answer agrees with the AOV table's reference mode, and
  // every mode it names is one the reference pass has.
  const auto& modes = api::findTechnique("reference")->params.at("aov").at("enum");
  for (const api::AovInfo& a : api::aovTable()) {
    if (a.producer.empty() || !byName.count(a.producer)) continue;
    const GroundTruth g = byName.at(a.producer)->groundTruth(Params(api::techniqueParams(a.producer)), a.name);
    EXPECT_EQ(g.exists(), !a.groundTruth.empty()) << a.name;
    if (!g.exists()) continue;
    EXPECT_EQ(g.reference.at("aov"), a.groundTruth) << a.name;
    EXPECT_NE(std::find(modes.begin(), modes.end(), g.reference.at("aov")), modes.end()) << a.name;
    // What it returns is a valid set of the reference pass's parameters.
    EXPECT_NO_THROW(api::techniqueParams("reference", g.reference)) << a.name;
  }
  // AO's ground truth follows its parameters: the radius, and the definition its method estimates.
  const Technique& ao = *byName.at("ambient_occlusion");
  const GroundTruth vol = ao.groundTruth(Params(api::techniqueParams("ambient_occlusion", {{"radius", 2.0}})), "ao");
  EXPECT_EQ(vol.reference, (nlohmann::json{{"aov", "ao"}, {"ao_radius", 2.0}, {"ao_definition", "volumetric"}}));
  const GroundTruth gtao = ao.groundTruth(
      Params(api::techniqueParams("ambient_occlusion", {{"radius", 0.25}, {"method", "gtao"}})), "ao");
  EXPECT_EQ(gtao.reference, (nlohmann::json{{"aov", "ao"}, {"ao_radius", 0.25}, {"ao_definition", "cosine"}}));
  // env_diffuse's indirect_diffuse holds the bounces its cube maps compute: 2 .. 1 + bounces.
  const Technique& env = *byName.at("env_diffuse");
  EXPECT_EQ(env.groundTruth(Params(api::techniqueParams("env_diffuse", {{"bounces", 3}})), "indirect_diffuse").reference,
            (nlohmann::json{{"aov", "indirect"}, {"max_bounces", 4}}));
  // The specular AOV has none: it is refused, not scored against beauty.
  EXPECT_FALSE(byName.at("specular")->groundTruth(Params(api::techniqueParams("specular")), "specular").exists());
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
