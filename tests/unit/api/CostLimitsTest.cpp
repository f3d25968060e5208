// Limits that see every cost knob (issue 20): the schema declares what a parameter costs ("x-cost"),
// and the server's caps key on that declaration, not on parameter names.
#include <gtest/gtest.h>

#include <regex>
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
  };
  for (const auto& [pointer, kind] : expected) {
    ASSERT_TRUE(found.count(pointer)) << pointer << " declares no x-cost";
    EXPECT_EQ(found[pointer], kind) << pointer;
  }
}

// Every x-cost knob, one above its cap (and within the schema's range): 422 limit-exceeded naming exactly
// that field and the flag that raises the cap; at the cap it is accepted.
TEST(CostLimits, AnOverCapValueOfEveryCostKnobIsA422NamingIt) {
  const json& schema = renderRequestSchema();
  int checked = 0;
  for (const auto& [pointer, kind] : costParameters(schema)) {
    const auto limit = costLimit(kind, RequestLimits{});
    if (!limit) continue;  // "none": not capped
    // The knob's own schema, for its range.
    std::string sp;
    for (std::size_t i = 1, j; i <= pointer.size(); i = j + 1) {
      j = pointer.find('/', i);
      if (j == std::string::npos) j = pointer.size();
      const std::string token = pointer.substr(i, j - i);
      sp += token == "*" ? "/items" : "/properties/" + token;
    }
    const json& knob = schema[json::json_pointer(sp)];
    const long long lo = knob.value("minimum", 0LL), hi = knob.value("maximum", 1LL << 40);
    // The cap: just above the minimum, but not below the defaults of the knobs of the same kind beside
    // it (a named pass gets every default, and those are capped too: reference.spp's 64 beside
    // light_paths_per_pixel).
    long long cap = std::max(lo, 1LL) + 1;
    const std::string parent = pointer.substr(0, pointer.rfind('/'));
    for (const auto& [other, otherKind] : costParameters(schema))
      if (otherKind == kind && other != pointer && other.substr(0, other.rfind('/')) == parent) {
        std::string op = sp.substr(0, sp.rfind('/')) + "/" + other.substr(other.rfind('/') + 1);
        cap = std::max(cap, schema[json::json_pointer(op)].value("default", 0LL));
      }
    ASSERT_LT(cap, hi) << pointer;
    SCOPED_TRACE(pointer);
    const RequestLimits limits = limitsWith(kind, cap);
    EXPECT_NO_THROW(parseRenderRequest(requestWith(pointer, cap), limits));
    try {
      parseRenderRequest(requestWith(pointer, cap + 1), limits);
      ADD_FAILURE() << "no error for " << pointer << " = " << cap + 1 << " above a cap of " << cap;
    } catch (const ApiError& e) {
      EXPECT_EQ(e.status, 422);
      EXPECT_EQ(e.type, "limit-exceeded");
      EXPECT_EQ(e.pointer, firstItem(pointer));
      EXPECT_NE(e.detail().find(limit->flag), std::string::npos) << e.detail();
    }
    ++checked;
  }
  EXPECT_GE(checked, 6);
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
}
