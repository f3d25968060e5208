#include "renderer/techniques/reference/ReferencePass.h"
#include "params/reference_params.h"

#include <algorithm>
#include <climits>

#include <nlohmann/json.hpp>

#include "renderer/frame/PassContext.h"
#include "renderer/frame/RayScenes.h"
#include "renderer/reference/LightTracer.h"
#include "renderer/raytracing/ParticleMedium.h"
#include "renderer/reference/VolumeTracer.h"

namespace radiant {

namespace {

// The volumetric reference's image of the frame's media: RGB radiance ("media") or the transmittance
// ("media_transmittance"), cached by what shapes it.
const Image& mediaReferenceImage(FrameResources& res, const Scene& scene, const FrameView& view,
                                 const ReferenceRequest& r, ReferenceRun& run) {
  reference::VolumeOptions o;
  o.mode = reference::mediaModeFromString(r.mediaMode);
  o.spp = r.spp;
  // Full mode's scattering cap: the shared safety cap (the volume tracer's roulette ends paths as the
  // path tracer's does, VolumeTracer.cpp); 0 still lets a camera ray's first scattering count.
  o.maxScattering = std::max(r.maxBounces, 1);
  o.seed = view.seed;
  o.sky = view.ambient;
  o.cancel = res.cancel();
  const glm::mat4& w = view.camera.world;
  const nlohmann::json key = {{"scene", res.sceneKey()}, {"media", view.mediaKey},
                              {"camera", std::vector<float>(&w[0][0], &w[0][0] + 16)},
                              {"projection", static_cast<int>(view.camera.projection)},
                              {"yfov", view.camera.yfov}, {"mag", {view.camera.xmag, view.camera.ymag}},
                              {"znear", view.camera.znear}, {"size", {view.width, view.height}},
                              {"spp", o.spp}, {"mode", r.mediaMode}, {"max_scattering", o.maxScattering},
                              {"seed", o.seed}, {"sky", {o.sky.x, o.sky.y, o.sky.z}}};
  bool built = false;
  const Image& rgba = res.cached<Image>("reference:media", key.dump(), [&] {
    built = true;
    const rt::ParticleMedium medium(view.media);
    return std::make_unique<Image>(
        reference::VolumeTracer(sharedRayScene(res, scene), medium).render(view.camera, view.width, view.height, o));
  });
  run.cacheHit = !built;
  const bool transmittance = r.aov == "media_transmittance";
  return res.cached<Image>("reference:" + r.aov, key.dump(), [&] {
    auto out = std::make_unique<Image>(Image::make("reference", rgba.width, rgba.height, transmittance ? 1 : 3));
    for (std::size_t p = 0; p < static_cast<std::size_t>(rgba.width) * rgba.height; ++p)
      for (int c = 0; c < out->channels; ++c) out->pixels[p * out->channels + c] = rgba.pixels[p * 4 + (transmittance ? 3 : c)];
    return out;
  });
}

}  // namespace

const Image& referenceImage(FrameResources& res, const Scene& scene, const FrameView& view,
                            const ReferenceRequest& r, ReferenceRun* run,
                            const std::function<void(double)>& progress) {
  ReferenceRun local;
  ReferenceRun& out = run ? *run : local;
  out = ReferenceRun{};
  if (r.aov == "media" || r.aov == "media_transmittance") return mediaReferenceImage(res, scene, view, r, out);
  const rt::RayScene& rayScene = sharedRayScene(res, scene);
  const reference::PathTracer tracer(rayScene);
  reference::ReferenceOptions o;
  o.spp = r.spp;
  o.maxBounces = r.maxBounces;
  o.russianRoulette = r.russianRoulette;
  o.seed = view.seed;
  o.skyRadiance = view.ambient;
  o.environment = view.environment;  // when set, it replaces skyRadiance
  o.environmentDistribution = environmentDistribution(res, view);
  o.cancel = res.cancel();
  if (r.aov == "direct") {
    o.minPathBounce = 0, o.maxPathBounce = 1;  // what the raster `direct` AOV holds: emission, sky, direct
  } else if (r.aov == "indirect" || r.aov == "indirect_diffuse") {
    o.minPathBounce = 2, o.maxPathBounce = INT_MAX;
  } else if (r.aov == "ao") {
    o.mode = r.aoDefinition == "volumetric" ? reference::ReferenceOptions::Mode::AoVolumetric
                                            : reference::ReferenceOptions::Mode::AoCosineStep;
    o.aoRadius = r.aoRadius;
  }
  // The light tracer's caustics join the image when caustic paths can exist and the range holds k >= 2.
  const bool causticsOnly = r.aov == "caustics";
  const bool lightTrace = causticsOnly || (r.caustics && o.mode == reference::ReferenceOptions::Mode::Radiance &&
                                           o.maxPathBounce >= 2 && reference::sceneHasDeltaLobes(scene));
  reference::LightTracerOptions lo;
  // Progress: the path tracer's tiles, then the light tracer's waves, in proportion to their samples.
  const double ptShare = causticsOnly ? 0.0 : lightTrace ? 0.5 : 1.0;
  if (progress) o.progress = [&progress, ptShare](double f) { progress(ptShare * f); };
  if (lightTrace) {
    o.excludeCaustics = true;
    lo.paths = reference::LightTracerOptions::Paths::Caustics;
    lo.pathsPerPixel = r.lightPathsPerPixel > 0 ? r.lightPathsPerPixel : r.spp;
    lo.maxBounces = o.maxBounces;
    lo.russianRoulette = o.russianRoulette;
    lo.seed = o.seed;
    lo.minPathBounce = std::max(2, o.minPathBounce);
    lo.maxPathBounce = o.maxPathBounce;
    lo.skyRadiance = o.skyRadiance;
    lo.environment = o.environment;
    lo.cancel = res.cancel();
    if (progress) lo.progress = [&progress, ptShare](double f) { progress(ptShare + (1.0 - ptShare) * f); };
  }
  const glm::mat4& w = view.camera.world;
  nlohmann::json key = {{"scene", res.sceneKey()},
                        {"camera", std::vector<float>(&w[0][0], &w[0][0] + 16)},
                        {"projection", static_cast<int>(view.camera.projection)},
                        {"yfov", view.camera.yfov}, {"mag", {view.camera.xmag, view.camera.ymag}},
                        {"size", {view.width, view.height}}, {"spp", o.spp}, {"max_bounces", o.maxBounces},
                        {"rr", o.russianRoulette}, {"seed", o.seed}, {"bounces", {o.minPathBounce, o.maxPathBounce}},
                        {"mode", static_cast<int>(o.mode)}, {"ao_radius", o.aoRadius},
                        {"sky", {o.skyRadiance.x, o.skyRadiance.y, o.skyRadiance.z}},
                        {"environment", view.environmentKey},
                        {"light_paths", lightTrace ? lo.pathsPerPixel : 0}, {"caustics_only", causticsOnly}};
  bool built = false;
  std::uint64_t lightRays = 0, lightCapped = 0;
  Image& img = res.cached<Image>("reference:" + r.aov, key.dump(), [&] {
    built = true;
    std::unique_ptr<Image> image;
    if (!causticsOnly) image = std::make_unique<Image>(tracer.render(view.camera, view.width, view.height, o));
    if (lightTrace) {
      const reference::LightTracer lightTracer(rayScene);
      const Image caustics = lightTracer.render(view.camera, view.width, view.height, lo);
      lightRays = lightTracer.raysTraced();
      lightCapped = lightTracer.pathsCapped();
      if (!image) image = std::make_unique<Image>(caustics);
      else
        for (std::size_t i = 0; i < image->pixels.size(); ++i) image->pixels[i] += caustics.pixels[i];
    }
    image->aov = "reference";
    if (o.mode != reference::ReferenceOptions::Mode::Radiance) {
      // AO is scalar: keep one channel, like the raster `ao` AOV.
      Image ao = Image::make("reference", image->width, image->height, 1);
      for (std::size_t i = 0; i < ao.pixels.size(); ++i) ao.pixels[i] = image->pixels[i * image->channels];
      *image = std::move(ao);
    }
    return image;
  });
  out.cacheHit = !built;
  out.rays = built ? (causticsOnly ? 0 : tracer.raysTraced()) + lightRays : 0;
  out.pathsCapped = built ? (causticsOnly ? 0 : tracer.pathsCapped()) + lightCapped : 0;
  out.lightTraced = lightTrace;
  return img;
}

const TechniqueInfo& ReferencePass::info() const {
  static const TechniqueInfo i = describedTechnique("reference");
  return i;
}

GroundTruth ReferencePass::groundTruth(const Params& params, const std::string& aov) const {
  if (aov != "reference") return {};
  nlohmann::json truth = params.json();
  // The compare block sets the truth's samples; its bounce range is the pass's own (max_bounces stays).
  truth.erase("spp");
  truth.erase("light_paths_per_pixel");
  return {truth};
}

Requirements ReferencePass::requirements(const Scene& scene, const api::RenderRequest& request) const {
  const SceneFeatures f = mediaFeatures(scene.features, request.media);
  return f.triangles > 0 || f.hasMedia() ? Requirements::ok()
                                         : Requirements::skip("the scene has no triangles and no media");
}

ReferenceRequest referenceRequestFrom(const Params& params) {
  const ReferenceParams p = ReferenceParams::from(params);
  ReferenceRequest r;
  r.aov = ReferenceParams::toString(p.aov);
  r.spp = p.spp;
  r.lightPathsPerPixel = p.light_paths_per_pixel;
  r.caustics = p.caustics;
  r.maxBounces = p.max_bounces;
  r.russianRoulette = p.russian_roulette;
  r.aoRadius = static_cast<float>(p.ao_radius);
  r.aoDefinition = ReferenceParams::toString(p.ao_definition);
  r.mediaMode = ReferenceParams::toString(p.media_mode);
  return r;
}

void ReferencePass::prepare(const Scene&, const Params& params, FrameResources& res) {
  request_ = referenceRequestFrom(params);
  res.texture("reference");  // a declared output: allocated by the Renderer
}

void ReferencePass::execute(PassContext& ctx) {
  ReferenceRun run;
  const Image& img = referenceImage(ctx.resources, ctx.scene, ctx.view, request_, &run, ctx.progress);
  // Upload as RGBA with GL's bottom-up rows so readback treats it like every other AOV.
  std::vector<float> rgba(static_cast<std::size_t>(img.width) * img.height * 4, 0.f);
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      for (int c = 0; c < std::min(img.channels, 3); ++c)
        rgba[(static_cast<std::size_t>(img.height - 1 - y) * img.width + x) * 4 + c] = img.at(x, y)[c];
  ctx.resources.texture("reference").upload(0, 0, 0, 0, img.width, img.height, 1, GL_RGBA, GL_FLOAT, rgba.data());
  ctx.stats.counters["spp"] = request_.spp;
  ctx.stats.counters["rays"] = static_cast<double>(run.rays);
  ctx.stats.counters["cached"] = run.cacheHit ? 1.0 : 0.0;
  // Paths that max_bounces ended while Russian roulette would have let them go on (0 when cached).
  ctx.stats.counters["paths_capped"] = static_cast<double>(run.pathsCapped);
  // 1 when the light tracer added the caustic paths L S+ D E (the scene has a Dirac-delta lobe).
  ctx.stats.counters["light_traced_caustics"] = run.lightTraced ? 1.0 : 0.0;
  ctx.resources.markWritten("reference");
}

}  // namespace radiant
