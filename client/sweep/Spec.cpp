// Sweep specs: parsing (unknown keys are errors, as in the API) and expansion into points.
#include <algorithm>
#include <fstream>

#include "api/Sha256.h"
#include "client/Commands.h"
#include "client/sweep/Sweep.h"

namespace radiant::client::sweep {

namespace fs = std::filesystem;
using ojson = nlohmann::ordered_json;

namespace {

json toJson(const ojson& o) { return json::parse(o.dump()); }

std::vector<std::string> splitPath(const std::string& path) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  for (;;) {
    const auto dot = path.find('.', start);
    parts.push_back(path.substr(start, dot == std::string::npos ? std::string::npos : dot - start));
    if (dot == std::string::npos) break;
    start = dot + 1;
  }
  for (const auto& p : parts)
    if (p.empty()) throw UsageError("sweep: bad dotted path \"" + path + "\"");
  return parts;
}

bool isIndex(const std::string& s) { return !s.empty() && std::all_of(s.begin(), s.end(), ::isdigit); }

int intField(const ojson& j, const char* key, int def, int lo, int hi, const std::string& where) {
  if (!j.contains(key)) return def;
  if (!j[key].is_number_integer() || j[key].get<long long>() < lo || j[key].get<long long>() > hi)
    throw UsageError(where + "/" + key + ": expected an integer in " + std::to_string(lo) + ".." + std::to_string(hi));
  return j[key].get<int>();
}

Spec parseOne(const ojson& j, const fs::path& dir, const std::string& where) {
  if (!j.is_object()) throw UsageError(where + ": a sweep is a JSON object");
  static const std::set<std::string> known{"name", "description", "base", "axes", "zip", "repeats",
                                           "warmup", "compare", "technique", "method"};
  for (const auto& [k, v] : j.items())
    if (!known.count(k))
      throw UsageError(where + "/" + k + ": unknown key (known: name, description, base, axes, zip, repeats, warmup, "
                                         "compare, technique, method)");
  Spec s;
  s.dir = dir;
  s.name = j.value("name", std::string("sweep"));
  if (!j.contains("base")) throw UsageError(where + "/base: missing (a render request, or the path of one)");
  if (j["base"].is_string()) {
    fs::path p = j["base"].get<std::string>();
    if (p.is_relative()) p = dir / p;
    auto b = json::parse(readFile(p.string()), nullptr, false);
    if (!b.is_object()) throw UsageError(where + "/base: " + p.string() + " is not a JSON object");
    s.base = b;
  } else if (j["base"].is_object()) {
    s.base = toJson(j["base"]);
  } else {
    throw UsageError(where + "/base: expected a request object or a path");
  }
  if (!s.base.contains("scene")) throw UsageError(where + "/base/scene: missing");
  s.base.erase("async");
  if (j.contains("axes")) {
    if (!j["axes"].is_object()) throw UsageError(where + "/axes: expected {\"dotted.path\": [values...]}");
    for (const auto& [path, values] : j["axes"].items()) {
      splitPath(path);
      if (!values.is_array() || values.empty())
        throw UsageError(where + "/axes/" + path + ": expected a non-empty array of values");
      Factor f;
      f.paths = {path};
      for (const auto& v : values) f.settings.push_back({toJson(v)});
      s.factors.push_back(std::move(f));
    }
  }
  if (j.contains("zip")) {
    if (!j["zip"].is_array()) throw UsageError(where + "/zip: expected an array of {\"path\": [values...]} groups");
    for (std::size_t g = 0; g < j["zip"].size(); ++g) {
      const ojson& group = j["zip"][g];
      const std::string gw = where + "/zip/" + std::to_string(g);
      if (!group.is_object() || group.empty()) throw UsageError(gw + ": expected {\"path\": [values...], ...}");
      Factor f;
      std::size_t n = 0;
      for (const auto& [path, values] : group.items()) {
        splitPath(path);
        if (!values.is_array() || values.empty()) throw UsageError(gw + "/" + path + ": expected a non-empty array");
        if (n && values.size() != n)
          throw UsageError(gw + "/" + path + ": zipped lists must have equal lengths (" + std::to_string(values.size()) +
                           " vs " + std::to_string(n) + ")");
        n = values.size();
        f.paths.push_back(path);
      }
      f.settings.assign(n, {});
      for (const auto& [path, values] : group.items())
        for (std::size_t i = 0; i < n; ++i) f.settings[i].push_back(toJson(values[i]));
      s.factors.push_back(std::move(f));
    }
  }
  std::set<std::string> seen;
  for (const auto& f : s.factors)
    for (const auto& p : f.paths)
      if (!seen.insert(p).second) throw UsageError(where + ": path \"" + p + "\" is swept twice");
  s.repeats = intField(j, "repeats", 3, 1, 1000, where);
  s.warmup = intField(j, "warmup", 1, 0, 100, where);
  if (j.contains("compare")) {
    if (!j["compare"].is_object()) throw UsageError(where + "/compare: expected an object (the request's compare block)");
    s.compare = toJson(j["compare"]);
  } else if (s.base.contains("compare")) {
    s.compare = s.base["compare"];
  }
  s.base.erase("compare");
  s.technique = j.value("technique", std::string());
  s.method = j.value("method", std::string());
  return s;
}

}  // namespace

void setPath(json& root, const std::string& path, const json& value) {
  const auto parts = splitPath(path);
  if (parts.size() == 2 && parts[0] == "scene") {
    root["scene"] = json{{parts[1], value}};
    return;
  }
  json* node = &root;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const bool last = i + 1 == parts.size();
    if (node->is_array() && isIndex(parts[i])) {
      const std::size_t k = std::stoul(parts[i]);
      if (k >= node->size()) throw UsageError("sweep: " + path + ": index " + parts[i] + " is past the array's end");
      node = &(*node)[k];
    } else {
      if (!node->is_object() && !node->is_null())
        throw UsageError("sweep: " + path + ": \"" + parts[i] + "\" is inside a value that is not an object");
      node = &(*node)[parts[i]];
    }
    if (last) *node = value;
  }
}

const json* findPath(const json& root, const std::string& path) {
  const json* node = &root;
  for (const auto& part : splitPath(path)) {
    if (node->is_array() && isIndex(part)) {
      const std::size_t k = std::stoul(part);
      if (k >= node->size()) return nullptr;
      node = &(*node)[k];
    } else if (node->is_object() && node->contains(part)) {
      node = &(*node)[part];
    } else {
      return nullptr;
    }
  }
  return node;
}

std::vector<Spec> parseSpecs(const json& j, const fs::path& dir) {
  const ojson o = ojson::parse(j.dump());
  return {parseOne(o, dir, "")};
}

std::vector<Spec> parseSpecFile(const fs::path& file) {
  const ojson j = ojson::parse(readFile(file.string()), nullptr, false);
  if (j.is_discarded()) throw UsageError("sweep: " + file.string() + " is not valid JSON");
  const fs::path dir = file.has_parent_path() ? file.parent_path() : fs::path(".");
  std::vector<Spec> specs;
  if (j.is_object() && j.contains("sweeps")) {
    if (j.size() != 1 || !j["sweeps"].is_array() || j["sweeps"].empty())
      throw UsageError("sweep: " + file.string() + ": {\"sweeps\": [...]} holds a non-empty array and nothing else");
    for (std::size_t i = 0; i < j["sweeps"].size(); ++i)
      specs.push_back(parseOne(j["sweeps"][i], dir, file.string() + ": /sweeps/" + std::to_string(i)));
  } else {
    specs.push_back(parseOne(j, dir, file.string() + ": "));
  }
  return specs;
}

std::vector<Point> expand(const Spec& spec) {
  std::size_t total = 1;
  for (const auto& f : spec.factors) total *= f.settings.size();
  std::vector<Point> points;
  points.reserve(total);
  std::vector<std::size_t> at(spec.factors.size(), 0);
  std::map<std::string, std::string> digests;  // scene file -> digest
  for (std::size_t n = 0; n < total; ++n) {
    Point p;
    p.sweep = spec.name;
    p.request = spec.base;
    p.repeats = spec.repeats;
    p.warmup = spec.warmup;
    p.compare = spec.compare;
    p.technique = spec.technique;
    p.method = spec.method;
    for (std::size_t f = 0; f < spec.factors.size(); ++f) {
      p.factors.push_back(spec.factors[f].paths);
      for (std::size_t k = 0; k < spec.factors[f].paths.size(); ++k) {
        const std::string& path = spec.factors[f].paths[k];
        const json& v = spec.factors[f].settings[at[f]][k];
        setPath(p.request, path, v);
        p.params[path] = v;
      }
    }
    // A scene file is uploaded by the runner; the request (and so the point id) names its digest.
    if (p.request["scene"].is_object() && p.request["scene"].contains("file")) {
      if (!p.request["scene"]["file"].is_string()) throw UsageError("sweep: scene.file must be a path");
      fs::path file = p.request["scene"]["file"].get<std::string>();
      if (file.is_relative()) file = spec.dir / file;
      auto it = digests.find(file.string());
      if (it == digests.end()) it = digests.emplace(file.string(), api::sceneDigest(sceneFileBytes(file.string()))).first;
      p.sceneFile = file.string();
      p.request["scene"] = {{"digest", it->second}};
    }
    json key = p.request;
    if (!p.compare.is_null()) key["compare"] = p.compare;
    p.id = api::sha256Hex(key.dump()).substr(0, 16);
    points.push_back(std::move(p));
    // Odometer: the last factor moves fastest.
    for (std::size_t f = spec.factors.size(); f-- > 0;) {
      if (++at[f] < spec.factors[f].settings.size()) break;
      at[f] = 0;
    }
  }
  return points;
}

json summarize(std::vector<double> v) {
  if (v.empty()) return nullptr;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  const double median = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
  return {{"median", median}, {"min", v.front()}, {"max", v.back()}, {"n", n}};
}

std::string paramLabel(const json& params, const std::set<std::string>& skip) {
  std::string out;
  for (const auto& [path, v] : params.items()) {
    if (skip.count(path)) continue;
    const auto dot = path.rfind('.');
    if (!out.empty()) out += " ";
    out += (dot == std::string::npos ? path : path.substr(dot + 1)) + "=" + (v.is_string() ? v.get<std::string>() : v.dump());
  }
  return out;
}

}  // namespace radiant::client::sweep
