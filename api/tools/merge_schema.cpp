// Build-time tool: completes api/schema/render_request.json with every technique's descriptor
// (renderer/techniques/<name>/<name>.json: its parameters, what it reads and writes, its AOV rows and
// light-path classes) so the daemon, the client, the renderer and the docs read one merged schema.
// A technique's parameters go to properties.passes.properties.<name> (its declaration to the
// annotation "x-technique" there), its AOV rows to the top-level "x-aovs" (api/Aovs.cpp).
//   merge_schema <out.json> <render_request.json> <media.json> <technique.json>...
// media.json (the particle-system schema) becomes properties.media.items (particles given inline) and
// the annotation "x-gltf-media" (the RADIANT_particle_system node extension: particles as accessors).
// A technique file that breaks the rules below fails the build, naming the file and the key.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

#include "api/LightPaths.h"

using nlohmann::json;

namespace {

json readJson(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  try {
    return json::parse(in);
  } catch (const json::exception& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
}

void fail(const std::string& file, const std::string& what) { throw std::runtime_error(file + ": " + what); }

// What is wrong with `v` as a value of the (normalised) parameter `p`: "is not of type T", "is below its
// minimum", "is above its maximum", "is not in its enum", or "" when it is one the parameter accepts.
std::string valueProblem(const json& p, const json& v) {
  const std::string type = p["type"];
  const bool typeOk = (type == "integer" && v.is_number_integer()) || (type == "number" && v.is_number()) ||
                      (type == "boolean" && v.is_boolean()) || (type == "string" && v.is_string());
  if (!typeOk) return "is not of type " + type;
  if (p.contains("minimum") && v.is_number() && v.get<double>() < p["minimum"].get<double>()) return "is below its minimum";
  if (p.contains("maximum") && v.is_number() && v.get<double>() > p["maximum"].get<double>()) return "is above its maximum";
  if (p.contains("enum") && std::find(p["enum"].begin(), p["enum"].end(), v) == p["enum"].end()) return "is not in its enum";
  return "";
}

// Technique parameters use the request schema's vocabulary; "min"/"max" are accepted as aliases.
json normaliseParam(const std::string& file, const std::string& name, const json& p) {
  static const std::set<std::string> kAllowed{"type",    "default", "minimum",     "maximum", "min",
                                              "max",     "enum",    "description", "x-cost"};
  if (!p.is_object()) fail(file, "params." + name + " must be an object");
  json out = json::object();
  for (const auto& [k, v] : p.items()) {
    if (!kAllowed.count(k)) fail(file, "params." + name + ": unknown key \"" + k + "\"");
    std::string key = k == "min" ? "minimum" : k == "max" ? "maximum" : k;
    out[key] = v;
  }
  static const std::set<std::string> kTypes{"integer", "number", "boolean", "string"};
  if (!out.contains("type") || !out["type"].is_string() || !kTypes.count(out["type"].get<std::string>()))
    fail(file, "params." + name + ".type must be one of integer, number, boolean, string");
  if (!out.contains("default")) fail(file, "params." + name + " has no default");
  if (!out.contains("description") || !out["description"].is_string())
    fail(file, "params." + name + " has no description");
  const std::string type = out["type"];
  // Every number a request can carry is bounded, so none overflows the float it becomes (issue 13).
  if ((type == "number" || type == "integer") && !out.contains("enum") &&
      !(out.contains("minimum") && out.contains("maximum")))
    fail(file, "params." + name + " is a " + type + " without both minimum and maximum (or an enum)");
  // What a parameter costs (api/Validate.h, costLimit): the server limit that caps it.
  if (out.contains("x-cost")) {
    static const std::set<std::string> kCosts{"samples", "photons", "particles", "resolution", "nodes", "iterations",
                                              "none"};
    if (!out["x-cost"].is_string() || !kCosts.count(out["x-cost"].get<std::string>()))
      fail(file, "params." + name +
                     ".x-cost must be one of samples, photons, particles, resolution, nodes, iterations, none");
    if (type != "integer") fail(file, "params." + name + " has an x-cost but is not an integer");
  }
  if (const std::string problem = valueProblem(out, out["default"]); !problem.empty())
    fail(file, "params." + name + ".default " + problem);
  return out;
}

// An optional array of names (resources, AOVs, light-path classes).
json names(const std::string& file, const json& t, const char* key) {
  const json v = t.value(key, json::array());
  if (!v.is_array()) fail(file, std::string("\"") + key + "\" must be an array of names");
  for (const auto& n : v)
    if (!n.is_string() || n.get<std::string>().empty()) fail(file, std::string("\"") + key + "\" must hold names");
  return v;
}

json flag(const std::string& file, const json& t, const char* key, bool required) {
  if (!t.contains(key)) {
    if (required) fail(file, std::string("missing \"") + key + "\" (true or false)");
    return false;
  }
  if (!t[key].is_boolean()) fail(file, std::string("\"") + key + "\" must be true or false");
  return t[key];
}

// The technique's preset for `radiant bench` (client/commands/Sweep.cpp): the parameter values its
// sweep crosses, in the full run and under --quick, the request fields it adds, and the compare block
// used when none of its outputs has a ground truth. Every axis must be one of its parameters and every
// value one its schema accepts, so the bench never sends a request the server refuses.
//   "bench": {"axes": {"<param>": [v, ...] | {"full": [v, ...], "quick": [v, ...]}},
//             "request": {...}, "compare": {...}}
json benchPreset(const std::string& file, const json& t, const json& params) {
  const json b = t.value("bench", json::object());
  if (!b.is_object()) fail(file, "\"bench\" must be an object");
  static const std::set<std::string> kAllowed{"axes", "request", "compare"};
  for (const auto& [k, v] : b.items())
    if (!kAllowed.count(k)) fail(file, "bench: unknown key \"" + k + "\"");
  json out = {{"axes", json::object()},
              {"request", b.value("request", json::object())},
              {"compare", b.value("compare", json::object())}};
  for (const char* k : {"request", "compare"})
    if (!out[k].is_object()) fail(file, std::string("bench.") + k + " must be an object");
  const json axes = b.value("axes", json::object());
  if (!axes.is_object()) fail(file, "bench.axes must be an object");
  for (const auto& [name, spec] : axes.items()) {
    const std::string where = "bench.axes." + name;
    if (!params.contains(name)) fail(file, where + " is not one of its \"params\"");
    const json& p = params[name];
    json modes = spec.is_array() ? json{{"full", spec}, {"quick", spec}} : spec;
    if (!modes.is_object() || !modes.contains("full") || !modes.contains("quick") || modes.size() != 2)
      fail(file, where + " must be an array of values or {\"full\": [...], \"quick\": [...]}");
    for (const auto& [mode, values] : modes.items()) {
      if (!values.is_array() || values.empty()) fail(file, where + "." + mode + " must be a non-empty array");
      for (const auto& v : values)
        if (const std::string problem = valueProblem(p, v); !problem.empty())
          fail(file, where + ": " + v.dump() + " " + problem);
    }
    out["axes"][name] = modes;
  }
  return out;
}

// One row of the AOV table (api/Aovs.h, AovInfo) with every default filled in: the resource is the
// AOV's own name, channels 3 (R, G, B; 1: Y; 4: R, G, B, A), resolve average, radiance true.
json aovRow(const std::string& file, const std::string& technique, const std::string& aov, const json& r) {
  static const std::set<std::string> kAllowed{"format",      "resource",   "first_channel", "channels",   "channel_names",
                                              "ground_truth", "resolve",   "radiance",      "description"};
  const std::string where = "aovs." + aov;
  if (!r.is_object()) fail(file, where + " must be an object");
  for (const auto& [k, v] : r.items())
    if (!kAllowed.count(k)) fail(file, where + ": unknown key \"" + k + "\"");
  static const std::set<std::string> kFormats{"RGBA32F", "RGBA16F", "R32F"};
  if (!r.contains("format") || !r["format"].is_string() || !kFormats.count(r["format"].get<std::string>()))
    fail(file, where + ".format must be one of RGBA32F, RGBA16F, R32F");
  if (!r.contains("description") || !r["description"].is_string()) fail(file, where + " has no description");
  const int channels = r.value("channels", 3);
  if (channels < 1 || channels > 4) fail(file, where + ".channels must be 1 to 4");
  const int first = r.value("first_channel", 0);
  const int capacity = r["format"] == "R32F" ? 1 : 4;
  if (first < 0 || first + channels > capacity) fail(file, where + ": first_channel + channels exceed its format");
  json suffixes = r.contains("channel_names") ? r["channel_names"]
                  : channels == 1             ? json::array({"Y"})
                  : channels == 4             ? json::array({"R", "G", "B", "A"})
                                              : json::array({"R", "G", "B"});
  if (!suffixes.is_array() || static_cast<int>(suffixes.size()) != channels)
    fail(file, where + ".channel_names must name each of its channels");
  json exr = json::array();
  for (const auto& s : suffixes) {
    if (!s.is_string()) fail(file, where + ".channel_names must be strings");
    exr.push_back(aov + "." + s.get<std::string>());
  }
  const std::string resolve = r.value("resolve", "average");
  if (resolve != "average" && resolve != "nearest") fail(file, where + ".resolve must be average or nearest");
  const json radiance = r.value("radiance", json(true));
  if (!radiance.is_boolean()) fail(file, where + ".radiance must be true or false");
  const json truth = r.value("ground_truth", json(""));
  if (!truth.is_string()) fail(file, where + ".ground_truth must be a reference mode");
  return json{{"name", aov},
              {"producer", technique},
              {"format", r["format"]},
              {"resource", r.value("resource", aov)},
              {"first_channel", first},
              {"channels", channels},
              {"exr", exr},
              {"ground_truth", truth},
              {"resolve", resolve},
              {"radiance", radiance},
              {"description", r["description"]}};
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4) {
    std::cerr << "usage: merge_schema <out.json> <render_request.json> <media.json> <technique.json>...\n";
    return 2;
  }
  try {
    json request = readJson(argv[2]);
    json& passes = request.at("properties").at("passes");
    passes["properties"] = json::object();
    std::set<std::string> aovs;
    std::map<std::string, std::string> aovRows;     // AOV -> the technique that declares its row
    std::map<std::string, std::string> outputFile;  // AOV -> the first descriptor that outputs it
    json aovTable = json::array();
    {
      const std::string file = argv[3];
      const json media = readJson(file);
      for (const char* k : {"system", "request_particles", "gltf_particles"})
        if (!media.contains(k) || !media[k].is_object()) fail(file, std::string("missing object \"") + k + "\"");
      json inRequest = media["system"], inGltf = media["system"];
      inRequest["properties"]["particles"] = media["request_particles"];
      inGltf["properties"]["particles"] = media["gltf_particles"];
      json& m = request.at("properties").at("media");
      m["items"] = inRequest;
      request["x-gltf-media"] = inGltf;
    }
    for (int i = 4; i < argc; ++i) {
      const std::string file = argv[i];
      json t = readJson(file);
      static const std::set<std::string> kAllowed{
          "name",    "summary",   "description", "inputs",         "optional_inputs", "prepare_outputs",
          "outputs", "resources", "aovs",        "adds_to_beauty", "beauty_blend",    "on_by_default",
          "light_paths", "requires_paths", "claims_when_named", "exclusive", "params", "bench"};
      for (const auto& [k, v] : t.items())
        if (!kAllowed.count(k))
          fail(file, "unknown key \"" + k + "\"" +
                         (k == "after" ? std::string(" (gone: the frame graph orders passes by what they read "
                                                     "and by their beauty_blend; docs/API.md)")
                                       : std::string()));
      if (!t.contains("name") || !t["name"].is_string()) fail(file, "missing \"name\"");
      const std::string name = t["name"];
      if (std::filesystem::path(file).stem().string() != name) fail(file, "name must match the file name");
      for (const char* k : {"summary", "description"})
        if (!t.contains(k) || !t[k].is_string()) fail(file, std::string("missing \"") + k + "\"");
      json outputs = names(file, t, "outputs");
      for (const auto& o : outputs) {
        aovs.insert(o.get<std::string>());
        outputFile.emplace(o.get<std::string>(), file);
      }
      json technique = {{"summary", t["summary"]},
                        {"inputs", names(file, t, "inputs")},
                        {"optional_inputs", names(file, t, "optional_inputs")},
                        {"prepare_outputs", names(file, t, "prepare_outputs")},
                        {"resources", names(file, t, "resources")},
                        {"adds_to_beauty", flag(file, t, "adds_to_beauty", true)},
                        {"beauty_blend", t.value("beauty_blend", json("add"))},
                        {"on_by_default", flag(file, t, "on_by_default", true)},
                        {"light_paths", names(file, t, "light_paths")},
                        {"requires_paths", names(file, t, "requires_paths")},
                        {"claims_when_named", flag(file, t, "claims_when_named", false)},
                        {"exclusive", flag(file, t, "exclusive", false)}};
      // How it composes into beauty, which orders it among the frame's beauty writers (FramePlanner's
      // executionOrder): add (commutes with the other adds), over (blended surfaces, after every add),
      // transmit (media: beauty * T + C, after everything else).
      if (const json& b = technique["beauty_blend"]; !b.is_string() || (b != "add" && b != "over" && b != "transmit"))
        fail(file, "\"beauty_blend\" must be \"add\", \"over\" or \"transmit\"");
      if (t.contains("beauty_blend") && !technique["adds_to_beauty"].get<bool>())
        fail(file, "\"beauty_blend\" needs \"adds_to_beauty\": true");
      // What prepare() publishes (before any pass's execute): readers need not run after this pass.
      for (const auto& o : technique["prepare_outputs"])
        if (std::find(outputs.begin(), outputs.end(), o) == outputs.end() &&
            std::find(technique["resources"].begin(), technique["resources"].end(), o) == technique["resources"].end())
          fail(file, "prepare_outputs: \"" + o.get<std::string>() + "\" is not one of its \"outputs\" or \"resources\"");
      for (const char* k : {"light_paths", "requires_paths"})
        for (const auto& c : technique[k])
          if (radiant::api::lightPathBit(c.get<std::string>()) == 0)
            fail(file, std::string(k) + ": \"" + c.get<std::string>() +
                           "\" is not a light-path class (api/LightPaths.h lists them)");
      for (const auto& c : technique["requires_paths"])
        if (std::find(technique["light_paths"].begin(), technique["light_paths"].end(), c) == technique["light_paths"].end())
          fail(file, "requires_paths: \"" + c.get<std::string>() + "\" is not one of its \"light_paths\"");
      const json declared = t.value("aovs", json::object());
      if (!declared.is_object()) fail(file, "\"aovs\" must be an object of AOV rows");
      for (const auto& [aov, row] : declared.items()) {
        if (std::find(outputs.begin(), outputs.end(), aov) == outputs.end())
          fail(file, "aovs." + aov + " is not one of its \"outputs\"");
        if (!aovRows.emplace(aov, name).second) fail(file, "aovs." + aov + " is declared by " + aovRows[aov] + " too");
        aovTable.push_back(aovRow(file, name, aov, row));
      }
      json properties = json::object();
      const json params = t.value("params", json::object());
      if (!params.is_object()) fail(file, "\"params\" must be an object");
      for (const auto& [pname, p] : params.items())
        properties[pname] = normaliseParam(file, pname, p);
      technique["bench"] = benchPreset(file, t, properties);
      passes["properties"][name] = json{{"type", "object"},
                                        {"description", t["description"]},
                                        {"x-outputs", outputs},
                                        {"x-technique", technique},
                                        {"additionalProperties", false},
                                        {"properties", properties}};
    }
    // Every AOV a technique outputs has one row, declared by one technique (the media AOVs, which
    // several exclusive techniques write, by the default owner).
    for (const std::string& aov : aovs)
      if (!aovRows.count(aov))
        fail(outputFile[aov], "outputs: no technique declares the row of AOV \"" + aov + "\" (\"aovs\")");
    request["x-aovs"] = aovTable;
    // The AOV names an output may ask for: "beauty" plus every technique's outputs.
    json aovEnum = json::array({"beauty"});
    for (const auto& a : aovs)
      if (a != "beauty") aovEnum.push_back(a);
    request["properties"]["outputs"]["items"]["properties"]["aovs"]["items"]["enum"] = aovEnum;
    request["properties"]["compare"]["properties"]["aov"]["enum"] = aovEnum;
    request["properties"]["refine"]["properties"]["aov"]["enum"] = aovEnum;

    std::ostringstream text;
    text << request.dump(2) << "\n";
    // Write only on change, so dependants do not rebuild needlessly.
    std::string old;
    if (std::ifstream in(argv[1]); in) old.assign(std::istreambuf_iterator<char>(in), {});
    if (old != text.str()) std::ofstream(argv[1]) << text.str();
  } catch (const std::exception& e) {
    std::cerr << "merge_schema: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
