#include "api/Types.h"

#include <algorithm>
#include <cmath>

namespace radiant::api {

namespace {
constexpr std::pair<ToneMap, const char*> kToneMapNames[] = {
    {ToneMap::Standard, "standard"}, {ToneMap::Aces, "aces"},
    {ToneMap::KhronosPbrNeutral, "khronos_pbr_neutral"}, {ToneMap::Agx, "agx"}};
}  // namespace

const char* toString(ToneMap t) {
  for (const auto& [value, name] : kToneMapNames)
    if (value == t) return name;
  return "standard";
}

std::optional<ToneMap> toneMapFromString(std::string_view name) {
  for (const auto& [value, n] : kToneMapNames)
    if (name == n) return value;
  return std::nullopt;
}

void to_json(nlohmann::json& j, const PassStats& s) {
  j = nlohmann::json{{"name", s.name},
                     {"gpu_ms", s.gpuMs},
                     {"cpu_ms", s.cpuMs},
                     {"prepare_ms", s.prepareMs},
                     {"counters", s.counters}};
}

void to_json(nlohmann::json& j, const FrameStats& s) {
  nlohmann::json cache = nlohmann::json::array();
  for (const auto& c : s.cache) cache.push_back({{"what", c.what}, {"hit", c.hit}});
  nlohmann::json passes = nlohmann::json::array();
  for (const auto& p : s.passes) passes.push_back(p);
  j = nlohmann::json{{"passes", passes},
                     {"pass_timing", s.passTiming},
                     {"skipped", s.skipped},
                     {"light_paths", s.lightPaths},
                     {"cache", cache},
                     {"scene_load_ms", s.sceneLoadMs},
                     {"upload_ms", s.uploadMs},
                     {"render_ms", s.renderMs},
                     {"readback_ms", s.readbackMs},
                     {"encode_ms", s.encodeMs},
                     {"triangles", s.triangles},
                     {"lights", s.lights},
                     {"device", s.device},
                     {"metrics", s.metrics},
                     {"lighting", s.lighting},
                     {"lighting_reason", s.lightingReason},
                     {"supersampling", s.supersampling},
                     {"camera", s.camera},
                     {"scene", s.scene},
                     {"warnings", s.warnings}};
  if (!s.clampedValues.empty()) {
    nlohmann::json& c = j["clamped_values"] = nlohmann::json::array();
    for (const auto& v : s.clampedValues)
      c.push_back({{"output", v.output}, {"aov", v.aov}, {"count", v.count}, {"limit", v.limit}});
  }
  if (!s.budget.is_null()) j["budget"] = s.budget;
  if (!s.refinement.is_null()) j["refinement"] = s.refinement;
  if (!s.memory.is_null()) j["memory"] = s.memory;
}

int defaultSupersampling(int width, int height) {
  constexpr double kSamplesPerAxis = 512.0;
  const double side = std::sqrt(std::max(1.0, double(width) * double(height)));
  return std::clamp(int(std::ceil(kSamplesPerAxis / side - 1e-9)), 2, 4);
}

int photonGatherStep(int requested, bool given, int width, int height) {
  if (given) return requested;
  const double size = std::sqrt(std::max(1.0, double(width) * double(height)));
  return std::clamp(static_cast<int>(std::lround(size / 64.0)), 2, 4);
}

}  // namespace radiant::api
