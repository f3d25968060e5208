#include "api/Validate.h"

#include <algorithm>
#include <cmath>
#include <regex>
#include <sstream>
#include <type_traits>

#include "api/JsonLimits.h"
#include "embedded/radiant_api_schema.h"

namespace radiant::api {

using nlohmann::json;

namespace {

// Path segments per sample the reference may run without Russian roulette (see normaliseRenderRequest).
constexpr long long kUnrouletteBouncesPerSample = 64;

// A value quoted in an error detail: at most ~80 bytes, never cut inside a UTF-8 sequence, and
// invalid bytes replaced, so the problem writer can always encode it.
std::string shown(const json& v) { return truncateUtf8(dumpSafe(v), 77); }

std::string at(const std::string& pointer) { return pointer.empty() ? "the request" : pointer; }

[[noreturn]] void typeError(const std::string& pointer, const std::string& expected, const json& value) {
  throw ApiError(400, "type-mismatch", "Wrong JSON type",
                 at(pointer) + ": expected " + expected + ", got " + std::string(value.type_name()) + " " + shown(value),
                 pointer);
}

[[noreturn]] void invalid(const std::string& pointer, const std::string& detail) {
  throw ApiError(422, "invalid-value", "Invalid value", at(pointer) + ": " + detail, pointer);
}

std::string number(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

bool isIntegral(const json& v) {
  if (v.is_number_integer()) return true;
  if (!v.is_number_float()) return false;
  double d = v.get<double>();
  return std::isfinite(d) && std::floor(d) == d && std::fabs(d) <= 9007199254740992.0;
}

bool hasType(const std::string& type, const json& v) {
  return type == "object"    ? v.is_object()
         : type == "array"   ? v.is_array()
         : type == "string"  ? v.is_string()
         : type == "boolean" ? v.is_boolean()
         : type == "number"  ? v.is_number()
         : type == "integer" ? isIntegral(v)
                             : false;
}

json checkType(const std::string& type, const json& v, const std::string& pointer) {
  if (type == "object") {
    if (!v.is_object()) typeError(pointer, "an object", v);
  } else if (type == "array") {
    if (!v.is_array()) typeError(pointer, "an array", v);
  } else if (type == "string") {
    if (!v.is_string()) typeError(pointer, "a string", v);
  } else if (type == "boolean") {
    if (!v.is_boolean()) typeError(pointer, "a boolean", v);
  } else if (type == "number") {
    if (!v.is_number()) typeError(pointer, "a number", v);
  } else if (type == "integer") {
    if (!isIntegral(v)) typeError(pointer, "an integer", v);
    if (v.is_number_float()) {  // 5.0 is an integer in JSON Schema; store it as one
      double d = v.get<double>();
      return d < 0 ? json(static_cast<std::int64_t>(d)) : json(static_cast<std::uint64_t>(d));
    }
  } else {
    throw std::logic_error("schema: unsupported type \"" + type + "\" at " + pointer);
  }
  return v;
}

// Caps every value whose schema declares "x-cost" (Validate.h), walking the validated request beside
// its schema and the request as sent (`given`, null where the request carries nothing). A pass
// parameter the request does not give (its schema default) is not refused here: the renderer lowers it
// to the cap with a warning (api::chooseConfiguration), as it does for passes the planner adds. Every
// other default is capped like a given value.
void capCosts(const json& schema, const json& value, const json* given, const std::string& pointer,
              const RequestLimits& limits) {
  if (auto c = schema.find("x-cost"); c != schema.end() && value.is_number_integer()) {
    const bool passDefault = !given && pointer.rfind("/passes/", 0) == 0;
    const std::string kind = c->get<std::string>();
    if (const auto l = costLimit(kind, limits); l && !passDefault && value.get<long long>() > l->max)
      throw ApiError(422, "limit-exceeded", "Server limit exceeded",
                     pointer + ": " + std::to_string(value.get<long long>()) + " is above this server's " + kind +
                         " limit " + std::to_string(l->max) + " (radiantd " + l->flag + ")",
                     pointer);
  }
  auto child = [&](const auto& key) -> const json* {
    if (!given) return nullptr;
    if constexpr (std::is_integral_v<std::decay_t<decltype(key)>>) {
      return given->is_array() && key < given->size() ? &(*given)[key] : nullptr;
    } else {
      if (!given->is_object()) return nullptr;
      auto it = given->find(key);
      return it == given->end() ? nullptr : &*it;
    }
  };
  if (value.is_object()) {
    if (auto p = schema.find("properties"); p != schema.end())
      for (const auto& [key, sub] : p->items())
        if (auto it = value.find(key); it != value.end())
          capCosts(sub, *it, child(key), pointerAppend(pointer, key), limits);
  } else if (value.is_array()) {
    if (auto items = schema.find("items"); items != schema.end())
      for (std::size_t i = 0; i < value.size(); ++i) capCosts(*items, value[i], child(i), pointerAppend(pointer, i), limits);
  }
}

void collectCosts(const json& schema, const std::string& pointer, std::vector<std::pair<std::string, std::string>>& out) {
  if (!schema.is_object()) return;
  if (auto c = schema.find("x-cost"); c != schema.end()) out.emplace_back(pointer, c->get<std::string>());
  if (auto p = schema.find("properties"); p != schema.end())
    for (const auto& [key, sub] : p->items()) collectCosts(sub, pointerAppend(pointer, key), out);
  if (auto items = schema.find("items"); items != schema.end()) collectCosts(*items, pointer + "/*", out);
}

}  // namespace

std::optional<CostLimit> costLimit(std::string_view cost, const RequestLimits& limits) {
  if (cost == "samples") return CostLimit{limits.maxSamples, "--max-samples"};
  if (cost == "photons") return CostLimit{limits.maxPhotons, "--max-photons"};
  if (cost == "particles") return CostLimit{static_cast<long long>(limits.maxParticles), "--max-particles"};
  if (cost == "resolution") return CostLimit{limits.maxMapResolution, "--max-map-resolution"};
  if (cost == "nodes") return CostLimit{limits.maxNetworkNodes, "--max-network-nodes"};
  if (cost == "iterations") return CostLimit{limits.maxIterations, "--max-iterations"};
  if (cost == "none") return std::nullopt;
  throw std::logic_error("schema: unknown x-cost \"" + std::string(cost) + "\"");
}

std::vector<std::pair<std::string, std::string>> costParameters(const json& schema) {
  std::vector<std::pair<std::string, std::string>> out;
  collectCosts(schema, "", out);
  return out;
}

std::string pointerAppend(const std::string& pointer, std::string_view token) {
  std::string out = pointer + "/";
  for (char c : token) {
    if (c == '~') out += "~0";
    else if (c == '/') out += "~1";
    else out += c;
  }
  return out;
}

std::string pointerAppend(const std::string& pointer, std::size_t index) {
  return pointer + "/" + std::to_string(index);
}

json validate(const json& schema, const json& input, const std::string& pointer) {
  // A union of alternatives of distinct JSON types ("background": a name or a colour): the value's type
  // picks the alternative, whose own checks then name what is wrong.
  if (auto alternatives = schema.find("oneOf"); alternatives != schema.end()) {
    std::string expected;
    for (const json& alternative : *alternatives) {
      const std::string type = alternative.value("type", "");
      if (hasType(type, input)) return validate(alternative, input, pointer);
      const bool vowel = type == "array" || type == "object" || type == "integer";
      expected += (expected.empty() ? "" : " or ") + std::string(vowel ? "an " : "a ") + type;
    }
    typeError(pointer, expected, input);
  }
  json value = input;
  if (auto t = schema.find("type"); t != schema.end()) value = checkType(t->get<std::string>(), value, pointer);

  if (auto e = schema.find("enum"); e != schema.end()) {
    if (std::find(e->begin(), e->end(), value) == e->end())
      invalid(pointer, shown(value) + " is not one of " + shown(*e));
  }
  if (value.is_number()) {
    const double d = value.get<double>();
    if (auto m = schema.find("minimum"); m != schema.end() && d < m->get<double>())
      throw ApiError(422, "out-of-range", "Value out of range",
                     at(pointer) + ": " + shown(value) + " is below the minimum " + number(m->get<double>()), pointer);
    if (auto m = schema.find("exclusiveMinimum"); m != schema.end() && !(d > m->get<double>()))
      throw ApiError(422, "out-of-range", "Value out of range",
                     at(pointer) + ": " + shown(value) + " is not above " + number(m->get<double>()), pointer);
    if (auto m = schema.find("maximum"); m != schema.end() && d > m->get<double>())
      throw ApiError(422, "out-of-range", "Value out of range",
                     at(pointer) + ": " + shown(value) + " is above the maximum " + number(m->get<double>()), pointer);
  }
  if (value.is_string()) {
    if (auto p = schema.find("pattern"); p != schema.end()) {
      // Patterns are few and small; compiling per call keeps this function stateless.
      if (!std::regex_search(value.get<std::string>(), std::regex(p->get<std::string>(), std::regex::ECMAScript)))
        invalid(pointer, shown(value) + " does not match " + p->get<std::string>());
    }
  }
  if (value.is_array()) {
    if (auto m = schema.find("minItems"); m != schema.end() && value.size() < m->get<std::size_t>())
      invalid(pointer, "needs at least " + std::to_string(m->get<std::size_t>()) + " items, got " + std::to_string(value.size()));
    if (auto m = schema.find("maxItems"); m != schema.end() && value.size() > m->get<std::size_t>())
      invalid(pointer, "allows at most " + std::to_string(m->get<std::size_t>()) + " items, got " + std::to_string(value.size()));
    if (auto items = schema.find("items"); items != schema.end())
      for (std::size_t i = 0; i < value.size(); ++i) value[i] = validate(*items, value[i], pointerAppend(pointer, i));
  }
  if (value.is_object()) {
    static const json kEmpty = json::object();
    auto pit = schema.find("properties");
    const json& props = pit != schema.end() ? *pit : kEmpty;
    const bool closed = schema.contains("additionalProperties") && schema["additionalProperties"] == false;
    for (auto it = value.begin(); it != value.end(); ++it) {
      auto ps = props.find(it.key());
      if (ps == props.end()) {
        if (closed) {
          std::string known;
          for (auto k = props.begin(); k != props.end(); ++k) known += (known.empty() ? "" : ", ") + k.key();
          throw ApiError(422, "unknown-field", "Unknown field",
                         pointerAppend(pointer, it.key()) + ": unknown key \"" + it.key() + "\"" +
                             (known.empty() ? " (this object takes no keys)" : " (known: " + known + ")"),
                         pointerAppend(pointer, it.key()));
        }
        continue;
      }
      it.value() = validate(*ps, it.value(), pointerAppend(pointer, it.key()));
    }
    if (auto r = schema.find("required"); r != schema.end())
      for (const auto& key : *r)
        if (!value.contains(key.get<std::string>()))
          throw ApiError(422, "missing-field", "Missing field",
                         pointerAppend(pointer, key.get<std::string>()) + ": required key \"" +
                             key.get<std::string>() + "\" is missing",
                         pointerAppend(pointer, key.get<std::string>()));
    if (auto m = schema.find("minProperties"); m != schema.end() && value.size() < m->get<std::size_t>()) {
      std::string keys;
      for (auto k = props.begin(); k != props.end(); ++k) keys += (keys.empty() ? "" : ", ") + k.key();
      invalid(pointer, "needs at least " + std::to_string(m->get<std::size_t>()) + " of the keys " + keys);
    }
    if (auto m = schema.find("maxProperties"); m != schema.end() && value.size() > m->get<std::size_t>())
      invalid(pointer, "allows at most " + std::to_string(m->get<std::size_t>()) + " key(s), got " + std::to_string(value.size()));
    for (auto k = props.begin(); k != props.end(); ++k)
      if (!value.contains(k.key()) && k->contains("default"))
        value[k.key()] = validate(*k, (*k)["default"], pointerAppend(pointer, k.key()));
  }
  return value;
}

void checkJsonText(std::string_view text, std::size_t maxDepth) {
  const auto problem = scanJson(text, maxDepth);
  if (!problem) return;
  switch (problem->kind) {
    case JsonScanProblem::Kind::TooDeep:
      throw ApiError(422, "limit-exceeded", "Server limit exceeded",
                     problem->detail + "; this server's limit is radiantd --max-json-depth " + std::to_string(maxDepth),
                     problem->pointer);
    case JsonScanProblem::Kind::InvalidUtf8:
      throw ApiError(400, "invalid-utf8", "Invalid UTF-8", problem->detail, problem->pointer);
    case JsonScanProblem::Kind::NumberOverflow:
      throw ApiError(422, "out-of-range", "Value out of range", problem->detail, problem->pointer);
  }
}

json parseJson(std::string_view text, std::size_t maxDepth) {
  // The scan first: nesting, UTF-8 and overflowing numbers are found without recursion and with
  // a pointer, before nlohmann builds (and later copies) the tree.
  checkJsonText(text, maxDepth);
  try {
    return json::parse(text.begin(), text.end());
  } catch (const json::parse_error& e) {
    throw ApiError(400, "malformed-json", "Malformed JSON",
                   "the body is not valid JSON: syntax error at byte " + std::to_string(e.byte), "");
  } catch (const json::exception& e) {
    throw ApiError(400, "malformed-json", "Malformed JSON", std::string("the body is not valid JSON: ") + e.what(), "");
  }
}

const json& renderRequestSchema() {
  static const json schema = [] {
    std::string_view text = embedded_schema::find("render_request.json");
    if (text.empty()) throw std::logic_error("embedded render_request.json missing");
    return json::parse(text);
  }();
  return schema;
}

json techniqueParams(std::string_view technique, const json& given) {
  const json& passes = renderRequestSchema().at("properties").at("passes").at("properties");
  auto it = passes.find(std::string(technique));
  if (it == passes.end()) throw std::out_of_range("no schema for technique '" + std::string(technique) + "'");
  return validate(*it, given.is_null() ? json::object() : given, pointerAppend("/passes", technique));
}

const std::vector<TechniqueSchema>& techniqueSchemas() {
  static const std::vector<TechniqueSchema> all = [] {
    std::vector<TechniqueSchema> out;
    for (const auto& [name, s] : renderRequestSchema()["properties"]["passes"]["properties"].items()) {
      TechniqueSchema t;
      t.name = name;
      t.description = s.value("description", "");
      t.outputs = s.value("x-outputs", std::vector<std::string>{});
      t.params = s.value("properties", json::object());
      const json& d = s.at("x-technique");
      t.summary = d.at("summary");
      t.inputs = d.at("inputs");
      t.optionalInputs = d.at("optional_inputs");
      t.prepareOutputs = d.at("prepare_outputs");
      t.beautyBlend = d.at("beauty_blend");
      t.resources = d.at("resources");
      t.lightPaths = d.at("light_paths");
      t.requiredPaths = d.at("requires_paths");
      t.addsToBeauty = d.at("adds_to_beauty");
      t.onByDefault = d.at("on_by_default");
      t.claimsWhenNamed = d.at("claims_when_named");
      t.exclusive = d.at("exclusive");
      t.bench = d.at("bench");
      out.push_back(std::move(t));
    }
    return out;
  }();
  return all;
}

const TechniqueSchema* findTechnique(std::string_view name) {
  for (const auto& t : techniqueSchemas())
    if (t.name == name) return &t;
  return nullptr;
}

json to_json_value(const TechniqueSchema& t) {
  return json{{"name", t.name},
              {"summary", t.summary},
              {"description", t.description},
              {"outputs", t.outputs},
              {"params", t.params},
              {"bench", t.bench}};
}

const char* toString(ImageFormat f) { return f == ImageFormat::Exr ? "exr" : "png"; }

json normaliseRenderRequest(const json& body, const RequestLimits& limits) {
  // validate() copies values (recursively): a tree parsed elsewhere is held to the same depth.
  if (jsonDepth(body, limits.maxJsonDepth) > limits.maxJsonDepth)
    throw ApiError(422, "limit-exceeded", "Server limit exceeded",
                   "the request is nested deeper than " + std::to_string(limits.maxJsonDepth) +
                       " levels; this server's limit is radiantd --max-json-depth",
                   "");
  // "passes": {"name": false} turns an on-by-default pass off, {"name": true} turns one on with its
  // defaults. The schema describes parameter objects, so booleans of known techniques are taken out
  // before validation and put back after it (an unknown name still fails validation below).
  json input = body;
  std::vector<std::string> disabled;
  if (input.is_object() && input.contains("passes") && input["passes"].is_object()) {
    json& passes = input["passes"];
    for (auto it = passes.begin(); it != passes.end();) {
      if (it->is_boolean() && findTechnique(it.key())) {
        if (!it->get<bool>()) {
          disabled.push_back(it.key());
          it = passes.erase(it);
          continue;
        }
        *it = json::object();
      }
      ++it;
    }
  }
  json v = validate(renderRequestSchema(), input, "");
  for (const std::string& name : disabled) v["passes"][name] = false;

  auto limit = [](const std::string& pointer, long long value, long long max, const char* what) {
    if (value > max)
      throw ApiError(422, "limit-exceeded", "Server limit exceeded",
                     pointer + ": " + std::to_string(value) + " is above this server's " + what + " limit " +
                         std::to_string(max),
                     pointer);
  };
  limit("/width", v["width"].get<long long>(), limits.maxWidth, "width");
  limit("/height", v["height"].get<long long>(), limits.maxHeight, "height");
  capCosts(renderRequestSchema(), v, &input, "", limits);
  // The reference without Russian roulette runs every path to max_bounces (or until it escapes): its
  // work per pixel is spp x max_bounces path segments, not spp. Capped at what --max-samples allowed when
  // the schema's bounce maximum was 64 (a closed scene's worst case then), since the cost models and
  // x-cost caps charge samples only.
  if (const auto p = v.find("passes"); p != v.end() && p->is_object())
    if (const auto r = p->find("reference"); r != p->end() && r->is_object() &&
                                             !r->value("russian_roulette", true)) {
      const long long spp = r->value("spp", 64LL), bounces = r->value("max_bounces", 1024LL);
      const long long max = static_cast<long long>(limits.maxSamples) * kUnrouletteBouncesPerSample;
      if (spp * bounces > max)
        throw ApiError(422, "limit-exceeded", "Server limit exceeded",
                       "/passes/reference/max_bounces: with russian_roulette false every path runs to max_bounces, and spp x "
                       "max_bounces = " + std::to_string(spp * bounces) + " path segments per pixel is above this server's limit " +
                           std::to_string(max) + " (radiantd --max-samples x " + std::to_string(kUnrouletteBouncesPerSample) +
                           "); lower max_bounces or spp, or keep russian_roulette",
                       "/passes/reference/max_bounces");
    }

  const json& outputs = v["outputs"];
  for (std::size_t i = 0; i < outputs.size(); ++i)
    if (outputs[i]["format"] == "png" && outputs[i]["aovs"].size() != 1)
      throw ApiError(422, "invalid-value", "Invalid value",
                     "/outputs/" + std::to_string(i) + "/aovs: a png output holds exactly one AOV, got " +
                         std::to_string(outputs[i]["aovs"].size()),
                     "/outputs/" + std::to_string(i) + "/aovs");
  // The same AOV twice in one file, or the same file twice, only costs memory and time.
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    const json& aovs = outputs[i]["aovs"];
    for (std::size_t k = 0; k < aovs.size(); ++k)
      for (std::size_t j = 0; j < k; ++j)
        if (aovs[j] == aovs[k])
          throw ApiError(422, "invalid-value", "Invalid value",
                         pointerAppend(pointerAppend(pointerAppend("/outputs", i), "aovs"), k) + ": AOV " +
                             shown(aovs[k]) + " is already listed at index " + std::to_string(j),
                         pointerAppend(pointerAppend(pointerAppend("/outputs", i), "aovs"), k));
    for (std::size_t j = 0; j < i; ++j)
      if (outputs[j] == outputs[i])
        throw ApiError(422, "invalid-value", "Invalid value",
                       pointerAppend("/outputs", i) + ": the same output as /outputs/" + std::to_string(j),
                       pointerAppend("/outputs", i));
  }
  if (limits.maxOutputBytes > 0) {
    // Uncompressed size of every file asked for: RGBA per AOV, 2 or 4 bytes per EXR channel, 4
    // bytes per PNG pixel (the encoder's input, and its worst case with png_compression 0).
    const std::uint64_t pixels = v["width"].get<std::uint64_t>() * v["height"].get<std::uint64_t>();
    std::uint64_t total = 0;
    for (const auto& o : outputs)
      total += pixels * o["aovs"].size() * (o["format"] == "exr" ? (o["half"].get<bool>() ? 8u : 16u) : 4u);
    if (total > limits.maxOutputBytes)
      throw ApiError(422, "limit-exceeded", "Server limit exceeded",
                     "/outputs: the requested files hold " + std::to_string(total) +
                         " bytes uncompressed, above this server's limit of " + std::to_string(limits.maxOutputBytes) +
                         " (radiantd --max-frame-bytes)",
                     "/outputs");
  }
  return v;
}

RenderRequest parseRenderRequest(const json& body, const RequestLimits& limits) {
  const json v = normaliseRenderRequest(body, limits);
  auto vec3 = [](const json& a) { return glm::vec3(a[0].get<float>(), a[1].get<float>(), a[2].get<float>()); };
  auto dvec3 = [](const json& a) { return glm::dvec3(a[0].get<double>(), a[1].get<double>(), a[2].get<double>()); };

  RenderRequest r;
  const json& scene = v["scene"];
  if (scene.contains("digest")) r.scene = {SceneRef::Kind::Digest, scene["digest"]};
  else if (scene.contains("builtin")) r.scene = {SceneRef::Kind::Builtin, scene["builtin"]};
  else if (scene.contains("asset")) r.scene = {SceneRef::Kind::Asset, scene["asset"]};
  else r.scene = {SceneRef::Kind::Inline, scene["inline_glb"]};
  if (v.contains("camera")) {
    const json& c = v["camera"];
    CameraOverride cam;
    cam.hasPosition = c.contains("position");
    cam.hasTarget = c.contains("target");
    cam.hasUp = c.contains("up");
    cam.hasYfov = c.contains("yfov_deg");
    if (cam.hasPosition) cam.position = vec3(c["position"]);
    if (cam.hasTarget) cam.target = vec3(c["target"]);
    if (cam.hasYfov) cam.yfovDegrees = c["yfov_deg"].get<float>();
    if (c.contains("orbit")) {
      if (cam.hasPosition)
        throw ApiError(422, "invalid-value", "Invalid value",
                       "/camera/orbit: give the eye either as position or as orbit, not both", "/camera/orbit");
      const json& o = c["orbit"];
      cam.orbit = CameraOverride::Orbit{o["theta_deg"].get<double>(), o["phi_deg"].get<double>(), o.value("radius", 0.0)};
    }
    // In double and relative to the vectors' own lengths: the schema bounds coordinates to
    // [-1e9, 1e9], so an up vector of length 1e-30 is a direction like any other.
    if (cam.hasUp) {
      const glm::dvec3 up = dvec3(c["up"]);
      if (!(glm::length(up) > 0.0))
        throw ApiError(422, "invalid-value", "Invalid value", "/camera/up: the zero vector has no direction", "/camera/up");
      cam.up = glm::vec3(up / glm::length(up));
    }
    if (cam.hasPosition && cam.hasTarget) {
      const glm::dvec3 view = dvec3(c["target"]) - dvec3(c["position"]);
      const double viewLength = glm::length(view);
      const double scale = std::max({glm::length(dvec3(c["target"])), glm::length(dvec3(c["position"])), 1e-30});
      if (!(viewLength > 1e-6 * scale) || glm::length(cam.target - cam.position) == 0.f)
        throw ApiError(422, "invalid-value", "Invalid value",
                       "/camera/target: equals the camera position (to single precision)", "/camera/target");
      // |sin| of the angle between the view and up directions: below 1e-6 (0.2 arc seconds) the
      // camera's right vector is numerically meaningless.
      if (cam.hasUp) {
        const glm::dvec3 up = dvec3(c["up"]);
        if (glm::length(glm::cross(view / viewLength, up / glm::length(up))) < 1e-6)
          throw ApiError(422, "invalid-value", "Invalid value", "/camera/up: parallel to the view direction", "/camera/up");
      }
    }
    r.camera = cam;
  }
  r.width = v["width"];
  r.height = v["height"];
  for (const auto& [name, params] : v["passes"].items()) {
    if (params.is_boolean()) r.disabledPasses.insert(name);  // only false survives normalisation
    else r.passes[name] = params;
  }
  r.outputs.clear();
  for (const auto& o : v["outputs"]) {
    OutputSpec spec;
    spec.format = o["format"] == "exr" ? ImageFormat::Exr : ImageFormat::Png;
    spec.aovs = o["aovs"].get<std::vector<std::string>>();
    spec.halfFloat = o["half"];
    spec.pngCompression = o["png_compression"];
    r.outputs.push_back(std::move(spec));
  }
  r.exposure = v["exposure"].get<float>();
  r.toneMap = *toneMapFromString(v["tone_map"].get<std::string>());  // the schema's enum
  for (OutputSpec& o : r.outputs) o.toneMap = r.toneMap;
  if (const json& b = v["background"]; b.is_array())
    r.background = Background{Background::Kind::Colour, vec3(b)};
  else if (b == "transparent")
    r.background.kind = Background::Kind::Transparent;
  r.seed = v["seed"].get<std::uint64_t>();
  r.ambient = vec3(v["ambient"]);
  r.environment = v["environment"].get<std::string>();
  r.defaultLighting = v["default_lighting"].get<bool>();
  r.supersamplingGiven = body.contains("supersampling");
  r.supersampling = r.supersamplingGiven ? v["supersampling"].get<int>() : defaultSupersampling(r.width, r.height);
  if (!r.environment.empty() && r.ambient != glm::vec3(0.f))
    throw ApiError(422, "invalid-value", "Invalid value",
                   "/environment: give the sky either as ambient or as an environment map, not both", "/environment");
  if (v.contains("compare")) {
    const json& c = v["compare"];
    r.compare = CompareSpec{c["against"], c["aov"], c["spp"], c["max_bounces"]};
  }
  r.async = v["async"];
  // The parameters the request gave itself win over quality and time_budget_ms (api/Presets.h, chooseConfiguration).
  r.passesNamed = body.contains("passes");
  if (body.contains("passes"))
    for (const auto& [name, params] : body["passes"].items())
      if (params.is_object())
        for (const auto& [key, value] : params.items()) r.explicitParams[name].insert(key);
  r.quality = v["quality"].get<std::string>();
  r.timeBudgetMs = v["time_budget_ms"].get<double>();
  // The preset table's cost and error (api/presets.json) were measured at one raster sample per pixel:
  // a request that asks for a quality or a time budget without choosing its supersampling gets 1, so
  // that the table's predictions hold (until bench/presets.py regenerates the table at the default 2).
  if ((!r.quality.empty() || r.timeBudgetMs > 0) && !body.contains("supersampling")) r.supersampling = 1;
  if (!r.quality.empty() && r.timeBudgetMs > 0)
    throw ApiError(422, "invalid-value", "Invalid value",
                   "/time_budget_ms: give either quality or time_budget_ms, not both", "/time_budget_ms");
  if (v.contains("refine")) {
    const json& f = v["refine"];
    r.refine = RefineSpec{f["until_ms"].get<double>(), f["target_rmse"].get<double>(), f["max_batches"].get<int>(),
                          f["aov"].get<std::string>()};
    if (!r.async)
      throw ApiError(422, "invalid-value", "Invalid value",
                     "/refine: progressive refinement needs \"async\": true (poll the job for the current frame)",
                     "/refine");
  }
  std::size_t particles = 0;
  for (std::size_t i = 0; i < v["media"].size(); ++i) {
    const std::string ptr = pointerAppend("/media", i);
    r.media.push_back(particleSystemFromRequest(v["media"][i], ptr, limits.maxParticles - particles));
    particles += r.media.back().particles.size();
  }
  return r;
}

RenderRequest parseRenderRequest(std::string_view text, const RequestLimits& limits) {
  return parseRenderRequest(parseJson(text, limits.maxJsonDepth), limits);
}

}  // namespace radiant::api
