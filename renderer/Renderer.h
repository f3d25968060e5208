#pragma once
#include <functional>
// The renderer library's one entry point. It owns the EGL context, so create it on the thread that
// will render, and call render() only from that thread. It knows nothing about HTTP.

#include <atomic>
#include <memory>
#include <vector>

#include "api/Types.h"
#include "renderer/Image.h"
#include "renderer/platform/EglDevice.h"
#include "renderer/scene/Scene.h"

namespace radiant {
class Technique;  // renderer/frame/Technique.h
namespace gl {
class ShaderLibrary;  // renderer/gl/ShaderLibrary.h
}
namespace api {
struct RequestLimits;  // api/Validate.h
}

struct RenderOutput {
  std::vector<Image> aovs;  // every AOV the request's outputs name (and "beauty" always)
  api::FrameStats stats;
  // With request.compare: the ground truth the compared AOV was scored against, with its channels
  // (the "reference" AOV may be the frame's own reference pass instead). A refining job scores the
  // batches' mean against it (server/Refinement.h). Empty without compare.
  Image compareReference;
};

// Images a request refers to by digest, resolved by the caller (the server's image store).
struct FrameInputs {
  const Image* compareTarget = nullptr;  // compare.against when it names an image
  const Image* environment = nullptr;    // request.environment
  // Progress of the frame in [0, 1]: passes done plus the running pass's own fraction (reference tiles,
  // light-tracer waves, photon tracing), in pass-count units, then 1 after readback. Never decreases.
  // May be called from the renderer's worker threads: keep it cheap and thread-safe (store an atomic).
  std::function<void(double)> progress{};
  // The server's caps (radiantd --max-samples, --max-photons, ...): quality presets and time budgets
  // choose only configurations within them (api::chooseConfiguration). Null = the schema's own bounds.
  const api::RequestLimits* limits = nullptr;
};

struct TechniqueDescription {
  std::string name, description;
  std::vector<std::string> outputs;  // AOVs it produces
  // Per output AOV, what scores it at the technique's default parameters (Technique::groundTruth): the
  // reference pass's parameters ({"aov": "ao", "ao_radius": 0.5, ...}; "max_bounces" when the
  // technique computes a fixed bounce range), or null when the reference renderer has none.
  // GET /v1/info serves it as techniques[].ground_truths; the client's bench presets read it.
  nlohmann::json groundTruths = nlohmann::json::object();
};

// The raster's samples per pixel axis for a frame of width x height that asks for `requested`
// (RenderRequest::supersampling, 1-4): 1 when the frame runs the reference pass, which integrates the
// pixel itself, and at most what keeps k^2 width height within 4096^2 pixels, the largest frame the
// limits allow at one sample, so that supersampling never raises a frame's memory above what a request
// may already ask for. stats.supersampling reports it.
int rasterSupersampling(int requested, int width, int height, bool runsReference);

// Finite output (docs/API.md, "Outputs"). Readback sets every NaN and Inf to 0; `zeroed` lists the
// AOVs that had any, with the passes of the frame that write each (a warning per AOV names them: such
// values are those passes' bug). Each half-float EXR output's values beyond +-65504, which
// io::encodeExr writes as +-65504, are counted per AOV in out.stats.clampedValues, with a warning.
struct ZeroedValues {
  std::string aov;
  std::size_t count = 0;
  std::vector<std::string> writers;  // the frame's passes that write the AOV (beauty: those adding to it)
};
void reportOutputRange(RenderOutput& out, const std::vector<ZeroedValues>& zeroed, const api::RenderRequest& request);

class Renderer {
public:
  explicit Renderer(const DeviceOptions& options = {});
  ~Renderer();
  const DeviceInfo& device() const;
  // The programs the frames rendered so far linked (gl::ShaderLibrary::programs): tests read their
  // sampler units in this renderer's context.
  const gl::ShaderLibrary& shaders() const;
  // Renders one frame. Throws api::ApiError for problems with the request that only show up here
  // (e.g. an unknown receiver node), and gl::GlError / EglError for environment failures; after
  // either the renderer stays usable. `cancel` is polled between passes.
  // With request.compare, stats.metrics holds the error of the compared AOV and the AOVs gain
  // "error" (per-pixel error map) and "reference". The ground truth is the reference path tracer, or
  // inputs.compareTarget when the request compares against an uploaded image (the server resolves
  // it). A request naming an image that `inputs` does not supply is refused (422).
  // A default supersampling (request.supersamplingGiven false) that the memory limit refuses (503
  // memory-busy: on llvmpipe the frame's targets are host memory) is lowered one step at a time, with a
  // warning, before the refusal reaches the caller.
  RenderOutput render(const Scene& scene, const api::RenderRequest& request,
                      const std::atomic<bool>* cancel = nullptr, const FrameInputs& inputs = {});
  static std::vector<TechniqueDescription> techniques();
  // Every 422 render() would raise for this request on this scene that needs no GL, raised now: the
  // planner's (an unknown AOV or pass, conflicting passes), an environment or compare image `inputs`
  // does not supply, the compare block's (an AOV without ground truth, an image of another size), the
  // camera's, and each planned technique's Technique::validate() with the request's view (an
  // unknown receiver, a network above its limits, an exact sky too costly for the frame's particles). Pure CPU and thread-safe: radiantd calls it on the
  // HTTP thread before it queues the job, so these are answers to the POST, not failed jobs.
  static void check(const Scene& scene, const api::RenderRequest& request, const FrameInputs& inputs);
  // How many scenes stay uploaded to the GPU, and how many input digests each kind of cached derived
  // data (BVH, photons, beams) keeps; least recently used evicted first. Maps held in shared frame
  // resources (shadow and cube maps) hold the last scene rendered (FrameResources::refill).
  // Default 4; radiantd --gpu-scenes.
  void setGpuSceneCapacity(std::size_t scenes);
  // Bytes the sized derived data (photon sets, splat grids) may hold together, least recently used
  // dropped first (FrameResources::setDerivedBytes). Default 1 TiB (unbounded); radiantd
  // --derived-cache-bytes.
  void setDerivedCacheBytes(std::size_t bytes);
  // The resident set the memory accountant keeps the process under (FrameResources::makeRoom): passes
  // about to allocate much, and every frame's end, release what the frame does not use when over it.
  // Default 1 TiB (off); radiantd --memory-target-bytes.
  void setMemoryTarget(std::size_t bytes);
  // The resident set beyond which a pass's large allocation is refused (503 memory-busy) when the
  // release does not make room for it; 0 = none (the default); radiantd --memory-limit-bytes.
  void setMemoryLimit(std::size_t bytes);
  // Called (on the render thread) when the memory accountant releases, to free what the renderer's
  // owner holds for it and may drop: radiantd's decoded scenes and images that no job holds.
  void setReleaseHook(std::function<void()> hook);
  // The budget chooser's speed factor (api::MachineSpeed): > 0 pins it (radiantd --speed-factor),
  // 0 measures it: a calibration frame before the first frame with a time budget, then the ratio of
  // measured to predicted time of recent frames comparable with the preset table. Default 0.
  void setSpeedFactor(double factor);
  // The techniques, in the order that breaks the frame graph's ties (default createTechniques(),
  // renderer/techniques/Registry.cpp). Tests reorder them: declarations alone order a frame.
  void setTechniques(std::vector<std::unique_ptr<Technique>> techniques);

private:
  RenderOutput renderFrame(const Scene& scene, const api::RenderRequest& request, const std::atomic<bool>* cancel,
                           const FrameInputs& inputs);
  void calibrateSpeed();
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace radiant
