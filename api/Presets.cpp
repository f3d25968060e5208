#include "api/Presets.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include "api/Validate.h"
#include "embedded/radiant_api_presets.h"

namespace radiant::api {

using nlohmann::json;

namespace {

const json& emptyArray() {
  static const json a = json::array();
  return a;
}

// A numeric parameter's value (a boolean counts as 0/1).
double paramValue(const json& params, const std::string& n) {
  if (params.contains(n) && params[n].is_number()) return params[n].get<double>();
  if (params.contains(n) && params[n].is_boolean()) return params[n].get<bool>() ? 1.0 : 0.0;
  throw std::logic_error("preset table: cost term names '" + n + "', which is no numeric parameter");
}

// sum of coef * product of vars; a var is "pixels" (the raster's), a scene count ("particles", "beams",
// "specular_objects"), photon_gi's "gather_samples" (its gather's block samples), a numeric parameter,
// or another technique's parameter ("photon_gi.C": its value in `frame`, 0 when that technique is not
// in the frame).
double evalTerms(const json& terms, const json& params, double pixels, const SceneCounts& counts = {},
                 const FrameParams& frame = {}) {
  double ms = 0.0;
  for (const auto& t : terms) {
    double v = t.value("coef", 0.0);
    for (const auto& name : t.value("vars", json::array())) {
      const std::string n = name.get<std::string>();
      if (n == "pixels") v *= pixels;
      else if (n == "particles") v *= counts.particles;
      else if (n == "beams") v *= counts.beams;
      else if (n == "specular_objects") v *= counts.specularObjects;
      else if (n == "gather_samples") {  // photon_gi's block samples (SceneCounts::photonGatherBlock)
        const double block = counts.photonGatherBlock > 0 ? counts.photonGatherBlock : paramValue(params, "gather_step");
        v *= pixels / std::max(1.0, block * block);
      } else if (const auto dot = n.find('.'); dot != std::string::npos) {
        auto other = frame.find(n.substr(0, dot));
        v *= other == frame.end() ? 0.0 : paramValue(other->second, n.substr(dot + 1));
      } else v *= paramValue(params, n);
    }
    ms += v;
  }
  return ms;
}

json paramsOf(const RenderRequest& request, const std::string& technique) {
  auto it = request.passes.find(technique);
  return techniqueParams(technique, it == request.passes.end() ? json() : it->second);
}

// A front point's parameters under the request's own: the request's explicit keys win.
json merged(const json& base, const json& point, const std::set<std::string>& explicitKeys) {
  json p = base;
  for (const auto& [k, v] : point.items())
    if (!explicitKeys.count(k)) p[k] = v;
  return p;
}

bool overridden(const json& point, const std::set<std::string>& explicitKeys) {
  for (const auto& [k, v] : point.items())
    if (explicitKeys.count(k)) return true;
  return false;
}

json chosenSubset(const json& params, const json& point) {
  json out = json::object();
  for (const auto& [k, v] : point.items()) out[k] = params[k];
  return out;
}

// The server's caps (RequestLimits, radiantd --max-samples / --max-photons / --max-particles) that a
// front point's parameters exceed, as {param: {"wanted", "limit", "flag"}}; a parameter the request
// gives itself wins over the point and was capped by validation already. Empty when the point fits.
json capsExceeded(const std::string& technique, const json& point, const std::set<std::string>& explicitKeys,
                  const RequestLimits* limits) {
  json out = json::object();
  const TechniqueSchema* schema = limits ? findTechnique(technique) : nullptr;
  if (!schema) return out;
  for (const auto& [k, v] : point.items()) {
    if (explicitKeys.count(k) || !v.is_number_integer() || !schema->params.contains(k)) continue;
    const json& p = schema->params[k];
    if (!p.contains("x-cost")) continue;
    const auto cap = costLimit(p["x-cost"].get<std::string>(), *limits);
    if (cap && v.get<long long>() > cap->max)
      out[k] = {{"wanted", v}, {"limit", cap->max}, {"flag", std::string("radiantd ") + cap->flag}};
  }
  return out;
}

// A point whose every capped parameter is lowered to its cap: what runs when no point of the front
// fits the caps (its error was not measured). The lowered value is one the schema allows: an
// enumerated knob (cube_resolution 16..512) takes its largest value within the cap. When the schema
// has no value within the cap (below the smallest enumerated value or the minimum), the technique
// cannot run on this server: a 422 naming the flag, not a value the schema forbids.
json clampedToCaps(const std::string& technique, const json& point, const json& exceeded) {
  json p = point;
  const TechniqueSchema* schema = findTechnique(technique);
  for (const auto& [k, c] : exceeded.items()) {
    const double limit = c["limit"].get<double>();
    json value = c["limit"];
    const json* param = schema && schema->params.contains(k) ? &schema->params.at(k) : nullptr;
    bool fits = !(param && param->contains("minimum") && limit < param->at("minimum").get<double>());
    if (param && param->contains("enum")) {
      value = nullptr;
      for (const json& v : param->at("enum"))
        if (v.is_number() && v.get<double>() <= limit && (value.is_null() || v.get<double>() > value.get<double>()))
          value = v;
      fits = fits && !value.is_null();
    }
    if (!fits)
      throw ApiError(422, "limit-exceeded", "Limit exceeded",
                     technique + "." + k + " has no allowed value within this server's limit " + c["limit"].dump() + " (" +
                         c["flag"].get<std::string>() + "), so " + technique + " cannot run here",
                     "/passes/" + technique + "/" + k);
    p[k] = value;
  }
  return p;
}

std::string describeCaps(const json& exceeded) {
  std::string s;
  for (const auto& [k, c] : exceeded.items())
    s += (s.empty() ? "" : ", ") + k + " " + c["wanted"].dump() + " is above this server's limit " + c["limit"].dump() +
         " (" + c["flag"].get<std::string>() + ")";
  return s;
}

}  // namespace

double passCostMs(const PassStats& pass) {
  double ms = pass.cpuMs;
  for (const char* prepared : {"trace_ms", "splat_build_ms"}) {
    auto it = pass.counters.find(prepared);
    if (it != pass.counters.end() && std::isfinite(it->second)) ms += it->second;
  }
  return ms;
}

PresetTable::PresetTable(json table) : table_(std::move(table)) {
  if (!table_.is_object() || !table_.contains("techniques") || !table_["techniques"].is_object())
    throw std::invalid_argument("preset table: no \"techniques\" object");
}

const PresetTable& PresetTable::builtin() {
  static const PresetTable t(json::parse(embedded_presets::find("presets.json")));
  return t;
}

bool PresetTable::hasFront(const std::string& technique) const { return !front(technique).empty(); }

bool PresetTable::hasModel(const std::string& technique) const {
  const json& t = table_["techniques"];
  return t.contains(technique) && t[technique].contains("model");
}

double PresetTable::predictMs(const std::string& technique, const json& params, double pixels,
                              const SceneCounts& counts, const FrameParams& frame) const {
  if (!hasModel(technique)) return -1.0;
  const json& terms = table_["techniques"][technique]["model"]["terms"];
  if (technique == "specular" && counts.specularMapTexels > 0 && params.contains("cube_resolution") &&
      params["cube_resolution"].is_number()) {
    json run = params;
    run["cube_resolution"] = std::min(params["cube_resolution"].get<double>(), counts.specularMapTexels);
    return std::max(0.0, evalTerms(terms, run, pixels, counts, frame));
  }
  return std::max(0.0, evalTerms(terms, params, pixels, counts, frame));
}

double PresetTable::predictOverheadMs(double pixels) const {
  if (!table_.contains("overhead")) return 0.0;
  return std::max(0.0, evalTerms(table_["overhead"]["terms"], json::object(), pixels));
}

const json& PresetTable::front(const std::string& technique) const {
  const json& t = table_["techniques"];
  if (!t.contains(technique) || !t[technique].contains("front")) return emptyArray();
  return t[technique]["front"];
}

int PresetTable::presetIndex(const std::string& technique, const std::string& quality) const {
  const json& t = table_["techniques"];
  if (!t.contains(technique) || !t[technique].contains("presets")) return -1;
  const json& p = t[technique]["presets"];
  return p.contains(quality) ? p[quality].get<int>() : -1;
}

namespace {
// The server's default frame budget applies to the planner's default frame only: no quality, no time
// budget, no passes named (api/Presets.h); 0 when it does not.
double defaultFrameBudget(const RenderRequest& request, const RequestLimits* limits) {
  if (!limits || request.passesNamed || !request.quality.empty() || request.timeBudgetMs > 0) return 0.0;
  return limits->defaultFrameBudgetMs > 0 ? limits->defaultFrameBudgetMs : 0.0;
}
}  // namespace

BudgetChoice chooseConfiguration(const PresetTable& table, const std::vector<std::string>& planned,
                                 const RenderRequest& request, const RequestLimits* limits,
                                 const SceneCounts& counts, double speed) {
  BudgetChoice c;
  if (!(speed > 0.0) || !std::isfinite(speed)) speed = 1.0;
  for (const auto& t : planned) c.params[t] = paramsOf(request, t);
  // A default the request does not set (or a pass the planner added) still above this server's caps
  // once the preset or budget has chosen runs at the cap: validation refuses only values the request
  // gives (api/Validate.cpp capCosts). Applied on every return path below.
  auto lowerDefaultsToCaps = [&] {
    for (const auto& t : planned) {
      auto it = request.explicitParams.find(t);
      const std::set<std::string> given = it == request.explicitParams.end() ? std::set<std::string>{} : it->second;
      const json exceeded = capsExceeded(t, c.params[t], given, limits);
      if (exceeded.empty()) continue;
      c.params[t] = techniqueParams(t, clampedToCaps(t, c.params[t], exceeded));
      c.warnings.push_back(t + ": default lowered to this server's caps: " + describeCaps(exceeded));
    }
  };
  c.active = !request.quality.empty() || request.timeBudgetMs > 0;
  if (!c.active) {
    lowerDefaultsToCaps();
    // The server's default frame budget: only for the planner's default frame (no passes named), and
    // only when every planned technique has a model (else the frame's cost is not known).
    if (const double defaultBudget = defaultFrameBudget(request, limits); defaultBudget > 0) {
      const double predicted =
          predictFrameMs(table, planned, c.params, double(request.width) * request.height, counts) *
          speed;
      if (predicted > defaultBudget) {
        RenderRequest budgeted = request;
        budgeted.timeBudgetMs = defaultBudget;
        BudgetChoice b = chooseConfiguration(table, planned, budgeted, limits, counts, speed);
        b.stats.erase("time_budget_ms");
        b.stats["default_frame_budget"] = {{"budget_ms", defaultBudget},
                                           {"predicted_default_ms", predicted},
                                           {"flag", "--default-frame-budget-ms"}};
        char line[320];
        std::snprintf(line, sizeof line,
                      "the default configuration is predicted at %.0f ms, over this server's default frame budget of "
                      "%.0f ms (radiantd --default-frame-budget-ms): rendered the budget's choice instead "
                      "(stats.budget, predicted %.0f ms); name a quality, a time_budget_ms or the passes to choose",
                      predicted, defaultBudget, b.stats.value("predicted_ms", 0.0));
        b.warnings.insert(b.warnings.begin(), line);
        return b;
      }
    }
    return c;
  }
  const double pixels = double(request.width) * request.height;
  const json& gen = table.data().value("generated", json::object());
  c.stats = {{"table", {{"generated", gen.value("date", "")}, {"command", gen.value("command", "")},
                        {"device", gen.value("device", json())}}}};
  if (!request.quality.empty()) c.stats["quality"] = request.quality;
  else c.stats["time_budget_ms"] = request.timeBudgetMs;

  // This machine's ms: the table's prediction times the speed factor (MachineSpeed), with the frame's
  // other techniques' parameters (`frame`, c.params unless given) for a model that names them.
  auto predictIn = [&](const std::string& t, const json& p, const FrameParams& frame) {
    const double ms = table.predictMs(t, p, pixels, counts, frame);
    return ms < 0 ? ms : ms * speed;
  };
  auto predict = [&](const std::string& t, const json& p) { return predictIn(t, p, c.params); };
  // What a candidate point `p` of technique t adds to the other planned techniques' cost against t's
  // request parameters (c.params[t]), for models that name t's parameters (specular's maps gather photon_gi's
  // photons with its kernel C). The other techniques are charged at their request parameters: exact for
  // those without a front (specular), which the budget does not change.
  auto coupledMs = [&](const std::string& t, const json& p) {
    FrameParams with = c.params;
    with[t] = p;
    double ms = 0.0;
    for (const auto& u : planned) {
      if (u == t) continue;
      const double a = predictIn(u, c.params[u], with), b = predictIn(u, c.params[u], c.params);
      if (a >= 0 && b >= 0) ms += a - b;
    }
    return ms;
  };
  const double overheadMs = table.predictOverheadMs(pixels) * speed;
  c.stats["speed_factor"] = speed;

  auto explicitOf = [&](const std::string& t) {
    auto it = request.explicitParams.find(t);
    return it == request.explicitParams.end() ? std::set<std::string>{} : it->second;
  };
  auto errorBlock = [&](const std::string& t, const json& point, bool overriddenByRequest) {
    if (overriddenByRequest) return json(nullptr);  // the measured point is not what runs
    json e = table.data()["techniques"][t].value("error", json::object());
    e["value"] = point["error"];
    return e;
  };

  json techniques = json::object();
  double fixedMs = overheadMs;
  // One candidate list per modelled technique with a front: (params, predicted ms with what the point adds
  // to the other techniques' cost (coupledMs), error, point index).
  struct Candidate {
    json params;
    double ms, error;
    int point;
  };
  std::map<std::string, std::vector<Candidate>> candidates;
  for (const auto& t : planned) {
    const std::set<std::string> given = explicitOf(t);
    json entry = json::object();
    if (!given.empty()) entry["explicit"] = given;
    const json& front = table.front(t);
    if (!request.quality.empty() && !front.empty()) {
      const int preset = table.presetIndex(t, request.quality);
      if (preset >= 0 && preset < int(front.size())) {
        // Under the server's caps: the preset's point if it fits, else the most accurate cheaper point
        // that does (the front is ordered by cost and error), else the cheapest point lowered to the caps.
        int i = preset;
        while (i >= 0 && !capsExceeded(t, front[i]["params"], given, limits).empty()) --i;
        json point = front[std::max(i, 0)]["params"];
        if (i != preset) {
          const json exceeded = capsExceeded(t, front[preset]["params"], given, limits);
          entry["capped"] = {{"limits", exceeded}, {"preset_point", preset}, {"clamped", i < 0}};
          if (i < 0) point = clampedToCaps(t, point, capsExceeded(t, point, given, limits));
          c.warnings.push_back("quality " + request.quality + ": " + t + " runs " +
                               (i < 0 ? "its cheapest front point lowered to the server's caps"
                                      : "front point " + std::to_string(i)) +
                               " instead of the preset's point " + std::to_string(preset) + ": " + describeCaps(exceeded));
        }
        c.params[t] = techniqueParams(t, merged(c.params[t], point, given));
        entry["params"] = chosenSubset(c.params[t], point);
        entry["point"] = std::max(i, 0);
        entry["predicted_error"] =
            i < 0 ? json(nullptr) : errorBlock(t, front[i], overridden(front[i]["params"], given));
      }
    } else if (request.timeBudgetMs > 0 && !front.empty() && table.hasModel(t)) {
      // Only the points within the server's caps are candidates; when none is, the cheapest point
      // lowered to the caps (error unmeasured: NaN here, null in the stats).
      std::vector<Candidate> all;
      json excluded = json::array(), exceededAll = json::object();
      for (std::size_t i = 0; i < front.size(); ++i) {
        const json exceeded = capsExceeded(t, front[i]["params"], given, limits);
        if (!exceeded.empty()) {
          excluded.push_back(i);
          exceededAll.update(exceeded);
          continue;
        }
        json p = techniqueParams(t, merged(c.params[t], front[i]["params"], given));
        const double ms = predict(t, p) + coupledMs(t, p);
        all.push_back({std::move(p), ms, front[i]["error"].get<double>(), int(i)});
      }
      if (!excluded.empty()) {
        entry["capped"] = {{"limits", exceededAll}, {"excluded_points", excluded}, {"clamped", all.empty()}};
        c.warnings.push_back("time_budget_ms: " + t + " chooses among " + std::to_string(all.size()) + " of its " +
                             std::to_string(front.size()) + " front points: " + describeCaps(exceededAll));
      }
      if (all.empty()) {
        const json lowered = clampedToCaps(t, front[0]["params"], capsExceeded(t, front[0]["params"], given, limits));
        json p = techniqueParams(t, merged(c.params[t], lowered, given));
        const double ms = predict(t, p) + coupledMs(t, p);
        all.push_back({std::move(p), ms, std::numeric_limits<double>::quiet_NaN(), -1});
      }
      // The front at this frame's pixel count: by predicted cost, then only points that lower the error.
      std::stable_sort(all.begin(), all.end(), [](const Candidate& a, const Candidate& b) { return a.ms < b.ms; });
      std::vector<Candidate> kept;
      for (auto& a : all)
        if (kept.empty() || a.error < kept.back().error) kept.push_back(std::move(a));
      candidates[t] = std::move(kept);
      techniques[t] = entry;
      continue;
    }
    const double ms = predict(t, c.params[t]);
    if (ms >= 0) fixedMs += ms;
    techniques[t] = entry;
  }

  if (request.timeBudgetMs > 0) {
    std::map<std::string, std::size_t> at;
    double spent = fixedMs;
    for (const auto& [t, list] : candidates) {
      at[t] = 0;
      spent += list[0].ms;
    }
    if (spent > request.timeBudgetMs)
      c.warnings.push_back("time_budget_ms " + std::to_string(request.timeBudgetMs) +
                           " is below the predicted cost of the cheapest configuration (" + std::to_string(spent) +
                           " ms): rendering that");
    for (;;) {
      std::string best;
      double bestRate = -1.0, bestMs = 0.0;
      for (const auto& [t, list] : candidates) {
        const std::size_t i = at[t];
        if (i + 1 >= list.size()) continue;
        const double dMs = std::max(list[i + 1].ms - list[i].ms, 1e-9);
        const double rate = std::log(list[i].error / list[i + 1].error) / dMs;
        if (rate > bestRate) {
          bestRate = rate;
          best = t;
          bestMs = dMs;
        }
      }
      if (best.empty() || spent + bestMs > request.timeBudgetMs) break;
      spent += bestMs;
      ++at[best];
    }
    for (const auto& [t, list] : candidates) {
      const Candidate& k = list[at[t]];
      const json& point = table.front(t)[std::max(k.point, 0)];
      c.params[t] = k.params;
      json& entry = techniques[t];
      entry["params"] = chosenSubset(k.params, point["params"]);
      entry["point"] = std::max(k.point, 0);
      entry["predicted_error"] =
          k.point < 0 ? json(nullptr) : errorBlock(t, point, overridden(point["params"], explicitOf(t)));
    }
  }
  lowerDefaultsToCaps();
  // Each technique's own prediction with the frame's final parameters (a model naming another technique's
  // parameter sees the value chosen for it).
  double total = overheadMs;
  for (const auto& t : planned) {
    const double ms = predict(t, c.params[t]);
    techniques[t]["predicted_ms"] = ms >= 0 ? json(ms) : json(nullptr);
    if (ms >= 0) total += ms;
  }
  c.stats["techniques"] = techniques;
  c.stats["scene_counts"] = counts.toJson();
  c.stats["predicted_overhead_ms"] = overheadMs;
  c.stats["predicted_ms"] = total;
  return c;
}

int supersamplingWithinDefaultBudget(const PresetTable& table, const std::vector<std::string>& planned,
                                     const RenderRequest& request, int k, const RequestLimits* limits,
                                     const SceneCounts& counts, double speed,
                                     const std::function<double(int)>& specularMapTexelsAt) {
  const double budget = defaultFrameBudget(request, limits);
  if (!(budget > 0) || k <= 1 || request.supersamplingGiven) return k;
  if (!(speed > 0.0) || !std::isfinite(speed)) speed = 1.0;
  const BudgetChoice defaults = chooseConfiguration(table, planned, request, nullptr, counts, speed);
  const double outputPixels = double(request.width) * request.height;
  const bool photons = std::find(planned.begin(), planned.end(), "photon_gi") != planned.end();
  for (; k > 1; --k) {
    SceneCounts atK = counts;
    atK.photonGatherBlock = photons ? photonGatherBlock(request, k) : 0.0;
    if (specularMapTexelsAt) atK.specularMapTexels = specularMapTexelsAt(k);
    const double ms = predictFrameMs(table, planned, defaults.params, outputPixels * k * k, atK);
    if (ms < 0) return k;  // a pass the table does not model: no prediction, as asked
    if (ms * speed <= budget) return k;
  }
  return 1;
}

double photonGatherBlock(const RenderRequest& request, int k) {
  k = std::max(1, k);
  const json params = paramsOf(request, "photon_gi");
  auto named = request.explicitParams.find("photon_gi");
  const bool given = named != request.explicitParams.end() && named->second.count("gather_step") > 0;
  return double(k) * photonGatherStep(params["gather_step"].get<int>(), given, request.width, request.height);
}

double predictFrameMs(const PresetTable& table, const std::vector<std::string>& planned,
                      const std::map<std::string, json>& params, double pixels, const SceneCounts& counts) {
  double ms = table.predictOverheadMs(pixels);
  for (const auto& t : planned) {
    auto it = params.find(t);
    const double m =
        it == params.end() ? -1.0 : table.predictMs(t, it->second, pixels, counts, params);
    if (m < 0) return -1.0;
    ms += m;
  }
  return ms;
}

double MachineSpeed::ratio(double measuredMs, double predictedMs) {
  if (!(measuredMs > 0) || !(predictedMs > 0) || !std::isfinite(measuredMs) || !std::isfinite(predictedMs)) return 0.0;
  return std::clamp(measuredMs / predictedMs, kMinRatio, kMaxRatio);
}

void MachineSpeed::pin(double factor) {
  pinned_ = factor > 0 && std::isfinite(factor) ? std::clamp(factor, kMinRatio, kMaxRatio) : 0.0;
}

void MachineSpeed::calibrate(double measuredMs, double predictedMs) {
  if (const double r = ratio(measuredMs, predictedMs); r > 0) calibration_ = r;
}

namespace {
double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}
}  // namespace

void MachineSpeed::observe(double measuredMs, double predictedMs, const std::string& scene) {
  const double r = ratio(measuredMs, predictedMs);
  if (!(r > 0)) return;
  recent_.push_back(r);
  if (recent_.size() > kWindow) recent_.erase(recent_.begin());
  const std::size_t index = observed_++;
  if (scene.empty() || pinned()) return;  // a pinned factor learns no scene's
  auto it = std::find_if(scenes_.begin(), scenes_.end(), [&](const SceneFrames& e) { return e.first == scene; });
  if (it == scenes_.end()) it = scenes_.insert(scenes_.end(), {scene, {}});
  it->second.push_back({r, index});
  if (it->second.size() > kSceneWindow) it->second.erase(it->second.begin());
  // A scene none of whose frames is among the last kWindow is not used again (ownRecent).
  std::erase_if(scenes_, [&](const SceneFrames& e) { return e.second.back().index + kWindow < observed_; });
}

std::vector<double> MachineSpeed::machineRatios() const {
  std::vector<double> v = recent_;
  if (calibration_ > 0) v.push_back(calibration_);
  return v;
}

double MachineSpeed::machine() const {
  if (pinned()) return pinned_;
  std::vector<double> v = machineRatios();
  return v.empty() ? 1.0 : median(std::move(v));
}

double MachineSpeed::headroom(const std::string& scene) const {
  if (pinned()) return 1.0;
  std::vector<double> v = ownRecent(scene);
  if (v.size() < 3) v = machineRatios();
  const std::size_t n = v.size();
  if (n < 3) return 1.0;
  double mean = 0, var = 0;
  for (double r : v) mean += std::log(r) / double(n);
  for (double r : v) var += (std::log(r) - mean) * (std::log(r) - mean) / double(n - 1);
  // One-sided 90% quantiles of Student's t with n - 1 = 2 .. 10 degrees of freedom (then 11+: 1.36).
  static constexpr double kT90[] = {1.886, 1.638, 1.533, 1.476, 1.440, 1.415, 1.397, 1.383, 1.372};
  const double t = n - 1 <= 10 ? kT90[n - 3] : 1.36;
  return std::clamp(std::exp(t * std::sqrt(var) * std::sqrt(1.0 + 1.0 / double(n))), 1.0, kMaxHeadroom);
}

double MachineSpeed::planningFactor(const std::string& scene) const {
  return std::clamp(factor(scene) * headroom(scene), kMinRatio, kMaxRatio);
}

std::vector<double> MachineSpeed::ownRecent(const std::string& scene) const {
  std::vector<double> own;
  if (pinned() || scene.empty()) return own;
  auto it = std::find_if(scenes_.begin(), scenes_.end(), [&](const SceneFrames& e) { return e.first == scene; });
  if (it != scenes_.end())
    for (const Frame& f : it->second)
      if (f.index + kWindow >= observed_) own.push_back(f.ratio);
  return own;
}

double MachineSpeed::factor(const std::string& scene) const {
  std::vector<double> own = ownRecent(scene);
  return own.empty() ? machine() : median(std::move(own));
}

json MachineSpeed::toJson(const std::string& scene) const {
  const bool measured = calibration_ > 0 || !recent_.empty();
  const std::vector<double> own = ownRecent(scene);
  return {{"factor", planningFactor(scene)},
          {"median", factor(scene)},
          {"headroom", headroom(scene)},
          {"source", pinned() ? "pinned" : measured ? "measured" : "table"},
          {"machine", machine()},
          {"calibration", calibration_ > 0 ? json(calibration_) : json(nullptr)},
          {"recent", recent_},
          {"scene", {{"basis", own.empty() ? "machine" : "own"}, {"recent", own}}}};
}

void recordMeasured(json& budget, const FrameStats& stats, double frameMs) {
  if (!budget.is_object()) return;
  for (const auto& p : stats.passes)
    if (budget["techniques"].contains(p.name)) budget["techniques"][p.name]["measured_ms"] = passCostMs(p);
  budget["measured_ms"] = frameMs;
}

}  // namespace radiant::api
