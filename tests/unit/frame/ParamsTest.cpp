// A technique's parameters have one source: the schema (renderer/techniques/*/*.json) gives every one a
// default, api::techniqueParams fills them in, and Params::get reads them without a fallback of its
// own (issue 33: the C++ fallbacks had drifted from the schema, e.g. photon_gi's ppm_alpha 2/3 against
// 0.6667, light_volumes' sigma_scale a constant beside 1.58).
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "api/Validate.h"
#include "renderer/frame/Technique.h"

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

}  // namespace
}  // namespace radiant
