#pragma once
// The one table of AOVs (arbitrary output variables): every image a frame can return, with how it
// is stored on the GPU, read back, named in an EXR file, written by the passes, and scored. Assembled
// from the frame's own rows (beauty, alpha, error) and the rows each technique's descriptor declares
// (renderer/techniques/<name>/<name>.json, "aovs", merged into the schema at build time).
// ARCHITECTURE.md, "Declared AOVs and resources" (Falcor RenderPassReflection, Mitsuba aov_names).
//
// Readers: the FramePlanner (what is requestable and who produces it), Renderer readback (resource,
// channels), the EXR writer (channel names), compare() (ground truth), and the server through the
// schema (api/schema: the request's aovs enum is beauty plus every technique's outputs).
// tests/gl/render/schema_consistency_test.cpp checks the table against the schema and the registry
// in both directions.
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

namespace radiant::api {

enum class AovFormat { Rgba32F, Rgba16F, R32F };  // the GPU format of the resource it is read from

// Overwrite: exactly one technique writes it per frame (AovInfo::producer, or for the media AOVs the
// media technique that owns the frame's "media" light-path class). Accumulate: every pass with addsToBeauty adds its
// light into it (beauty); it exists in every frame even when nothing drew.
enum class AovBlend { Overwrite, Accumulate };

// How a supersampled frame (RenderRequest::supersampling = k) resolves the k x k samples of a pixel:
// Average, the box filter, for what is linear in radiance or reflectance (the pixel integral the
// reference estimates); Nearest, the sample nearest the pixel centre, for geometry, whose average
// across a silhouette names no surface (a depth between the two, a normal of neither).
enum class AovResolve { Average, Nearest };

struct AovInfo {
  int id;                        // index in aovTable()
  std::string name;              // as in requests ("beauty", "depth")
  AovFormat format;              // of `resource`
  std::string resource;          // frame resource read back ("gbuffer_position" for depth)
  int firstChannel;              // first channel of `resource` read
  int channels;                  // channels of the image (1 or 3)
  std::vector<std::string> exr;  // EXR channel names, one per channel
  AovBlend blend;
  std::string producer;          // Overwrite: the technique that writes it by default ("compare" for error)
  bool requestable;              // may appear in outputs[].aovs (error and the compare reference may not)
  // What compare() scores it against when compare.against is "reference": a reference-pass mode
  // (beauty, direct, indirect, ao), or "" when the AOV has no ground truth the reference can render
  // (then compare.aov naming it is a 422, instead of silently scoring against beauty).
  std::string groundTruth;
  AovResolve resolve = AovResolve::Average;
  // Radiance: a PNG shows it through the request's view transform (tone_map, renderer/io/ToneMap.h).
  // false for data (reflectance, geometry, occlusion, transmittance, error), which a PNG shows as stored.
  bool radiance = true;
  std::string description{};  // one sentence, served by /v1/info
};

const std::vector<AovInfo>& aovTable();
// nullptr when no AOV has that name.
const AovInfo* findAov(std::string_view name);

const char* toString(AovFormat f);  // "RGBA32F" | "RGBA16F" | "R32F"
const char* toString(AovBlend b);   // "overwrite" | "accumulate"
const char* toString(AovResolve r); // "average" | "nearest"

// The table as GET /v1/info serves it: [{"name", "format", "channels": [EXR names], "blend",
// "producer", "requestable", "ground_truth", "description"}].
nlohmann::json aovTableJson();

}  // namespace radiant::api
