#include "api/Aovs.h"

#include <algorithm>

#include "api/Validate.h"

namespace radiant::api {

namespace {

AovFormat formatOf(const std::string& s) {
  return s == "R32F" ? AovFormat::R32F : s == "RGBA16F" ? AovFormat::Rgba16F : AovFormat::Rgba32F;
}

// A row a technique's descriptor declares (renderer/techniques/<name>/<name>.json, "aovs"), as
// merge_schema completed it with its defaults into the schema's "x-aovs".
AovInfo describedAov(const nlohmann::json& r) {
  AovInfo a{0, r.at("name"), formatOf(r.at("format")), r.at("resource"), r.at("first_channel"), r.at("channels"),
            r.at("exr"), AovBlend::Overwrite, r.at("producer"), true, r.at("ground_truth")};
  a.resolve = r.at("resolve") == "nearest" ? AovResolve::Nearest : AovResolve::Average;
  a.radiance = r.at("radiance");
  a.description = r.at("description");
  return a;
}

}  // namespace

const std::vector<AovInfo>& aovTable() {
  using F = AovFormat;
  using B = AovBlend;
  // The frame's own AOVs, which no technique owns: beauty (every pass with addsToBeauty adds into it;
  // EXR's default layer, R, G, B, so that viewers show it first), alpha and error. Every other row is
  // declared by the technique that writes it, in its descriptor ("<aov>.<channel>" in EXR).
  static const std::vector<AovInfo> table = [] {
    std::vector<AovInfo> t = {{0, "beauty", F::Rgba32F, "beauty", 0, 3, {"R", "G", "B"}, B::Accumulate, "", true,
                               "beauty", AovResolve::Average, true,
                               "The frame: the sum of every planned pass's light (the reference scores it as a whole)."}};
    for (const auto& r : renderRequestSchema().at("x-aovs")) t.push_back(describedAov(r));
    // With "background": "transparent", the Renderer's coverage of the beauty (the fraction of a
    // pixel's samples that hit a surface): the beauty's A channel in EXR and PNG; never requested.
    t.push_back({0, "alpha", F::R32F, "", 0, 1, {"A"}, B::Overwrite, "background", false, "", AovResolve::Average, false,
                 "Coverage of the beauty with a transparent background (its A channel); never requested."});
    // compare() writes it (per-pixel luminance-weighted absolute error); never requested.
    t.push_back({0, "error", F::R32F, "", 0, 1, {"error.Y"}, B::Overwrite, "compare", false, "", AovResolve::Average,
                 false, "compare's per-pixel luminance-weighted absolute error; never requested."});
    for (std::size_t i = 0; i < t.size(); ++i) t[i].id = static_cast<int>(i);
    return t;
  }();
  return table;
}

const AovInfo* findAov(std::string_view name) {
  const auto& t = aovTable();
  auto it = std::find_if(t.begin(), t.end(), [&](const AovInfo& a) { return a.name == name; });
  return it == t.end() ? nullptr : &*it;
}

const char* toString(AovFormat f) {
  switch (f) {
    case AovFormat::R32F: return "R32F";
    case AovFormat::Rgba16F: return "RGBA16F";
    default: return "RGBA32F";
  }
}
const char* toString(AovBlend b) { return b == AovBlend::Accumulate ? "accumulate" : "overwrite"; }
const char* toString(AovResolve r) { return r == AovResolve::Nearest ? "nearest" : "average"; }

nlohmann::json aovTableJson() {
  nlohmann::json out = nlohmann::json::array();
  for (const AovInfo& a : aovTable())
    out.push_back({{"name", a.name},
                   {"format", toString(a.format)},
                   {"channels", a.exr},
                   {"blend", toString(a.blend)},
                   {"resolve", toString(a.resolve)},
                   {"producer", a.producer.empty() ? nlohmann::json(nullptr) : nlohmann::json(a.producer)},
                   {"requestable", a.requestable},
                   {"ground_truth", a.groundTruth.empty() ? nlohmann::json(nullptr) : nlohmann::json(a.groundTruth)},
                   {"description", a.description}});
  return out;
}

}  // namespace radiant::api
