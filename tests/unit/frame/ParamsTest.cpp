// A technique's parameters have one source: the schema (renderer/techniques/*/*.json) gives every one a
// default, api::techniqueParams fills them in, and Params::get reads them without a fallback of its
// own (issue 33: the C++ fallbacks had drifted from the schema, e.g. photon_gi's ppm_alpha 2/3 against
// 0.6667, light_volumes' sigma_scale a constant beside 1.58). A technique reads them through the
// struct generated from its schema (generated/params/<name>_params.h, api/tools/param_structs.cpp):
// fields and enums the compiler checks instead of string keys.
#include <cstdint>
#include <functional>
#include <map>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "api/Validate.h"
#include "params/every_technique_params.h"
#include "renderer/frame/Technique.h"
#include "renderer/techniques/ambient_occlusion/AmbientOcclusion.h"
#include "tests/support/Expect.h"

namespace radiant {
namespace {

TEST(Params, TheSchemaFillsEveryParameterOfEveryTechnique) {
  for (const auto& t : api::techniqueSchemas()) {
    const Params params(api::techniqueParams(t.name));
    for (const auto& [key, spec] : t.params.items()) {
      ASSERT_TRUE(params.json().contains(key)) << t.name << "." << key;
      EXPECT_FALSE(params.json().at(key).is_null()) << t.name << "." << key;
      EXPECT_EQ(params.json().at(key), spec.at("default")) << t.name << "." << key;
    }
  }
  // What a pass reads is what the schema says, to the last digit.
  const Params photons(api::techniqueParams("photon_gi"));
  EXPECT_EQ(photons.get<double>("ppm_alpha"), 0.6667);
  EXPECT_EQ(photons.get<int>("photons"), 250000);
  EXPECT_EQ(photons.get<std::string>("h_schedule"), "paper");
}

TEST(Params, AKeyTheSchemaDoesNotDeclareIsAProgrammerErrorNamingIt) {
  const Params params(api::techniqueParams("photon_gi"));
  try {
    params.get<float>("no_such_key");
    FAIL() << "no exception";
  } catch (const std::logic_error& e) {
    EXPECT_NE(std::string(e.what()).find("no_such_key"), std::string::npos) << e.what();
  }
  EXPECT_THROW(Params().get<int>("photons"), std::logic_error);  // not from the schema
}

// Every technique's struct, by technique name: each reads a Params through its generated from().
using Reader = std::function<void(const Params&)>;
template <class... S>
std::map<std::string, Reader> readers() {
  std::map<std::string, Reader> m;
  ((m[S::kTechnique] = [](const Params& p) { (void)S::from(p); }), ...);
  return m;
}
template <class... S>
std::map<std::string, Reader> readersOf(std::tuple<S...>*) {
  return readers<S...>();
}
const std::map<std::string, Reader>& everyStruct() {
  static const auto m = readersOf(static_cast<EveryTechniqueParams*>(nullptr));
  return m;
}

// Every technique's struct reads its schema's defaults: a field whose key or type (an integer enum
// read as a string, a seed past int) no longer matches the schema throws here, not in a frame.
TEST(Params, EveryTechniquesTypedStructReadsItsSchemasDefaults) {
  for (const auto& t : api::techniqueSchemas()) {
    ASSERT_TRUE(everyStruct().count(t.name)) << t.name << ": no generated struct (every_technique_params.h)";
    EXPECT_NO_THROW(everyStruct().at(t.name)(Params(api::techniqueParams(t.name)))) << t.name;
  }
  const PhotonGiParams photons = PhotonGiParams::from(Params(api::techniqueParams("photon_gi")));
  EXPECT_EQ(photons.ppm_alpha, 0.6667);
  EXPECT_EQ(photons.photons, 250000);
  EXPECT_EQ(photons.h_schedule, PhotonGiParams::HSchedule::kPaper);
  EXPECT_FALSE(photons.given.photons);
  EXPECT_STREQ(PhotonGiParams::toString(photons.method), "gather");
}

// A pass reads its parameters without clamping them: no value outside the schema's range reaches it
// (api::techniqueParams is a 422 naming the field, for the HTTP route and for Renderer alike), and
// where the range feeds a fixed capacity the schema's maximum is that capacity.
TEST(Params, ASchemasRangeIsWhatItsPassCanHold) {
  for (const auto& [technique, key, outside] : std::vector<std::tuple<std::string, std::string, nlohmann::json>>{
           {"specular", "layers", 7}, {"specular", "max_depth", 0}, {"caustics", "cube_resolution", 2048},
           {"caustics", "splat_radius", 0.0}, {"ambient_occlusion", "samples", 65}, {"ambient_occlusion", "radius", 0.0}}) {
    const api::ApiError e = testing::thrownApiError([&] { api::techniqueParams(technique, {{key, outside}}); });
    EXPECT_EQ(e.status, 422) << technique << "." << key;
    EXPECT_NE(e.pointer.find(key), std::string::npos) << e.pointer;
  }
  // AO's std140 sample block holds ao::kMaxSamples kernel samples (buildSampleBlock throws above it).
  const nlohmann::json& samples = api::findTechnique("ambient_occlusion")->params.at("samples");
  EXPECT_EQ(samples.at("maximum").get<int>(), ao::kMaxSamples);
  EXPECT_EQ(samples.at("minimum").get<int>(), 1);
}

// Every value of every string enum parses (the generated parse lists the schema's values), and a value
// the schema does not hold is a programmer error naming the parameter.
TEST(Params, EveryEnumValueOfEverySchemaParses) {
  int values = 0;
  for (const auto& t : api::techniqueSchemas())
    for (const auto& [key, spec] : t.params.items()) {
      if (spec.at("type") != "string" || !spec.contains("enum")) continue;
      for (const auto& v : spec["enum"]) {
        EXPECT_NO_THROW(everyStruct().at(t.name)(Params(api::techniqueParams(t.name, nlohmann::json{{key, v}}))))
            << t.name << "." << key << " = " << v;
        ++values;
      }
    }
  EXPECT_GE(values, 50);
  EXPECT_EQ(ReferenceParams::from(Params(api::techniqueParams("reference", {{"aov", "media_transmittance"}}))).aov,
            ReferenceParams::Aov::kMediaTransmittance);
  EXPECT_EQ(LightVolumesParams::parseSplit("2d"), LightVolumesParams::Split::k2d);
  try {
    CausticsParams::parseMethod("splat ");
    FAIL() << "no exception";
  } catch (const std::logic_error& e) {
    EXPECT_NE(std::string(e.what()).find("caustics.method"), std::string::npos) << e.what();
  }
}

// What the request set reaches the field and its given flag; what it did not set stays a default.
TEST(Params, AGivenValueReachesItsFieldAndItsGivenFlag) {
  const nlohmann::json set = {{"method", "splat"}, {"cube_resolution", 64}};
  const CausticsParams p = CausticsParams::from(Params(api::techniqueParams("caustics", set), {"method", "cube_resolution"}));
  EXPECT_EQ(p.method, CausticsParams::Method::kSplat);
  EXPECT_EQ(p.cube_resolution, 64);
  EXPECT_TRUE(p.given.method);
  EXPECT_TRUE(p.given.cube_resolution);
  EXPECT_FALSE(p.given.area_weight);
  // illumination_network's seed spans 32 unsigned bits: the field is 64-bit, not an int that wraps.
  const IlluminationNetworkParams n =
      IlluminationNetworkParams::from(Params(api::techniqueParams("illumination_network", {{"seed", 4294967295u}})));
  EXPECT_EQ(n.seed, std::int64_t{4294967295});
}

}  // namespace
}  // namespace radiant
