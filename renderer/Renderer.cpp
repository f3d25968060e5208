#include "renderer/Renderer.h"

#include <algorithm>
#include <mutex>
#include <chrono>
#include <cmath>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>

#include "api/Aovs.h"
#include "api/Lru.h"
#include "api/Presets.h"
#include "api/Validate.h"
#include "renderer/frame/FrameAllocation.h"
#include "renderer/frame/FrameLighting.h"
#include "renderer/frame/FramePlanner.h"
#include "renderer/frame/FrameResources.h"
#include "renderer/frame/FrameView.h"
#include "renderer/frame/GpuProfiler.h"
#include "renderer/frame/GpuScene.h"
#include "renderer/frame/PassContext.h"
#include "renderer/gl/ShaderLibrary.h"
#include "renderer/io/ImageIO.h"
#include "renderer/metrics/Metrics.h"
#include "renderer/scene/BuiltinScenes.h"
#include "renderer/shading/DirectLighting.h"
#include "renderer/shading/EnvironmentLights.h"
#include "renderer/techniques/reference/ReferencePass.h"
#include "renderer/techniques/specular/Specular.h"
#include "renderer/techniques/Registry.h"
#include "renderer/shading/GBufferInputs.h"

namespace radiant {
namespace {

// The split's options from `direct`'s parameters (renderer/techniques/direct/direct.json): they decide
// what `direct` lights with, and photon_gi and image-based lighting follow.
EnvironmentLightOptions environmentLightOptions(const api::RenderRequest& request) {
  EnvironmentLightOptions o;
  o.skyLights = 16;  // direct.json's default
  const auto it = request.passes.find("direct");
  if (it != request.passes.end() && it->second.is_object()) {
    o.maxLights = it->second.value("environment_lights", o.maxLights);
    o.threshold = it->second.value("environment_light_threshold", o.threshold);
    o.skyLights = it->second.value("sky_lights", o.skyLights);
  }
  return o;
}

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

// How an AOV is read back: which resource, which channels (the AOV table, api/Aovs.cpp).
struct AovSource {
  std::string texture;
  int firstChannel, channels;
};
AovSource aovSource(const std::string& aov) {
  const api::AovInfo* a = api::findAov(aov);
  if (!a) throw std::logic_error("Renderer: AOV '" + aov + "' is not in the AOV table (api/Aovs.cpp)");
  return {a->resource, a->firstChannel, a->channels};
}

// Resolves a read-back RGBA frame of (k out.width) x (k out.height), GL rows (bottom first), into `out`
// (top row first): the box average of each pixel's k x k samples for radiance and reflectance, the
// sample nearest the pixel centre for geometry (api::AovResolve). k = 1 copies.
void resolveSupersampled(const std::vector<float>& rgba, int width, int height, int k, const AovSource& src, Image& out) {
  const bool average = api::findAov(out.aov)->resolve == api::AovResolve::Average;
  const int j0 = average ? 0 : k / 2, j1 = average ? k : k / 2 + 1;
  const float weight = 1.f / static_cast<float>((j1 - j0) * (j1 - j0));
  for (int y = 0; y < out.height; ++y)
    for (int x = 0; x < out.width; ++x) {
      float* p = out.at(x, y);
      for (int c = 0; c < src.channels; ++c) p[c] = 0.f;
      for (int sy = j0; sy < j1; ++sy) {
        const float* row = &rgba[static_cast<std::size_t>(height - 1 - (y * k + sy)) * width * 4];
        for (int sx = j0; sx < j1; ++sx)
          for (int c = 0; c < src.channels; ++c) p[c] += weight * row[(x * k + sx) * 4 + src.firstChannel + c];
      }
    }
}

// resolveSupersampled on the GPU (shaders/common/supersample_resolve.comp): the k x k samples are
// resolved into an output-sized RGBA32F texture and only that is read back, k^2 times fewer bytes and
// no per-sample loop on the CPU (at 1920x1080, k = 2 on an H200 the readback of the full frame and its
// CPU resolve took 198-314 ms, the passes 70-120 ms; docs/PERFORMANCE.md, "GPU check"). False (nothing
// done) for a texture that texelFetch of a float sampler cannot read: integer formats.
bool resolveSupersampledOnGpu(FrameResources& resources, gl::ShaderLibrary& shaders, const gl::Texture& samples,
                              int k, const AovSource& src, Image& out) {
  switch (samples.format()) {
    case GL_RGBA16F: case GL_RGBA32F: case GL_RGB16F: case GL_RGB32F: case GL_RG16F: case GL_RG32F:
    case GL_R16F: case GL_R32F: case GL_RGBA8: case GL_R11F_G11F_B10F: break;
    default: return false;
  }
  const bool average = api::findAov(out.aov)->resolve == api::AovResolve::Average;
  gl::Texture& resolved = resources.texture("supersample_resolve", GL_TEXTURE_2D, GL_RGBA32F, out.width, out.height);
  const gl::Program& prog = shaders.program({"common/supersample_resolve.comp"});
  prog.use();
  const int outSize[2] = {out.width, out.height};
  const int first[2] = {average ? 0 : k / 2, average ? 0 : k - 1 - k / 2};
  glUniform2iv(glGetUniformLocation(prog.id(), "u_outSize"), 1, outSize);
  glUniform2iv(glGetUniformLocation(prog.id(), "u_first"), 1, first);
  prog.set("u_k", k);
  prog.set("u_count", average ? k : 1);
  // A sampler object with a non-mipmapped filter, so the samples' texture is complete for texelFetch
  // whatever its own filter state.
  GLuint sampler = 0;
  glCreateSamplers(1, &sampler);
  glSamplerParameteri(sampler, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glSamplerParameteri(sampler, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  samples.bindUnit(0);
  glBindSampler(0, sampler);
  resolved.bindImage(0, GL_WRITE_ONLY);
  glDispatchCompute(static_cast<GLuint>((out.width + 7) / 8), static_cast<GLuint>((out.height + 7) / 8), 1);
  glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT);
  glBindSampler(0, 0);
  glDeleteSamplers(1, &sampler);
  std::vector<float> rgba(static_cast<std::size_t>(out.width) * out.height * 4);
  resolved.download(0, GL_RGBA, GL_FLOAT, rgba.data(), rgba.size() * sizeof(float));
  for (int y = 0; y < out.height; ++y) {
    const float* row = &rgba[static_cast<std::size_t>(out.height - 1 - y) * out.width * 4];
    for (int x = 0; x < out.width; ++x)
      for (int c = 0; c < src.channels; ++c) out.at(x, y)[c] = row[x * 4 + src.firstChannel + c];
  }
  return true;
}

// The beauty as the camera sees it against the request's background (api::Background): each sample
// that hit no surface (the G-buffer's position w is 0 there: the sky, an alpha-masked cut-out) shows the
// background colour, or 0 when it is transparent, instead of the sky; then the k x k samples are resolved
// like the beauty, so an edge pixel mixes object and background by the fraction of its samples that hit,
// and a transparent frame's coverage is that fraction (the premultiplied alpha of `beautySamples`).
// `beautySamples`: the read-back beauty (GL rows, RGBA), or null when nothing drew into it (no geometry).
void presentBackground(FrameResources& resources, const FrameView& view, int k, const api::Background& background,
                       std::vector<float>* beautySamples, std::optional<Image>& presented, std::optional<Image>& alpha) {
  const bool transparent = background.kind == api::Background::Kind::Transparent;
  const glm::vec3 shown = transparent ? glm::vec3(0.f) : background.colour;
  const std::size_t samples = static_cast<std::size_t>(view.width) * view.height;
  // Coverage per sample in channel 3 (where the AOV table reads depth from), 1 or 0.
  std::vector<float> position(samples * 4, 0.f);
  if (gbuffer::written(resources, gbuffer::Attachment::Position))
    gbuffer::texture(resources, gbuffer::Attachment::Position).download(0, GL_RGBA, GL_FLOAT, position.data(), position.size() * sizeof(float));
  for (std::size_t i = 0; i < samples; ++i) position[i * 4 + 3] = position[i * 4 + 3] > 0.f ? 1.f : 0.f;
  std::vector<float> beauty = beautySamples ? *beautySamples : std::vector<float>(samples * 4, 0.f);
  for (std::size_t i = 0; i < samples; ++i)
    if (position[i * 4 + 3] == 0.f)
      for (int c = 0; c < 3; ++c) beauty[i * 4 + c] = shown[c];
  const int w = view.width / k, h = view.height / k;
  presented = Image::make("beauty", w, h, 3);
  resolveSupersampled(beauty, view.width, view.height, k, aovSource("beauty"), *presented);
  if (transparent) {
    alpha = Image::make("alpha", w, h, 1);
    resolveSupersampled(position, view.width, view.height, k, AovSource{"", 3, 1}, *alpha);
  }
}

// Replaces NaN and Inf by 0 and counts them: output is never NaN or Inf, and the stats say if a pass
// produced any (which is a bug to fix, not to hide).
std::size_t sanitize(std::vector<float>& v) {
  std::size_t bad = 0;
  for (float& x : v)
    if (!std::isfinite(x)) { x = 0.f; ++bad; }
  return bad;
}

// The passes of the frame that write `aov`: its declared writers, or for beauty those that add to it.
std::vector<std::string> writersOf(const std::string& aov, const std::vector<Technique*>& passes) {
  std::vector<std::string> names;
  for (const Technique* t : passes) {
    const TechniqueInfo& info = t->info();
    if (aov == "beauty" ? info.addsToBeauty : std::count(info.outputs.begin(), info.outputs.end(), aov) > 0)
      names.push_back(info.name);
  }
  return names;
}

// The seed of every ground truth compare() renders (see there).
constexpr std::uint64_t kGroundTruthSeed = 0x6A09E667F3BCC909ull;

// A technique's parameters as the request gives them (api::techniqueParams: defaults filled in), with
// the keys it set itself (Params::given).
Params requestParams(const std::string& technique, const api::RenderRequest& request) {
  const auto given = request.passes.find(technique);
  const auto named = request.explicitParams.find(technique);
  return Params(api::techniqueParams(technique, given != request.passes.end() && given->second.is_object()
                                                    ? given->second
                                                    : nlohmann::json(nullptr)),
                named == request.explicitParams.end() ? std::set<std::string>{} : named->second);
}

// The compare block's 422s, found before the frame (Renderer::check, renderFrame): an image named but
// not supplied, an uploaded image of another size than the frame, an AOV the reference renderer has no
// ground truth for. Returns the ground truth compare() renders: the AOV's as its producer in this frame
// declares it (Technique::groundTruth with the request's parameters of that technique; the media AOVs
// have several producers, one per frame), or the AOV table's producer when it does not run (its AOV is
// then read back empty and scored as such); none when the request compares against an uploaded image.
GroundTruth checkedCompare(const api::RenderRequest& request, const Image* target, const std::vector<Technique*>& all,
                           const FramePlan& plan) {
  const api::CompareSpec& c = *request.compare;
  const api::AovInfo* info = api::findAov(c.aov);
  const Technique* producer = nullptr;
  for (const Technique* p : plan.passes)
    if (std::count(p->info().outputs.begin(), p->info().outputs.end(), c.aov)) producer = p;
  for (const Technique* t : all)
    if (!producer && info && t->info().name == info->producer) producer = t;
  if (c.against != "reference") {
    if (!target)
      throw api::ApiError(422, "invalid-compare", "Nothing to compare against",
                          "compare.against names an image (" + c.against + ") that was not supplied", "/compare/against");
    if (target->width != request.width || target->height != request.height)
      throw api::ApiError(422, "invalid-compare", "Size mismatch",
                          "the comparison image is " + std::to_string(target->width) + "x" +
                              std::to_string(target->height) + ", the frame " + std::to_string(request.width) + "x" +
                              std::to_string(request.height),
                          "/compare/against");
    return {};
  }
  // A reference mode and its parameters, or none, which is an error rather than a score against
  // something else (the specular AOV used to be scored against full beauty).
  GroundTruth truth;
  if (info && !info->producer.empty()) {
    if (producer) truth = producer->groundTruth(requestParams(producer->info().name, request), c.aov);
  } else if (info) {
    truth = GroundTruth::fromAovTable(c.aov);  // beauty: the sum of every pass
  }
  if (!truth.exists()) {
    std::string have;
    for (const api::AovInfo& a : api::aovTable())
      if (!a.groundTruth.empty()) have += (have.empty() ? "" : ", ") + a.name;
    throw api::ApiError(422, "invalid-compare", "No ground truth",
                        "the reference renderer has no ground truth for the AOV '" + c.aov +
                            "' (AOVs with one: " + have + "); compare it against an uploaded image instead",
                        "/compare/aov");
  }
  return truth;
}

// Scores the compared AOV against `truth` (checkedCompare) or the uploaded `target`; adds stats.metrics
// and the "error" and "reference" AOVs.
void compare(FrameResources& resources, const Scene& scene, const FrameView& view, const api::RenderRequest& request,
             const Image* target, const GroundTruth& truth, RenderOutput& out) {
  const api::CompareSpec& c = *request.compare;
  auto test = std::find_if(out.aovs.begin(), out.aovs.end(), [&](const Image& i) { return i.aov == c.aov; });
  if (test == out.aovs.end())
    throw api::ApiError(422, "invalid-compare", "Nothing to compare", "the frame has no AOV '" + c.aov + "'",
                        "/compare/aov");
  nlohmann::json m = {{"against", c.against}, {"aov", c.aov}, {"rel_mse_epsilon", metrics::kRelMseEpsilon}};
  Image reference;
  if (target) {
    reference = *target;
  } else {
    ReferenceRequest r = referenceRequestFrom(Params(api::techniqueParams("reference", truth.reference)));
    m["reference_mode"] = r.aov;
    // The mode's own parameters (ao: radius and definition) go into the metrics as the technique gave them.
    for (const auto& [key, value] : truth.reference.items())
      if (key != "aov") m[key] = value;
    r.spp = c.spp;
    // A technique that computes a fixed bounce range declares it (env_diffuse: bounces + 1); otherwise
    // the compare block's path length limit applies.
    r.maxBounces = truth.reference.contains("max_bounces") ? r.maxBounces : c.maxBounces;
    ReferenceRun run;
    const auto t0 = Clock::now();
    // The ground truth draws its own random numbers. With the frame's seed, sample s of pixel p would
    // be the same path in the truth as in a `reference` pass of the frame (rt::Sampler hashes
    // (pixel, sample, seed)), so a reference scored against itself would share its first spp samples
    // with the truth and report too small an error (zero at equal spp: the cache returned the frame's
    // own image). One fixed seed, far from the small seeds requests use, is independent of the frame's
    // and of refinement's batches (seed, seed + 1, ...), and every seed of a sweep or a refinement is
    // scored against the same, cached, truth.
    FrameView truthView = view;
    truthView.seed = kGroundTruthSeed;
    reference = referenceImage(resources, scene, truthView, r, &run);
    if (!view.media.empty() && r.aov != "media" && r.aov != "media_transmittance")
      out.stats.warnings.push_back("the reference path tracer renders no participating media: compare.aov " + c.aov +
                                   " is scored without the frame's particle systems (compare.aov media scores them)");
    m["spp"] = c.spp;
    m["max_bounces"] = r.maxBounces;
    m["reference_cached"] = run.cacheHit;
    // Paths of the truth that the bounce cap ended (0 when cached or at the default cap in practice).
    m["reference_paths_capped"] = run.pathsCapped;
    m["reference_ms"] = msSince(t0);
    if (r.aov == "media" || r.aov == "media_transmittance") m["media_mode"] = r.mediaMode;
  }
  // Compare colour with colour and scalar with scalar.
  if (reference.channels != test->channels) {
    Image r = Image::make(reference.aov, reference.width, reference.height, test->channels);
    for (std::size_t p = 0; p < static_cast<std::size_t>(r.width) * r.height; ++p)
      for (int ch = 0; ch < r.channels; ++ch)
        r.pixels[p * r.channels + ch] = reference.pixels[p * reference.channels + std::min(ch, reference.channels - 1)];
    reference = std::move(r);
  }
  const metrics::ImageMetrics e = metrics::compareImages(*test, reference, request.exposure);
  metrics::writeMetricsJson(e, m);
  out.stats.metrics = m;
  out.compareReference = reference;
  Image err = metrics::errorMap(*test, reference);
  err.aov = "error";
  out.aovs.push_back(std::move(err));
  reference.aov = "reference";
  if (std::none_of(out.aovs.begin(), out.aovs.end(), [](const Image& i) { return i.aov == "reference"; }))
    out.aovs.push_back(std::move(reference));
}

}  // namespace

// A beauty whose brightest pixel is below 1e-6 (of any colour): no light reached the camera. Names the
// likely cause so that a user does not mistake it for a finished render.
std::string blackFrameWarning(const RenderOutput& out, const api::FrameStats& stats, const Scene& scene,
                              const api::RenderRequest& request) {
  auto it = std::find_if(out.aovs.begin(), out.aovs.end(), [](const Image& i) { return i.aov == "beauty"; });
  if (it == out.aovs.end()) return "";
  float brightest = 0.f;
  for (float v : it->pixels) brightest = std::max(brightest, v);
  if (brightest >= 1e-6f) return "";
  std::string cause;
  if (stats.lighting == "none")
    cause = "the scene has no lights or emissive surfaces, and the request names no ambient or environment "
            "(and turned the default lighting off)";
  else if (scene.meshes.empty())
    cause = "the scene has no geometry and the sky is black";
  else if (!stats.skipped.empty()) {
    cause = "passes were skipped:";
    for (const auto& [name, why] : stats.skipped) cause += " " + name + " (" + why + ")";
  } else {
    cause = "no light reaches the camera (every light is occluded, outside the view, or of zero intensity)";
  }
  return "black frame: the beauty's brightest pixel is below 1e-6; " + cause;
}

// Whether a frame's time says how fast this machine runs the preset table's frames (api::MachineSpeed).
// The table's costs are those of a first render with its own seed on a warm daemon (bench/presets.py):
// shaders compiled, the scene uploaded, its scene-keyed maps (shadow maps, the image-based lighting's
// tables) reused, the seed-keyed and knob-keyed derived data (photons, splats, networks, beams,
// caustic cubes, specular maps, reference images) built. A frame that compiled a program, uploaded its
// scene or reused any other derived data is faster or slower than the table for reasons that are not the
// machine's.
static bool comparableWithPresetTable(const api::FrameStats& stats, bool compiledPrograms) {
  if (compiledPrograms) return false;
  // Derived data keyed on the scene and its environment only (never on the seed or a quality knob):
  // the preset table's timing frames found these warm as well. Any other hit is reused work.
  static const std::set<std::string> kSceneKeyed{"ray_scene", "shadow_maps", "ibl_dfg", "ibl_prefiltered", "ibl_sh",
                                                 "environment_distribution"};
  bool sceneResident = false;
  for (const api::CacheEvent& e : stats.cache) {
    if (e.what == "gpu_scene") sceneResident = e.hit;
    else if (e.hit && !kSceneKeyed.count(e.what)) return false;
  }
  return sceneResident;
}

void reportOutputRange(RenderOutput& out, const std::vector<ZeroedValues>& zeroed, const api::RenderRequest& request) {
  api::FrameStats& stats = out.stats;
  for (const ZeroedValues& z : zeroed) {
    if (z.count == 0) continue;
    std::string writers;
    for (const std::string& w : z.writers) writers += (writers.empty() ? "" : ", ") + w;
    stats.warnings.push_back(z.aov + ": " + std::to_string(z.count) + " NaN or infinite values were written as 0; " +
                             (writers.empty() ? std::string("no pass of this frame writes it")
                                              : "passes that wrote it: " + writers));
  }
  for (std::size_t o = 0; o < request.outputs.size(); ++o) {
    const api::OutputSpec& spec = request.outputs[o];
    if (spec.format != api::ImageFormat::Exr || !spec.halfFloat) continue;
    for (const std::string& aov : spec.aovs) {
      const auto img = std::find_if(out.aovs.begin(), out.aovs.end(), [&](const Image& i) { return i.aov == aov; });
      const std::size_t n = img == out.aovs.end() ? 0 : io::valuesBeyondHalf(*img);
      if (n == 0) continue;
      stats.clampedValues.push_back({o, aov, n, double(io::kHalfMax)});
      stats.warnings.push_back("output " + std::to_string(o) + " (half-float EXR): " + std::to_string(n) + " values of " +
                               aov + " beyond +-65504 were written as +-65504 (\"half\": false keeps them)");
    }
  }
}

int rasterSupersampling(int requested, int width, int height, bool runsReference) {
  if (runsReference) return 1;
  constexpr double kMaxPixels = 4096.0 * 4096.0;
  int k = std::clamp(requested, 1, 4);
  while (k > 1 && double(k) * k * width * height > kMaxPixels) --k;
  return k;
}

// renderFrame's stages (below, after checkedPlan): what the frame decided before any GL work, and what
// its readback produced.
struct FrameConfig;
struct FrameReadback;
struct FrameProgress;

struct Renderer::Impl {
  std::unique_ptr<EglDevice> device;
  gl::ShaderLibrary shaders;
  FrameResources resources{shaders};
  GpuProfiler profiler;
  std::vector<std::unique_ptr<Technique>> techniques = createTechniques();
  // GPU copies of recently used scenes, keyed by digest (or address when unnamed).
  api::Lru<std::string, std::unique_ptr<GpuScene>> gpuScenes;
  std::size_t gpuSceneCapacity = 4;
  // The budget chooser's speed factor, and the last frame's times for the calibration (observeSpeed).
  api::MachineSpeed speed;
  bool calibrating = false;
  struct FrameTimes {
    double measuredMs = 0, predictedMs = -1;
  } lastFrame;
  std::unique_ptr<Scene> calibrationScene;

  // The raster's split of recent environment maps (renderer/shading/EnvironmentLights.h), the last 4:
  // derived data of the map and the options only, computed once per change of either.
  api::Lru<std::string, std::shared_ptr<const EnvironmentLights>> environmentSplits;

  std::function<void()> releaseHook;  // setReleaseHook: what the renderer's owner may drop

  std::shared_ptr<const EnvironmentLights> environmentLights(const FrameView& view, const EnvironmentLightOptions& o,
                                                             api::FrameStats& stats, const rt::Cancel& cancel) {
    const Image& map = *view.environment;
    const std::string key = view.environmentKey + "|" + std::to_string(map.width) + "x" + std::to_string(map.height) +
                            "|" + o.key();
    const auto* found = environmentSplits.use(key);
    stats.cache.push_back({"environment_lights", found != nullptr});
    if (found) return *found;
    auto split = std::make_shared<const EnvironmentLights>(extractEnvironmentLights(map, o, cancel));
    environmentSplits.evict([](const auto& l) { return l.size() >= 4; });
    environmentSplits.put(key, split);
    return split;
  }

  const GpuScene& gpuScene(const Scene& scene, api::FrameStats& stats, const rt::Cancel& cancel) {
    const std::string key = scene.digest.empty() ? "addr:" + std::to_string(reinterpret_cast<std::uintptr_t>(&scene))
                                                 : scene.digest;
    const auto* found = gpuScenes.use(key);
    stats.cache.push_back({"gpu_scene", found != nullptr});
    if (found) return **found;
    // An upload is a large allocation like a pass's (on llvmpipe its textures and buffers are host
    // memory): released for and admitted under the memory limit before it is made.
    const std::size_t bytes = GpuScene::estimateBytes(scene);
    resources.makeRoom(bytes);
    resources.admit(bytes, "/scene");
    const auto t0 = Clock::now();
    auto g = std::make_unique<GpuScene>(scene, cancel);
    stats.uploadMs = msSince(t0);
    gpuScenes.evict([&](const auto& l) { return l.size() >= gpuSceneCapacity; });
    return *gpuScenes.put(key, std::move(g)).value;
  }

  // renderFrame's stages, in their order: configure -> beginResources -> passParameters -> runPasses ->
  // readBack; then renderFrame's accounting, compare and background.
  FrameConfig configure(const Scene& scene, const api::RenderRequest& request, const FrameInputs& inputs,
                        api::FrameStats& stats, const rt::Cancel& cancel);
  const GpuScene& beginResources(const Scene& scene, const FrameConfig& config, api::FrameStats& stats,
                                 const rt::Cancel& cancel);
  std::vector<Params> passParameters(const Scene& scene, FrameConfig& config, const api::RenderRequest& request,
                                     const FrameInputs& inputs, api::FrameStats& stats);
  void runPasses(const Scene& scene, const GpuScene& gpu, const FrameConfig& config, const std::vector<Params>& params,
                 api::FrameStats& stats, FrameProgress& progress, const rt::Cancel& cancel);
  FrameReadback readBack(const FrameConfig& config, const api::RenderRequest& request, RenderOutput& out);
};

Renderer::Renderer(const DeviceOptions& options) : impl_(std::make_unique<Impl>()) {
  impl_->device = EglDevice::create(options);
  // What the memory accountant may drop beyond the frame's own resources: the GPU copies of the scenes
  // not being rendered (the current one is the most recently used) and their environment splits.
  impl_->resources.setTrimHook([im = impl_.get()] {
    im->gpuScenes.evict([](const auto& l) { return l.size() > 1; });
    im->environmentSplits.evict([](const auto& l) { return l.size() > 1; });
    if (im->releaseHook) im->releaseHook();
  });
  // Per-pass times (GpuProfiler.h): timer queries on a hardware device, glFinish brackets on a software one.
  impl_->profiler = GpuProfiler(impl_->device->info().software ? GpuProfiler::Method::Finish : GpuProfiler::Method::TimerQuery);
  // Reversed-Z needs the [0,1] clip-space depth range (FrameView.h).
  glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
  glEnable(GL_TEXTURE_CUBE_MAP_SEAMLESS);
  gl::checkError("Renderer::Renderer");
}

Renderer::~Renderer() = default;

void Renderer::setSpeedFactor(double factor) { impl_->speed.pin(factor); }

void Renderer::setTechniques(std::vector<std::unique_ptr<Technique>> techniques) {
  impl_->techniques = std::move(techniques);
}

void Renderer::setReleaseHook(std::function<void()> hook) { impl_->releaseHook = std::move(hook); }

// The speed factor's calibration (api::MachineSpeed): the preset table's canonical frame, the built-in
// Cornell box at the table's error size with photon_gi's cheapest front point, rendered twice with
// fresh seeds: the first compiles the shaders and uploads the scene, the second is timed against the
// table's prediction for it. A few hundred ms on llvmpipe, once per daemon, before its first frame with
// a time budget (a daemon that never gets one never pays it).
void Renderer::calibrateSpeed() {
  Impl& im = *impl_;
  const api::PresetTable& table = api::PresetTable::builtin();
  const int size = table.data()["generated"].value("error_size", 64);
  nlohmann::json body{{"scene", {{"builtin", "cornell_box"}}}, {"width", size}, {"height", size}, {"supersampling", 1}};
  if (table.hasFront("photon_gi")) body["passes"] = {{"photon_gi", table.front("photon_gi")[0]["params"]}};
  if (!im.calibrationScene) im.calibrationScene = std::make_unique<Scene>(loadBuiltinScene("cornell_box"));
  im.calibrating = true;
  try {
    for (std::uint64_t seed : {0xCA11B000ull, 0xCA11B001ull}) {
      body["seed"] = seed;
      render(*im.calibrationScene, api::parseRenderRequest(body));
    }
  } catch (...) {
    im.calibrating = false;
    throw;
  }
  im.calibrating = false;
  im.speed.calibrate(im.lastFrame.measuredMs, im.lastFrame.predictedMs);
}

void Renderer::setDerivedCacheBytes(std::size_t bytes) { impl_->resources.setDerivedBytes(bytes); }

void Renderer::setMemoryTarget(std::size_t bytes) { impl_->resources.setMemoryTarget(bytes); }

void Renderer::setMemoryLimit(std::size_t bytes) { impl_->resources.setMemoryLimit(bytes); }

void Renderer::setGpuSceneCapacity(std::size_t scenes) {
  impl_->gpuSceneCapacity = std::max<std::size_t>(1, scenes);
  impl_->resources.setDerivedCapacity(impl_->gpuSceneCapacity);
  impl_->gpuScenes.evict([&](const auto& l) { return l.size() > impl_->gpuSceneCapacity; });
}

const DeviceInfo& Renderer::device() const { return impl_->device->info(); }
const gl::ShaderLibrary& Renderer::shaders() const { return impl_->shaders; }

std::vector<TechniqueDescription> Renderer::techniques() {
  std::vector<TechniqueDescription> out;
  for (const auto& t : createTechniques()) {
    TechniqueDescription d{t->info().name, t->info().description, t->info().outputs};
    Params defaults;
    if (api::findTechnique(d.name)) defaults = Params(api::techniqueParams(d.name));
    for (const std::string& aov : d.outputs) {
      const GroundTruth truth = t->groundTruth(defaults, aov);
      d.groundTruths[aov] = truth.exists() ? truth.reference : nlohmann::json(nullptr);
    }
    out.push_back(std::move(d));
  }
  return out;
}

namespace {
nlohmann::json vec3Json(const glm::vec3& v) { return nlohmann::json::array({v.x, v.y, v.z}); }

nlohmann::json cameraStats(const FrameView& view) {
  const Camera& c = view.camera;
  nlohmann::json j{{"source", view.cameraSource},
                   {"projection", c.projection == ProjectionType::Perspective ? "perspective" : "orthographic"},
                   {"position", vec3Json(view.eye)},
                   {"target", vec3Json(view.target)},
                   {"up", vec3Json(glm::normalize(glm::vec3(c.world[1])))},
                   {"forward", vec3Json(-glm::normalize(glm::vec3(c.world[2])))},
                   {"znear", c.znear}};
  if (!c.name.empty()) j["name"] = c.name;
  if (c.projection == ProjectionType::Perspective) j["yfov_deg"] = glm::degrees(c.yfov);
  else j["ymag"] = c.ymag;
  return j;
}

nlohmann::json sceneStats(const Scene& scene) {
  const Bounds& b = scene.features.bounds;
  nlohmann::json nodes = nlohmann::json::array();
  if (!scene.nodeNames.empty()) {
    for (const auto& n : scene.nodeNames) nodes.push_back(n);
  } else {  // scenes built in code have no node list: their instances' names
    for (const auto& m : scene.meshes)
      if (std::find(nodes.begin(), nodes.end(), m.name) == nodes.end()) nodes.push_back(m.name);
  }
  return {{"name", scene.name},
          {"digest", scene.digest},
          {"bounds", b.empty() ? nlohmann::json(nullptr)
                               : nlohmann::json{{"min", vec3Json(b.min)}, {"max", vec3Json(b.max)},
                                                {"center", vec3Json(b.center())}, {"radius", b.radius()}}},
          {"nodes", nodes},
          {"meshes", scene.meshes.size()},
          {"materials", scene.materials.size()},
          {"textures", scene.textures.size()}};
}
// The GL state passes change and expect at its default on entry (blending, depth test and mask, colour
// mask, the bound program and framebuffer), set back as a fresh context has it after a pass stopped
// mid-way for a cancelled request: the renderer's next frame must not inherit a half-finished pass's state.
void resetPipelineState() {
  glDisable(GL_BLEND);
  glBlendEquation(GL_FUNC_ADD);
  glBlendFunc(GL_ONE, GL_ZERO);
  glDisable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glBindVertexArray(0);
  glUseProgram(0);
  while (glGetError() != GL_NO_ERROR) {
  }
}
// The frame's plan and every 422 it raises without GL but the techniques' own (validate(), called with
// the parameters each frame runs): an environment the caller did not supply, the planner's (an unknown
// AOV or pass, conflicting passes), the compare block's (checkedCompare, whose ground truth it returns).
struct CheckedPlan {
  FramePlan plan;
  GroundTruth truth;
};
CheckedPlan checkedPlan(const std::vector<Technique*>& all, const Scene& scene, const api::RenderRequest& request,
                        const FrameInputs& inputs) {
  if (!request.environment.empty() && !inputs.environment)
    throw api::ApiError(422, "invalid-value", "Environment not supplied",
                        "the environment image " + request.environment + " was not supplied", "/environment");
  CheckedPlan c{planFrame(all, scene, request), {}};
  if (request.compare) c.truth = checkedCompare(request, inputs.compareTarget, all, c.plan);
  return c;
}
}  // namespace

void Renderer::check(const Scene& scene, const api::RenderRequest& requestIn, const FrameInputs& inputsIn) {
  const std::vector<std::unique_ptr<Technique>> techniques = createTechniques();
  std::vector<Technique*> all;
  for (const auto& t : techniques) all.push_back(t.get());
  // The request the frame would run (the default lighting), as renderFrame() makes it.
  FrameLighting lit = frameLighting(scene, requestIn, inputsIn.environment);
  FrameInputs inputs = inputsIn;
  inputs.environment = lit.environment;
  const CheckedPlan checked = checkedPlan(all, scene, lit.request, inputs);
  FrameView view = makeFrameView(scene, lit.request);  // the camera's 422s
  std::vector<Params> params;
  for (Technique* t : checked.plan.passes) params.push_back(requestParams(t->info().name, lit.request));
  view.shadowMapExclusions = shadowMapExclusions(checked.plan.passes, params, scene);
  for (std::size_t i = 0; i < params.size(); ++i) checked.plan.passes[i]->validate(scene, view, params[i]);
}

RenderOutput Renderer::render(const Scene& scene, const api::RenderRequest& requestIn, const std::atomic<bool>* cancel,
                              const FrameInputs& inputs) {
  api::RenderRequest request = requestIn;
  std::string lowered;
  for (;;) {
    try {
      RenderOutput out = renderFrame(scene, request, cancel, inputs);
      if (!lowered.empty()) out.stats.warnings.insert(out.stats.warnings.begin(), lowered);
      return out;
    } catch (const api::ApiError& e) {
      // The frame released what it held as it failed (FrameResources::settleAfterFrame): a lower k
      // allocates k^2 times fewer samples' targets.
      if (e.status != 503 || e.type != "memory-busy" || request.supersamplingGiven || request.supersampling <= 1)
        throw;
      const int k = request.supersampling - 1;
      lowered = "supersampling " + std::to_string(k) + " instead of the default " + std::to_string(requestIn.supersampling) +
                ": at " + std::to_string(request.supersampling) + " the frame did not fit under this server's memory " +
                "limit (radiantd --memory-limit-bytes; refused at " + (e.pointer.empty() ? "its targets" : e.pointer) +
                "); give \"supersampling\" to choose";
      request.supersampling = k;
    }
  }
}

// What a frame decided before any GL work (Impl::configure, then passParameters): the plan and the
// compare block's ground truth, the raster's supersampling k, the cost models' counts, the views (the
// supersampled raster's, with the environment's lights, and the output's), the budget's choice.
struct FrameConfig {
  std::vector<Technique*> all;  // every registered technique (the planner's and the frame graph's input)
  CheckedPlan checked;
  std::vector<std::string> planned;  // the planned passes' names, in the frame graph's order
  int k = 1;                         // the raster's supersampling
  api::SceneCounts counts;           // the cost models' scene variables at this k
  std::string speedScene;            // the speed factor's scene (api::MachineSpeed)
  api::RenderRequest supersampled;   // the request at k (the cost models' pixels are the raster's)
  FrameView view;                    // the raster's (k x the request's size)
  FrameView outView;                 // the request's size, on which readback resolves and compare renders
  api::BudgetChoice choice;          // each planned technique's parameters (presets, budgets, or the request's)
  nlohmann::json speedState;         // the speed factor the choice used
};

// The readback's products (Impl::readBack): NaN and infinities it zeroed, and the beauty as presented
// against the request's background (applied after compare) with its coverage.
struct FrameReadback {
  std::size_t nonFinite = 0;
  std::vector<ZeroedValues> zeroed;
  std::optional<Image> presented, alpha;
};

// Frame progress: monotone, and reported in order although a pass's callback may come from several
// threads at once (hence the lock around the comparison and the call).
struct FrameProgress {
  explicit FrameProgress(const std::function<void(double)>& s) : sink(s) {}
  const std::function<void(double)>& sink;
  std::mutex mutex;
  double soFar = 0.0;
  void operator()(double value) {
    if (!sink) return;
    std::lock_guard lock(mutex);
    if (!(value > soFar)) return;
    soFar = value;
    sink(value);
  }
};

FrameConfig Renderer::Impl::configure(const Scene& scene, const api::RenderRequest& request, const FrameInputs& inputs,
                                      api::FrameStats& stats, const rt::Cancel& cancel) {
  FrameConfig c;
  for (auto& t : techniques) c.all.push_back(t.get());
  c.checked = checkedPlan(c.all, scene, request, inputs);
  const FramePlan& plan = c.checked.plan;
  // The passes run on the supersampled view; readback resolves to outView (the request's size), on
  // which compare() renders the reference.
  int k = rasterSupersampling(
      request.supersampling, request.width, request.height,
      std::any_of(plan.passes.begin(), plan.passes.end(), [](const Technique* t) { return t->info().name == "reference"; }));
  for (Technique* t : plan.passes) c.planned.push_back(t->info().name);
  const std::vector<std::string>& planned = c.planned;
  // The cost models' scene variables (particles of the scene and the request's media, light_volumes' beams).
  api::SceneCounts& counts = c.counts;
  counts = costCounts(c.all, scene, request.media);
  // specular's maps follow the view: its model is charged the resolution the pass will choose at the
  // frame's k (and each k the default frame budget weighs, below).
  std::function<double(int)> specularMapTexelsAt;
  if (std::find(planned.begin(), planned.end(), "specular") != planned.end()) {
    const Params sp = requestParams("specular", request);
    const auto owned = plan.owned.find("caustics");
    const bool forCaustics = owned != plan.owned.end() && (owned->second & api::kPathLSDE);
    specularMapTexelsAt = [&, sp, forCaustics](int atK) {
      api::RenderRequest r = request;
      r.width *= atK;
      r.height *= atK;
      r.supersampling = atK;
      return double(chooseMapResolution(scene, makeFrameView(scene, r, inputs.environment), sp, forCaustics).texels);
    };
    counts.specularMapTexels = specularMapTexelsAt(k);
  }
  // The speed factor's scene (api::MachineSpeed): the scene and the passes it runs, whose own recent
  // frames measure the load and the models' error on it at once.
  c.speedScene = (scene.digest.empty() ? "name:" + scene.name : scene.digest) + "|";
  for (const std::string& p : planned) c.speedScene += p + ",";
  // The server's default frame budget lowers a default supersampling first (api/Presets.h).
  if (const int within = api::supersamplingWithinDefaultBudget(api::PresetTable::builtin(), planned, request, k,
                                                               inputs.limits, counts, speed.planningFactor(c.speedScene),
                                                               specularMapTexelsAt);
      within < k) {
    stats.warnings.push_back("supersampling " + std::to_string(within) + " instead of the default " + std::to_string(k) +
                             ": at " + std::to_string(k) + " the default frame is predicted above this server's default "
                             "frame budget (radiantd --default-frame-budget-ms); give \"supersampling\" to choose");
    k = within;
    if (specularMapTexelsAt) counts.specularMapTexels = specularMapTexelsAt(k);  // the maps this k runs
  }
  c.k = k;
  stats.supersampling = k;
  c.supersampled = request;
  c.supersampled.width *= k;
  c.supersampled.height *= k;
  c.supersampled.supersampling = k;  // the k used (capped; 1 with the reference)
  // photon_gi's gather block at this k (its step grows with the frame): the model's block samples.
  if (std::find(planned.begin(), planned.end(), "photon_gi") != planned.end())
    counts.photonGatherBlock = api::photonGatherBlock(request, k);
  FrameView& view = c.view;
  view = makeFrameView(scene, c.supersampled, inputs.environment);
  view.supersampling = k;
  // The environment's compact bright regions become shadowed directional lights of the raster when
  // `direct` runs to light with them (docs/TECHNIQUES.md, "Environment lights"); the reference and
  // the background keep the whole map.
  const bool directPlanned = std::find(planned.begin(), planned.end(), "direct") != planned.end();
  if (view.environment && directPlanned) {
    EnvironmentLightOptions o = environmentLightOptions(request);
    // Sky lights stand for photon_gi's first-hit sky photons (the residual's L(sky)DE): only when it
    // owns that class (ambient_occlusion's SH irradiance times AO otherwise; docs/TECHNIQUES.md,
    // direct, "Sky lights").
    const auto owned = plan.owned.find("photon_gi");
    if (owned == plan.owned.end() || !(owned->second & api::kPathSkyDE)) o.skyLights = 0;
    view.environmentLights = environmentLights(view, o, stats, cancel);
    view.environmentLightsKey = o.key();
    const auto& taken = view.environmentLights->lights;
    view.lights.insert(view.lights.end(), taken.begin(), taken.end());
    const auto& sky = view.environmentLights->skyLights;
    view.lights.insert(view.lights.end(), sky.begin(), sky.end());
  }
  c.outView = view;
  c.outView.width = request.width;
  c.outView.height = request.height;
  c.outView.supersampling = 1;
  return c;
}

// The scene on the GPU and the frame's resources: declared outputs allocated, beauty cleared, the
// environment map and lights declared; the profiler and the per-pass stats ready.
const GpuScene& Renderer::Impl::beginResources(const Scene& scene, const FrameConfig& config, api::FrameStats& stats,
                                               const rt::Cancel& cancel) {
  const FramePlan& plan = config.checked.plan;
  stats.camera = cameraStats(config.view);
  const GpuScene& gpu = gpuScene(scene, stats, cancel);
  stats.skipped = plan.skipped;
  stats.lightPaths = plan.lightPaths;

  resources.beginFrame(gpu, config.view, &stats.cache);
  resources.setCancel(cancel);  // prepare() and the derived-data builders (photons, beams, BVH)
  resources.setLightPathOwners(plan.lightPaths, plan.owned);
  // Declared resources (renderer/frame/FrameAllocation.h): the Renderer allocates the planned passes'
  // AOV outputs, beauty and the environment map; each pass then touches the shared resources only as
  // its TechniqueInfo declares (declaredAccess, checked by FrameResources in the pass scopes below).
  resources.setSharedResources(sharedResources(config.all));
  allocateDeclaredOutputs(resources, plan.passes);
  declareEnvironmentMap(resources, config.view);
  declareFrameLights(resources, config.view);
  profiler.beginFrame();
  // PassStats must not move while the profiler holds pointers to them.
  stats.passes.resize(plan.passes.size());
  return gpu;
}

// quality / time_budget_ms: each planned technique's parameters from the preset table (api/Presets.h);
// without them, the request's own. Each pass validates the parameters it will run (as Renderer::check
// did with the request's own) and names the meshes whose shadows it supplies itself (light_volumes).
std::vector<Params> Renderer::Impl::passParameters(const Scene& scene, FrameConfig& config,
                                                   const api::RenderRequest& request, const FrameInputs& inputs,
                                                   api::FrameStats& stats) {
  const FramePlan& plan = config.checked.plan;
  std::vector<Params> params(plan.passes.size());
  stats.scene["counts"] = config.counts.toJson();
  // The supersampled request: the cost models' `pixels` are the raster's (the table was measured at
  // k = 1, so a request that keeps its own supersampling under a budget is charged k^2 the pixels);
  // photon_gi's gather is charged its block samples (counts.photonGatherBlock).
  config.speedState = speed.toJson(config.speedScene);  // what this frame's choice used
  config.choice = api::chooseConfiguration(api::PresetTable::builtin(), config.planned, config.supersampled,
                                           inputs.limits, config.counts, speed.planningFactor(config.speedScene));
  for (auto& w : config.choice.warnings) stats.warnings.push_back(std::move(w));
  for (std::size_t i = 0; i < plan.passes.size(); ++i) {
    Technique* t = plan.passes[i];
    stats.passes[i].name = t->info().name;
    const auto given = request.explicitParams.find(t->info().name);
    params[i] = Params(config.choice.params.at(t->info().name),
                       given == request.explicitParams.end() ? std::set<std::string>{} : given->second);
  }
  // Meshes whose shadows a pass supplies itself (light_volumes): known before any pass validates, as
  // the shadow maps' limits count the meshes they draw.
  config.view.shadowMapExclusions = shadowMapExclusions(plan.passes, params, scene);
  for (std::size_t i = 0; i < plan.passes.size(); ++i) plan.passes[i]->validate(scene, config.view, params[i]);
  return params;
}

// Every planned pass's prepare(), then every execute(), in the frame graph's order, each inside the
// scope of what it declares (FrameResources) and, for execute, timed by the profiler.
void Renderer::Impl::runPasses(const Scene& scene, const GpuScene& gpu, const FrameConfig& config,
                               const std::vector<Params>& params, api::FrameStats& stats, FrameProgress& progress,
                               const rt::Cancel& cancel) {
  const FramePlan& plan = config.checked.plan;
  for (std::size_t i = 0; i < plan.passes.size(); ++i) {
    Technique* t = plan.passes[i];
    cancel.check("the frame's set-up, before preparing " + t->info().name);
    resources.beginPass(t->info().name, declaredAccess(t->info()), FrameResources::Phase::Prepare);
    const auto start = std::chrono::steady_clock::now();
    t->prepare(scene, params[i], resources);
    stats.passes[i].prepareMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    resources.endPass();
    gl::checkError(("prepare " + t->info().name).c_str());
  }
  const double passCount = static_cast<double>(std::max<std::size_t>(1, plan.passes.size()));
  for (std::size_t i = 0; i < plan.passes.size(); ++i) {
    progress(0.95 * static_cast<double>(i) / passCount);
    if (cancel.requested())
      throw api::ApiError(409, "canceled", "Render canceled", "the render was cancelled before pass " +
                                                                plan.passes[i]->info().name);
    Technique* t = plan.passes[i];
    gl::DebugGroup group(t->info().name);
    PassContext ctx{scene, gpu, config.view, params[i], resources, shaders, stats.passes[i],
                    [&, i](double f) { progress(0.95 * (static_cast<double>(i) + std::clamp(f, 0.0, 1.0)) / passCount); },
                    cancel};
    resources.beginPass(t->info().name, declaredAccess(t->info()), FrameResources::Phase::Execute);
    {
      GpuProfiler::Scope scope(profiler, stats.passes[i]);
      t->execute(ctx);
    }
    // A pass writes only what it declares (its outputs; beauty if it adds to it): programmer error.
    if (const std::string bad = undeclaredWrite(t->info(), resources.passWrites()); !bad.empty())
      throw std::logic_error("Renderer: pass " + t->info().name + " wrote '" + bad +
                             "', which its TechniqueInfo does not declare");
    resources.endPass();
    gl::checkError(("execute " + t->info().name).c_str());
    for (auto& w : stats.passes[i].warnings) stats.warnings.push_back(t->info().name + ": " + std::move(w));
    stats.passes[i].warnings.clear();
  }
}

// Readback of every AOV the outputs name (beauty always, and the compared one), resolved from the
// raster's k x k samples to the request's size; non-finite values zeroed and counted.
FrameReadback Renderer::Impl::readBack(const FrameConfig& config, const api::RenderRequest& request, RenderOutput& out) {
  const FrameView& view = config.view;
  const FrameView& outView = config.outView;
  const int k = config.k;
  FrameReadback r;
  std::vector<std::string> aovs{"beauty"};
  for (const auto& o : request.outputs)
    for (const auto& a : o.aovs)
      if (std::find(aovs.begin(), aovs.end(), a) == aovs.end()) aovs.push_back(a);
  if (request.compare && std::find(aovs.begin(), aovs.end(), request.compare->aov) == aovs.end())
    aovs.push_back(request.compare->aov);
  std::vector<float> rgba;  // the samples of an AOV resolved on the CPU (k = 1, or presentBackground)
  // The background (api::Background), applied to the beauty after compare (which scores the frame with
  // the environment behind it, as the reference renders it): the beauty as presented and its coverage.
  const bool environmentBehind = request.background.kind == api::Background::Kind::Environment;
  for (const std::string& aov : aovs) {
    const AovSource src = aovSource(aov);
    Image img = Image::make(aov, outView.width, outView.height, src.channels);
    const bool drawn = resources.hasTexture(src.texture) && resources.written(aov);
    // The beauty shown against another background needs its samples on the CPU (presentBackground).
    const bool samplesNeeded = k == 1 || (aov == "beauty" && !environmentBehind);
    if (drawn) {
      if (samplesNeeded || !resolveSupersampledOnGpu(resources, shaders, resources.texture(src.texture), k, src, img)) {
        if (rgba.empty()) rgba.resize(static_cast<std::size_t>(view.width) * view.height * 4);
        resources.texture(src.texture).download(0, GL_RGBA, GL_FLOAT, rgba.data(), rgba.size() * sizeof(float));
        resolveSupersampled(rgba, view.width, view.height, k, src, img);
      }
    } else if (aov == "beauty" || aov == "direct") {
      // Nothing was drawn (no geometry): the frame shows the sky.
      for (int i = 0; i < outView.width * outView.height; ++i)
        for (int c = 0; c < 3; ++c) img.pixels[static_cast<std::size_t>(i) * 3 + c] = view.ambient[c];
    }
    if (aov == "beauty" && !environmentBehind)
      presentBackground(resources, view, k, request.background, drawn ? &rgba : nullptr, r.presented, r.alpha);
    if (const std::size_t bad = sanitize(img.pixels)) {
      r.nonFinite += bad;
      r.zeroed.push_back({aov, bad, writersOf(aov, config.checked.plan.passes)});
    }
    out.aovs.push_back(std::move(img));
  }
  return r;
}

// The frame: its default lighting, then the stages above; then its time against the cost model, compare,
// the background and the memory accountant.
RenderOutput Renderer::renderFrame(const Scene& scene, const api::RenderRequest& requestIn,
                                   const std::atomic<bool>* cancel, const FrameInputs& inputsIn) {
  Impl& im = *impl_;
  im.device->makeCurrent();
  // The frame's memory claim (FrameResources::admit) ends with the frame, however it ends.
  struct ClaimScope {
    FrameResources& resources;
    ~ClaimScope() { resources.releaseClaim(); }
  } claimScope{im.resources};
  RenderOutput out;
  api::FrameStats& stats = out.stats;
  const DeviceInfo& dev = im.device->info();
  stats.device = {{"vendor", dev.vendor}, {"renderer", dev.renderer}, {"version", dev.version},
                  {"platform", dev.platform}, {"reason", dev.reason}};
  stats.passTiming = im.profiler.methodName();
  stats.triangles = scene.features.triangles;
  stats.lights = static_cast<int>(scene.lights.size());
  stats.scene = sceneStats(scene);
  stats.warnings = scene.warnings;

  // Default lighting (renderer/frame/FrameLighting.h): the studio map for a scene without punctual
  // lights when the request names no ambient or environment.
  FrameLighting lit = frameLighting(scene, requestIn, inputsIn.environment);
  api::RenderRequest effective = std::move(lit.request);
  FrameInputs inputs = inputsIn;
  inputs.environment = lit.environment;
  stats.lighting = std::move(lit.lighting);
  stats.lightingReason = std::move(lit.reason);
  const api::RenderRequest& request = effective;
  if (request.timeBudgetMs > 0 && im.speed.needsCalibration() && !im.calibrating) calibrateSpeed();

  try {
    const auto frameStart = Clock::now();
    const std::size_t programsBefore = im.shaders.cachedPrograms();
    const rt::Cancel cancelToken(cancel);
    FrameConfig config = im.configure(scene, request, inputs, stats, cancelToken);
    const GpuScene& gpu = im.beginResources(scene, config, stats, cancelToken);
    const std::vector<Params> params = im.passParameters(scene, config, request, inputs, stats);
    FrameProgress progress(inputs.progress);
    im.runPasses(scene, gpu, config, params, stats, progress, cancelToken);

    const auto readStart = Clock::now();
    FrameReadback readback = im.readBack(config, request, out);
    stats.readbackMs = msSince(readStart);
    im.profiler.resolve();
    progress(0.95);
    if (const std::string w = blackFrameWarning(out, stats, scene, request); !w.empty()) stats.warnings.push_back(w);
    // This frame's time against the table's prediction (before compare's reference, which the table
    // does not model): the speed factor's evidence when the frame is comparable with the table.
    api::BudgetChoice& choice = config.choice;
    im.lastFrame = {msSince(frameStart),
                    api::predictFrameMs(api::PresetTable::builtin(), config.planned, choice.params,
                                        double(config.supersampled.width) * config.supersampled.height, config.counts)};
    if (choice.active) {
      stats.budget = std::move(choice.stats);
      stats.budget["speed"] = config.speedState;
      api::recordMeasured(stats.budget, stats, im.lastFrame.measuredMs);
    }
    const bool observed = !im.calibrating && !im.speed.pinned() && im.lastFrame.predictedMs > 0 &&
                          comparableWithPresetTable(stats, programsBefore != im.shaders.cachedPrograms());
    if (observed) im.speed.observe(im.lastFrame.measuredMs, im.lastFrame.predictedMs, config.speedScene);
    if (choice.active) stats.budget["speed"]["observed"] = observed;  // this frame joined the window
    if (request.compare)
      compare(im.resources, scene, config.outView, request, inputs.compareTarget, config.checked.truth, out);
    std::size_t nonFinite = readback.nonFinite;
    if (readback.presented) {
      nonFinite += sanitize(readback.presented->pixels);
      *std::find_if(out.aovs.begin(), out.aovs.end(), [](const Image& i) { return i.aov == "beauty"; }) =
          std::move(*readback.presented);
      if (readback.alpha) out.aovs.push_back(std::move(*readback.alpha));
    }
    stats.renderMs = msSince(frameStart);
    // The memory accountant: what this frame has not used goes when the resident set is over the target,
    // and its own targets too when they leave it over the limit.
    im.resources.settleAfterFrame();
    stats.memory = {{"resident_bytes", FrameResources::residentBytes()},
                    {"resource_bytes", im.resources.resourceBytes()},
                    {"derived_bytes", im.resources.derivedBytes()},
                    {"target_bytes", im.resources.memoryTarget()},
                    {"limit_bytes", im.resources.memoryLimit()},
                    {"released_bytes", im.resources.releasedThisFrame()}};
    progress(1.0);
    if (nonFinite) stats.passes.back().counters["non_finite_pixels_zeroed"] = static_cast<double>(nonFinite);
    reportOutputRange(out, readback.zeroed, request);  // after compare: its error and reference AOVs are outputs too
    im.resources.setCancel({});  // the flag belongs to this request's job, which may go away after it
    return out;
  } catch (const rt::Cancelled& c) {
    // A pass or builder saw the cancel flag mid-loop (renderer/raytracing/Cancel.h): what it built is not
    // stored (a shared resource it was rewriting holds nothing: FrameResources::refill), and the GL
    // pipeline state it changed goes back to the defaults a fresh context has.
    im.resources.setCancel({});
    im.profiler.beginFrame();
    resetPipelineState();
    im.resources.settleAfterFrame();  // a frame refused or stopped midway holds its targets too
    throw api::ApiError(409, "canceled", "Render canceled", c.what());
  } catch (const api::ApiError& e) {
    im.resources.setCancel({});
    im.profiler.beginFrame();
    if (e.status == 409) resetPipelineState();
    im.resources.settleAfterFrame();
    throw;
  } catch (...) {
    im.resources.setCancel({});
    // An environment failure may leave GL objects in any state: drop derived data so the next frame
    // rebuilds from scratch, and drain the GL error queue.
    im.profiler = GpuProfiler(im.profiler.method());
    im.resources.clear();
    im.gpuScenes.clear();
    while (glGetError() != GL_NO_ERROR) {
    }
    throw;
  }
}

}  // namespace radiant
