#pragma once
// The vocabulary shared by server, client and renderer. The JSON forms of these types are defined by
// the schema in api/schema/ (the single source of truth); api/Validate.h turns JSON into these types.

#include <cstdint>
#include <map>
#include <set>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "api/Media.h"

namespace radiant::api {

// A user-input error. Maps to a 4xx application/problem+json response whose "pointer" is a JSON
// pointer (RFC 6901) to the offending field of the request ("/passes/ambient_occlusion/samples").
struct ApiError : std::runtime_error {
  int status;           // 400, 404, 413, 415, 422, 503 ...
  std::string type;     // short slug, becomes "https://radiant.dev/problems/<type>"
  std::string title;    // short human summary
  std::string pointer;  // JSON pointer into the request body ("" when not about a field)
  ApiError(int status, std::string type, std::string title, std::string detail, std::string pointer = "")
      : std::runtime_error(std::move(detail)), status(status), type(std::move(type)),
        title(std::move(title)), pointer(std::move(pointer)) {}
  std::string detail() const { return what(); }
};

struct SceneRef {
  enum class Kind { Digest, Builtin, Inline, Asset };
  Kind kind = Kind::Builtin;
  std::string value;  // "sha256:..." | builtin name | base64 GLB (decoded by the server) | path under --asset-root
};

// A request's camera. Fields the request did not set (has* false) keep the scene's camera: the file's
// first camera, or the automatic framing of the scene bounds (renderer/frame/FrameView.cpp).
struct CameraOverride {
  glm::vec3 position{0.f, 1.f, 3.f};
  glm::vec3 target{0.f, 1.f, 0.f};
  glm::vec3 up{0.f, 1.f, 0.f};
  float yfovDegrees = 40.f;
  bool hasPosition = true, hasTarget = true, hasUp = true, hasYfov = true;
  // camera.orbit (instead of position): the eye at target + radius (sin phi sin theta, cos phi,
  // sin phi cos theta), model-viewer's camera-orbit convention; radius 0 = the scene camera's distance.
  struct Orbit {
    double thetaDeg = 0, phiDeg = 90, radius = 0;
  };
  std::optional<Orbit> orbit{};
};

enum class ImageFormat { Exr, Png };

// The view transform of PNG output (render_request.json "tone_map"): scene-linear radiance times
// 2^exposure to display-linear [0, 1], before the sRGB transfer (renderer/io/ToneMap.h). Standard is
// the clamp; Aces is three.js's ACESFilmicToneMapping (model-viewer's fidelity goldens), KhronosPbrNeutral
// the Khronos PBR Neutral tone mapper (2024), Agx three.js's AgXToneMapping (Blender's default look).
enum class ToneMap { Standard, Aces, KhronosPbrNeutral, Agx };
const char* toString(ToneMap t);  // the schema's names: "standard", "aces", "khronos_pbr_neutral", "agx"
std::optional<ToneMap> toneMapFromString(std::string_view name);

// What the camera sees where no surface is (render_request.json "background"): the environment (the
// sky that lights the scene: map, ambient or studio), nothing (an alpha channel of coverage), or a
// linear colour. Only camera rays: the environment still lights the scene. Applied after compare, so
// stats.metrics score the frame as the reference renders it (docs/API.md, "Background").
struct Background {
  enum class Kind { Environment, Transparent, Colour };
  Kind kind = Kind::Environment;
  glm::vec3 colour{0.f};  // Kind::Colour: linear RGB radiance
};

struct OutputSpec {
  ImageFormat format = ImageFormat::Png;
  std::vector<std::string> aovs{"beauty"};  // EXR: all listed become channel groups; PNG: exactly one
  bool halfFloat = true;                    // EXR pixel type
  int pngCompression = 1;                   // PNG zlib level 0..9
  // PNG: the request's tone_map (parseRenderRequest copies it into every output, so that an encoder
  // needs the spec and the exposure only). The C++ default is the schema's.
  ToneMap toneMap = ToneMap::Aces;
};

struct CompareSpec {
  std::string against = "reference";  // "reference" or "sha256:..." of an uploaded EXR
  std::string aov = "beauty";         // beauty | direct | indirect | ao | ...
  int spp = 256;                      // reference samples per pixel
  int maxBounces = 1024;
};

// Progressive refinement of an async job (render_request.json "refine"): independent batches, averaged.
struct RefineSpec {
  double untilMs = 0;      // 0 = no time limit
  double targetRmse = 0;   // 0 = no target
  int maxBatches = 64;
  std::string aov = "beauty";  // whose error is estimated
  // Not in the schema: a session's next generation starts with the seed of the batch its previous one
  // rendered last (that photon set's splats are on the GPU); the later batches are seed, seed + 1, ...
  // without it (server/Sessions.h).
  std::optional<std::uint64_t> firstSeed{};
};

struct RenderRequest {
  std::string id;  // assigned by the server
  SceneRef scene;
  std::optional<CameraOverride> camera;
  int width = 256, height = 256;
  // Technique name -> its parameters, complete with defaults filled in from the schema.
  std::map<std::string, nlohmann::json> passes;
  // Techniques the request turned off ("passes": {"specular": false}); the planner skips them.
  std::set<std::string> disabledPasses;
  // The request gave a "passes" object of its own (named, turned on or off, or parameterised a pass):
  // it runs as asked, never lowered to the server's default frame budget (api/Presets.h).
  bool passesNamed = false;
  std::vector<OutputSpec> outputs{OutputSpec{}};
  float exposure = 0.f;  // EV; PNG = sRGB(toneMap(L * 2^exposure))
  ToneMap toneMap = ToneMap::Aces;  // the view transform of PNG output (also in each OutputSpec)
  Background background;            // what camera rays that hit nothing see
  std::uint64_t seed = 0;
  glm::vec3 ambient{0.f};  // uniform sky radiance L^a (W/sr/m^2), used by ambient passes
  std::string environment;  // digest of an uploaded equirect map ("" none); replaces ambient
  // A scene with no punctual lights (whatever its emission), or with directional lights only, rendered
  // without ambient or environment, is lit by the default studio environment as well
  // (renderer/scene/StudioEnvironment.h; docs/API.md, "Default lighting"); false keeps only the scene's
  // own light (black without lights or emission).
  bool defaultLighting = true;
  // Samples per pixel axis of the raster passes (the schema's "supersampling"): they run at (k width) x
  // (k height) and readback resolves each AOV to width x height (api::AovResolve). An HTTP request
  // without the field gets defaultSupersampling(width, height) from parseRenderRequest; a RenderRequest
  // built in C++ (the renderer's tests and benches) keeps 1, the single sample its expected values assume.
  int supersampling = 1;
  bool supersamplingGiven = false;  // the request chose it (the default frame budget may lower a default one)
  std::optional<CompareSpec> compare;
  bool async = false;
  // A quality preset ("" none, draft, preview, final, reference) or a frame time budget (0 none), both
  // resolved against the preset table (api/presets.json) by api/Presets.h, chooseConfiguration.
  std::string quality;
  double timeBudgetMs = 0;
  // Technique -> the parameter names the request gave itself (they win over quality and budget).
  std::map<std::string, std::set<std::string>> explicitParams;
  std::optional<RefineSpec> refine;
  // Particle systems added to the scene's own for this frame (api/Media.h), generators expanded.
  std::vector<ParticleSystem> media;
};

// The raster's samples per pixel axis when a request does not choose: at least 2, and enough that the
// raster takes about 512 x 512 samples in all, up to 4 (128 x 128 px: 4; 200 x 200: 3; 256 x 256 and
// larger: 2). A small frame's pixels each cover much of the scene: sub-pixel sun glints on normal-mapped
// metal and whole environments reflected in a few pixels of a mirror sphere alias at 2 x 2 samples
// (docs/PERFORMANCE.md, render fidelity), while its cost is mostly per frame, not per pixel.
int defaultSupersampling(int width, int height);

// The output pixels per side of photon_gi's gather block on a frame of width x height output pixels (at
// supersampling k the block is k times that in raster samples): `requested` (gather_step) when the request
// gives it, else one output pixel in 64 of the frame's size (its geometric mean), at least 2 and at most
// 4: 2 below 160 px (the preset table's sweeps, 32-128 px), 3 from 160, 4 from 224 px, at every k
// (docs/TECHNIQUES.md, photon_gi, gather_step). The pass runs it and the cost model charges it
// (api::SceneCounts::photonGatherBlock).
int photonGatherStep(int requested, bool given, int width, int height);

// Timing and counters for one pass that ran.
struct PassStats {
  std::string name;
  double gpuMs = 0.0;
  double cpuMs = 0.0;
  std::map<std::string, double> counters;  // beams, photons, samples, ...
  // What the pass chose differently from what the request implies (the Renderer moves each into
  // stats.warnings, prefixed with the pass's name).
  std::vector<std::string> warnings;
  // Wall time of its prepare(): allocation, cache lookups and the derived data built on a miss (BVHs,
  // photons, beams, the shadow maps' overdraw estimate), timed by the Renderer around the call, so a
  // pass cannot leave a build out. GPU work prepare() issues (uploads) is counted as issued.
  double prepareMs = 0.0;
};

struct CacheEvent {
  std::string what;  // "shadow_map:light0", "bvh", "cube_maps"...
  bool hit = false;
};

// Values an output's pixel type cannot hold, written as its largest finite value instead of Inf (a
// half-float EXR: |v| > 65504). Serialised as stats.clamped_values.
struct ClampedValues {
  std::size_t output = 0;  // index in request.outputs
  std::string aov;
  std::size_t count = 0;   // values (pixels x channels) clamped
  double limit = 0;        // the largest finite value of the output's type
};

struct FrameStats {
  std::vector<PassStats> passes;
  // How passes[].gpu_ms was measured: "timer_query" (GL_TIME_ELAPSED per pass, hardware devices) or
  // "finish_bracketed" (wall time between glFinish before and after the pass, software devices).
  std::string passTiming;
  std::map<std::string, std::string> skipped;  // pass name -> reason
  std::map<std::string, std::string> lightPaths;  // light-path class -> technique that supplies it
  std::vector<CacheEvent> cache;
  double sceneLoadMs = 0, uploadMs = 0, renderMs = 0, readbackMs = 0, encodeMs = 0;
  std::size_t triangles = 0;
  int lights = 0;
  std::map<std::string, std::string> device;  // vendor, renderer, version, device, reason
  nlohmann::json metrics;  // error metrics when a compare block was given (null otherwise)
  // What lit the frame: "scene" (its lights or emission) and the sky, "ambient", "environment" or
  // "default" (the studio environment, see RenderRequest::defaultLighting), joined by '+' when both
  // ("scene+default", "scene+environment"); "none" when nothing did.
  std::string lighting;
  // Why (docs/API.md, "Default lighting"): which rule chose `lighting`, in a sentence.
  std::string lightingReason;
  int supersampling = 1;  // the raster's samples per pixel axis this frame used (RenderRequest::supersampling, capped)
  nlohmann::json camera;  // the camera used: position, target, up, yfov_deg, source
  nlohmann::json scene;   // name, digest, bounds {min, max}, node names
  std::vector<std::string> warnings;  // things the scene has that this frame could not honour
  std::vector<ClampedValues> clampedValues;  // empty when every output holds every value
  // With quality or time_budget_ms: what the preset table chose per technique, predicted and measured
  // ms, predicted error (api/Presets.h, chooseConfiguration); null otherwise. With refine: also "refinement".
  nlohmann::json budget;
  nlohmann::json refinement;
  // The memory accountant after the frame (FrameResources::makeRoom): resident_bytes, resource_bytes
  // (textures and buffers), derived_bytes (sized derived data), target_bytes, released_bytes (what
  // this frame's passes and its end released to stay under the target).
  nlohmann::json memory;
};

void to_json(nlohmann::json& j, const PassStats& s);
void to_json(nlohmann::json& j, const FrameStats& s);

}  // namespace radiant::api
