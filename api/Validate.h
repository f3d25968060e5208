#pragma once
// Validation of request JSON against the embedded schema (api/schema/, merged at build time), and
// conversion to the typed RenderRequest.
//
// The schema language is a subset of JSON Schema: type (object, array, string, integer, number,
// boolean), properties, additionalProperties (false only), required, minimum, maximum, enum, default,
// description, items, minItems, maxItems, minProperties, maxProperties, pattern, and oneOf whose
// alternatives have distinct types (the value's JSON type picks the alternative). Annotations ("title",
// "$id", "x-outputs") are ignored. Every property with a default is filled in when absent.
//
// Cost: an integer parameter whose value buys work or memory carries "x-cost", naming the server limit
// that caps it (costLimit below): "samples" (per pixel: spp, AO samples, light paths per pixel),
// "photons" (per frame), "particles" (per media system; their sum is capped again in api/Media.cpp),
// or "none" for a parameter whose name looks like a cost but is not one (ppm_base_photons is a radius
// calibration point). parseRenderRequest caps every x-cost value of the request, wherever it sits in
// the schema; schema_cost_test fails on a cost-like parameter name without x-cost.
//
// Error mapping (one rule, documented in docs/API.md): every error is an api::ApiError whose pointer
// (RFC 6901) names the offending field.
//   400 malformed-json   the body is not JSON (pointer "")
//   400 type-mismatch    a value has the wrong JSON type ("width": "big")
//   422 unknown-field    a key the schema does not define (unknown technique, misspelt parameter)
//   422 missing-field    a required key is absent
//   422 out-of-range     a number outside [minimum, maximum]
//   422 invalid-value    a value not in its enum, not matching its pattern, or a wrong item/key count
//   422 limit-exceeded   within the schema, but above a limit this server is configured with
//   400 invalid-utf8     a string that is not UTF-8 (before parsing, see api/JsonLimits.h)
// i.e. 400 means "this is not the shape of a request", 422 means "a request, but not one we accept".

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "api/Types.h"

namespace radiant::api {

// Limits a server sets at or below the schema's own.
struct RequestLimits {
  int maxWidth = 4096;
  int maxHeight = 4096;
  int maxSamples = 65536;  // caps every x-cost "samples" parameter (spp, samples, light_paths_per_pixel, compare.spp)
  long long maxPhotons = 4000000;  // caps every x-cost "photons" parameter (radiantd --max-photons)
  std::size_t maxJsonDepth = 64;  // nesting of the request text (radiantd --max-json-depth)
  // Uncompressed bytes of all requested output files (radiantd --max-frame-bytes); 0 = no limit.
  std::uint64_t maxOutputBytes = 0;
  // Particles of all request media systems together (radiantd --max-particles).
  std::size_t maxParticles = 65536;
  // Texels per side of any map or grid a pass allocates (x-cost "resolution": shadow_map_size, the
  // cube_resolution of specular, caustics and env_diffuse, photon/impostor/slice resolutions; memory and
  // fill grow with its square) (radiantd --max-map-resolution).
  int maxMapResolution = 4096;
  // Illumination-network nodes (x-cost "nodes": memory and work per iteration grow with nodes x
  // directions) (radiantd --max-network-nodes).
  int maxNetworkNodes = 65536;
  // Iterations of an iterative solver in one request (x-cost "iterations": illumination_network's
  // passes over every node and direction) (radiantd --max-iterations).
  int maxIterations = 1024;
  // The server's default frame budget in ms (radiantd --default-frame-budget-ms; 0 = none): a request
  // that names no quality, no time_budget_ms and no passes, whose default configuration the preset
  // table predicts above it, is rendered as if it had asked for time_budget_ms = this, with a warning
  // (api::chooseConfiguration). Not a cap: a request that names its passes runs as asked.
  double defaultFrameBudgetMs = 0;
};

// The limit an "x-cost" kind is capped by, and the radiantd flag that sets it; nullopt for "none".
// Throws std::logic_error for a kind it does not know (merge_schema refuses those at build time).
struct CostLimit {
  long long max;
  const char* flag;  // "--max-samples"
};
std::optional<CostLimit> costLimit(std::string_view cost, const RequestLimits& limits);
// Every parameter of `schema` (recursively: properties, items) that declares "x-cost", as a JSON pointer
// into a request with '*' for an array index ("/passes/reference/spp", "/media/*/generator/count"),
// paired with its kind.
std::vector<std::pair<std::string, std::string>> costParameters(const nlohmann::json& schema);

// The merged request schema (technique parameter schemas included under properties.passes).
const nlohmann::json& renderRequestSchema();

// One technique as its descriptor declares it (renderer/techniques/<name>/<name>.json, merged into
// the schema at build time; docs/API.md, "A technique declares itself"): params in schema form, and
// what the renderer's TechniqueInfo is made of (renderer/frame/Technique.h, describedTechnique).
struct TechniqueSchema {
  std::string name;
  std::string summary;      // one line (/v1/info's technique list)
  std::string description;  // the parameters' object's description (the docs, the schema)
  std::vector<std::string> outputs;  // the AOVs a request may ask of it
  nlohmann::json params;  // name -> {type, default, minimum?, maximum?, enum?, description}
  std::vector<std::string> inputs, optionalInputs, prepareOutputs, resources, lightPaths, requiredPaths;
  std::string beautyBlend = "add";  // add, over or transmit (docs/API.md, "A technique declares itself")
  bool addsToBeauty = false, onByDefault = false, claimsWhenNamed = false, exclusive = false;
  // `radiant bench`'s preset: {"axes": {param: {"full": [...], "quick": [...]}}, "request": {...},
  // "compare": {...}} (the descriptor's "bench", checked against the parameters at build time).
  nlohmann::json bench;
};
const std::vector<TechniqueSchema>& techniqueSchemas();
const TechniqueSchema* findTechnique(std::string_view name);
nlohmann::json to_json_value(const TechniqueSchema& t);

// Validates `value` against `schema` (the subset above) and returns it with defaults filled in.
// `pointer` is where `value` sits in the document. Throws ApiError.
nlohmann::json validate(const nlohmann::json& schema, const nlohmann::json& value, const std::string& pointer = "");

// A technique's parameters: `given` (an object, or null for none) validated against the technique's
// schema with every default filled in. This is what a technique receives, whether or not the request
// named it, so the schema is the only place a default is written. Throws ApiError for bad values and
// std::out_of_range for a technique the schema does not declare.
nlohmann::json techniqueParams(std::string_view technique, const nlohmann::json& given = nullptr);

// JSON text -> json. Throws ApiError 400 malformed-json (detail names the byte offset), 400
// invalid-utf8, 422 out-of-range (a number beyond a double) or 422 limit-exceeded (nested deeper
// than maxDepth), the last three with the pointer of the value (see api/JsonLimits.h).
nlohmann::json parseJson(std::string_view text, std::size_t maxDepth = 64);

// Validates against the request schema, applies `limits`, and converts. Throws ApiError.
RenderRequest parseRenderRequest(const nlohmann::json& body, const RequestLimits& limits = {});
RenderRequest parseRenderRequest(std::string_view text, const RequestLimits& limits = {});

// The validated request's JSON form with defaults filled (what parseRenderRequest converted).
nlohmann::json normaliseRenderRequest(const nlohmann::json& body, const RequestLimits& limits = {});

// RFC 6901: appends one reference token, escaping '~' and '/'.
std::string pointerAppend(const std::string& pointer, std::string_view token);
std::string pointerAppend(const std::string& pointer, std::size_t index);

const char* toString(ImageFormat f);  // "exr" | "png"

}  // namespace radiant::api
