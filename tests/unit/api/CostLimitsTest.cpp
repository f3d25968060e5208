// Limits that see every cost knob (issue 20): the schema declares what a parameter costs ("x-cost"),
// and the server's caps key on that declaration, not on parameter names.
#include <gtest/gtest.h>

#include <algorithm>
#include <regex>
#include <vector>
#include <set>

#include "api/Validate.h"

namespace {

using nlohmann::json;
using radiant::api::ApiError;
using radiant::api::costLimit;
using radiant::api::costParameters;
using radiant::api::parseRenderRequest;
using radiant::api::RequestLimits;
using radiant::api::renderRequestSchema;

// A parameter name that reads like a count of work (samples, photons, beams, particles, paths, rays),
// possibly per something ("light_paths_per_pixel"). Sizes of grids and maps ("photon_resolution",
// "cube_resolution") are not counts: their schema maximum bounds them.
bool looksLikeCost(const std::string& name) {
  static const std::regex kCostLike("(^|_)(spp|samples?|photons?|beams?|particles?|light_paths|paths|rays|count)(_per_[a-z]+)?$");
  return std::regex_search(name, kCostLike);
}

// Pointers of the integer parameters of `schema` whose names look like a cost and that declare no x-cost.
void undeclaredCosts(const json& schema, const std::string& pointer, std::vector<std::string>& out) {
  if (!schema.is_object()) return;
  if (auto p = schema.find("properties"); p != schema.end())
    for (const auto& [key, sub] : p->items()) {
      const std::string at = pointer + "/" + key;
      if (sub.is_object() && sub.value("type", "") == "integer" && looksLikeCost(key) && !sub.contains("x-cost"))
        out.push_back(at);
      undeclaredCosts(sub, at, out);
    }
  if (auto items = schema.find("items"); items != schema.end()) undeclaredCosts(*items, pointer + "/*", out);
}
std::vector<std::string> undeclaredCosts(const json& schema) {
  std::vector<std::string> out;
  undeclaredCosts(schema, "", out);
  return out;
}

// A costParameters() pointer with its '*' (any item) as the first item.
std::string firstItem(std::string pointer) {
  for (std::size_t at; (at = pointer.find("/*")) != std::string::npos;) pointer.replace(at, 2, "/0");
  return pointer;
}

// The smallest request that carries `value` at `pointer`.
json requestWith(const std::string& pointer, long long value) {
  json body{{"scene", {{"builtin", "cornell_box"}}}};
  if (pointer.rfind("/media/*/", 0) == 0) body["media"] = json::array({{{"kind", "smoke"}}});
  body[json::json_pointer(firstItem(pointer))] = value;
  return body;
}

RequestLimits limitsWith(const std::string& kind, long long max) {
  RequestLimits l;
  if (kind == "samples") l.maxSamples = static_cast<int>(max);
  else if (kind == "photons") l.maxPhotons = max;
  else if (kind == "particles") l.maxParticles = static_cast<std::size_t>(max);
  else if (kind == "resolution") l.maxMapResolution = static_cast<int>(max);
  else if (kind == "nodes") l.maxNetworkNodes = static_cast<int>(max);
  else if (kind == "iterations") l.maxIterations = static_cast<int>(max);
  return l;
}

}  // namespace

TEST(CostLimits, TheSchemaDeclaresEveryKnownCostKnob) {
  std::map<std::string, std::string> found;
  for (const auto& [pointer, kind] : costParameters(renderRequestSchema())) found[pointer] = kind;
  const std::map<std::string, std::string> expected{
      {"/passes/reference/spp", "samples"},
      {"/passes/reference/light_paths_per_pixel", "samples"},
      {"/passes/ambient_occlusion/samples", "samples"},
      {"/passes/photon_gi/photons", "photons"},
      {"/passes/photon_gi/ppm_base_photons", "none"},
      {"/compare/spp", "samples"},
      {"/media/*/generator/count", "particles"},
      // Sizes of maps and grids: texels per side (memory and fill grow with the square).
      {"/passes/shadow_maps/shadow_map_size", "resolution"},
      {"/passes/specular/cube_resolution", "resolution"},
      {"/passes/caustics/cube_resolution", "resolution"},
      {"/passes/caustics/photon_resolution", "resolution"},
      {"/passes/env_diffuse/cube_resolution", "resolution"},
      {"/passes/depth_impostors/impostor_resolution", "resolution"},
      {"/passes/depth_impostors/slice_resolution", "resolution"},
      {"/passes/illumination_network/nodes", "nodes"},
      {"/passes/illumination_network/iterations", "iterations"},
  };
  for (const auto& [pointer, kind] : expected) {
    ASSERT_TRUE(found.count(pointer)) << pointer << " declares no x-cost";
    EXPECT_EQ(found[pointer], kind) << pointer;
  }
}

// The schema of the knob at a costParameters() pointer.
const json& knobSchema(const json& schema, const std::string& pointer) {
  std::string sp;
  for (std::size_t i = 1, j; i <= pointer.size(); i = j + 1) {
    j = pointer.find('/', i);
    if (j == std::string::npos) j = pointer.size();
    const std::string token = pointer.substr(i, j - i);
    sp += token == "*" ? "/items" : "/properties/" + token;
  }
  return schema[json::json_pointer(sp)];
}
long long smallestValue(const json& knob) {
  if (knob.contains("enum")) {
    const auto v = knob.at("enum").get<std::vector<long long>>();
    return *std::min_element(v.begin(), v.end());
  }
  return knob.value("minimum", 0LL);
}

// Every x-cost knob, one above its cap (and within the schema's range; for an enumerated knob, the next
// allowed value): 422 limit-exceeded naming exactly that field and the flag that raises the cap; at the
// cap it is accepted. The knobs of the same kind beside it are set to their smallest values and the cap
// is at least those (a pass default above a cap is lowered by the renderer, not refused: Presets.
// DefaultsAboveTheServersCapsRunAtTheCaps; media defaults are still refused).
TEST(CostLimits, AnOverCapValueOfEveryCostKnobIsA422NamingIt) {
  const json& schema = renderRequestSchema();
  int checked = 0;
  for (const auto& [pointer, kind] : costParameters(schema)) {
    const auto limit = costLimit(kind, RequestLimits{});
    if (!limit) continue;  // "none": not capped
    SCOPED_TRACE(pointer);
    const json& knob = knobSchema(schema, pointer);
    std::vector<std::pair<std::string, long long>> siblings;
    long long floor = std::max(knob.value("minimum", 0LL), 1LL) + 1;
    const std::string parent = pointer.substr(0, pointer.rfind('/'));
    for (const auto& [other, otherKind] : costParameters(schema))
      if (otherKind == kind && other != pointer && other.substr(0, other.rfind('/')) == parent) {
        siblings.emplace_back(other, smallestValue(knobSchema(schema, other)));
        floor = std::max(floor, siblings.back().second);
      }
    long long cap = floor, over = floor + 1;
    if (knob.contains("enum")) {
      std::vector<long long> values = knob.at("enum").get<std::vector<long long>>();
      std::sort(values.begin(), values.end());
      const auto at = std::lower_bound(values.begin(), values.end(), floor);
      ASSERT_TRUE(at != values.end() && at + 1 != values.end());
      cap = *at;
      over = *(at + 1);
    } else {
      ASSERT_LT(cap, knob.value("maximum", 1LL << 40));
    }
    auto body = [&](long long value) {
      json b = requestWith(pointer, value);
      for (const auto& [other, smallest] : siblings) b[json::json_pointer(firstItem(other))] = smallest;
      return b;
    };
    const RequestLimits limits = limitsWith(kind, cap);
    EXPECT_NO_THROW(parseRenderRequest(body(cap), limits));
    try {
      parseRenderRequest(body(over), limits);
      ADD_FAILURE() << "no error for " << pointer << " = " << over << " above a cap of " << cap;
    } catch (const ApiError& e) {
      EXPECT_EQ(e.status, 422);
      EXPECT_EQ(e.type, "limit-exceeded");
      EXPECT_EQ(e.pointer, firstItem(pointer));
      EXPECT_NE(e.detail().find(limit->flag), std::string::npos) << e.detail();
    }
    ++checked;
  }
  EXPECT_GE(checked, 15);
}

TEST(CostLimits, ACostLikeParameterWithoutXCostFails) {
  // The real schema: every integer parameter named like a count of work declares its cost.
  EXPECT_EQ(undeclaredCosts(renderRequestSchema()), std::vector<std::string>{});
  // The check itself finds one (a technique that adds "beams" without declaring it).
  const json schema{{"properties",
                     {{"passes",
                       {{"properties",
                         {{"light_volumes",
                           {{"properties",
                             {{"beams", {{"type", "integer"}, {"minimum", 1}, {"maximum", 10}}},
                              {"max_depth", {{"type", "integer"}, {"minimum", 1}, {"maximum", 10}}},
                              {"spp", {{"type", "integer"}, {"x-cost", "samples"}}}}}}}}}}}}}};
  EXPECT_EQ(undeclaredCosts(schema), std::vector<std::string>{"/passes/light_volumes/beams"});
  EXPECT_TRUE(looksLikeCost("light_paths_per_pixel"));
  EXPECT_TRUE(looksLikeCost("photons"));
  EXPECT_FALSE(looksLikeCost("photon_resolution"));  // a grid size: bounded by its schema maximum
  EXPECT_FALSE(looksLikeCost("max_depth"));
}

TEST(CostLimits, UnknownCostKindIsAProgrammerError) {
  EXPECT_THROW(costLimit("beams", RequestLimits{}), std::logic_error);
  EXPECT_FALSE(costLimit("none", RequestLimits{}).has_value());
  EXPECT_EQ(costLimit("photons", RequestLimits{})->max, 4000000);
  // The defaults are the schema's own maxima: a server without flags refuses nothing the schema allows.
  EXPECT_EQ(costLimit("resolution", RequestLimits{})->max, 4096);
  EXPECT_EQ(costLimit("nodes", RequestLimits{})->max, 65536);
  EXPECT_EQ(costLimit("iterations", RequestLimits{})->max, 1024);
}
