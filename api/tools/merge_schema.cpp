// Build-time tool: completes api/schema/render_request.json with every technique's parameter schema
// (api/schema/techniques/<name>.json) so the daemon, the client and the docs read one merged schema.
//   merge_schema <out.json> <render_request.json> <media.json> <technique.json>...
// media.json (the particle-system schema) becomes properties.media.items (particles given inline) and
// the annotation "x-gltf-media" (the RADIANT_particle_system node extension: particles as accessors).
// A technique file that breaks the rules below fails the build, naming the file and the key.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

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
  const json& d = out["default"];
  bool typeOk = (type == "integer" && d.is_number_integer()) || (type == "number" && d.is_number()) ||
                (type == "boolean" && d.is_boolean()) || (type == "string" && d.is_string());
  if (!typeOk) fail(file, "params." + name + ".default is not of type " + type);
  if (out.contains("minimum") && d.is_number() && d.get<double>() < out["minimum"].get<double>())
    fail(file, "params." + name + ".default is below its minimum");
  if (out.contains("maximum") && d.is_number() && d.get<double>() > out["maximum"].get<double>())
    fail(file, "params." + name + ".default is above its maximum");
  if (out.contains("enum") && std::find(out["enum"].begin(), out["enum"].end(), d) == out["enum"].end())
    fail(file, "params." + name + ".default is not in its enum");
  return out;
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
      static const std::set<std::string> kAllowed{"name", "description", "outputs", "params"};
      for (const auto& [k, v] : t.items())
        if (!kAllowed.count(k)) fail(file, "unknown key \"" + k + "\"");
      if (!t.contains("name") || !t["name"].is_string()) fail(file, "missing \"name\"");
      const std::string name = t["name"];
      if (std::filesystem::path(file).stem().string() != name) fail(file, "name must match the file name");
      if (!t.contains("description") || !t["description"].is_string()) fail(file, "missing \"description\"");
      json outputs = t.value("outputs", json::array());
      if (!outputs.is_array()) fail(file, "\"outputs\" must be an array of AOV names");
      for (const auto& o : outputs) aovs.insert(o.get<std::string>());
      json properties = json::object();
      const json params = t.value("params", json::object());
      if (!params.is_object()) fail(file, "\"params\" must be an object");
      for (const auto& [pname, p] : params.items())
        properties[pname] = normaliseParam(file, pname, p);
      passes["properties"][name] = json{{"type", "object"},
                                        {"description", t["description"]},
                                        {"x-outputs", outputs},
                                        {"additionalProperties", false},
                                        {"properties", properties}};
    }
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
