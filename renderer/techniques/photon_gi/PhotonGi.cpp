#include "renderer/techniques/photon_gi/PhotonGi.h"
#include "params/photon_gi_params.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <nlohmann/json.hpp>

#include "api/Types.h"
#include "renderer/frame/PassContext.h"
#include "renderer/frame/RayScenes.h"
#include "renderer/raytracing/PhotonTracer.h"
#include "renderer/shading/PhotonGrid.h"

namespace radiant {
namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

// Coverage points per kernel disk (pi h^2) for the edge renormalisation: stratified, so the kernel mass
// they estimate is within about 1% at this density.
constexpr double kCoveragePerKernel = 64.0;
constexpr std::size_t kMaxCoveragePerSurface = 1u << 18;

struct PhotonCache {
  rt::PhotonSet set;
  std::size_t bytes() const { return set.records.capacity() * sizeof(rt::PhotonRecord); }  // FrameResources' budget
};
struct SplatCache {
  photon_gi::SplatGrid grid;
  std::size_t records = 0;      // the photon records it was built from
  std::uint64_t capped = 0;     // photons of that set ended by max_bounces
  std::size_t photonSplats = 0, coveragePoints = 0;
  float hMin = 0.f, hMax = 0.f;
  std::size_t bytes() const {
    return grid.splats.capacity() * sizeof(photon_gi::GpuSplat) + grid.cellStart.capacity() * sizeof(grid.cellStart[0]);
  }
};

// Which environment photons are drawn (docs/TECHNIQUES.md, photon_gi, "Sky photons under a split
// map"). When the frame split the map into lights S and a residual R (EnvironmentLights.h), the
// lights' first hits are `direct`'s: photons drawn by L spend 70-79% of the sky's photons on a sun
// whose first hits are not splatted, and the residual's direct light is estimated from the rest.
// Texels are then drawn by the luminance of R + weight S; every photon still carries L / pdf, so every
// bounce stays unbiased (R > 0 wherever L > 0), and the suns' photons, fewer and heavier, carry their
// light's later bounces. Null (draw by L) when the map is not split or weight is 1. Derived data of
// the map, the split and the weight: cached per their key.
struct PhotonEnvironmentDistribution {
  std::shared_ptr<const rt::EnvironmentDistribution> distribution;
};
std::shared_ptr<const rt::EnvironmentDistribution> photonEnvironmentDistribution(FrameResources& res,
                                                                                 const FrameView& view, float weight,
                                                                                 std::string& key) {
  key = view.environmentKey;
  // With sky lights (direct's sky_lights) no first hit of the sky is splatted: draw by L, for the bounces.
  if (!view.environment || !view.environmentLights || !view.environmentLights->split() || weight >= 1.f ||
      view.skyLights() > 0)
    return environmentDistribution(res, view);
  const Image& map = *view.environment;
  const Image& residual = view.environmentLights->residual;
  if (residual.width != map.width || residual.height != map.height) return environmentDistribution(res, view);
  key = view.lightingEnvironmentKey() + "|light_photons=" + std::to_string(weight);
  return res
      .cached<PhotonEnvironmentDistribution>(
          "photon_gi_environment_distribution", key,
          [&] {
            Image w = Image::make("photon_weight", map.width, map.height, 1);
            for (int y = 0; y < map.height; ++y) {
              if ((y & 63) == 0) res.cancel().check("photon_gi's environment distribution");
              for (int x = 0; x < map.width; ++x) {
                const float* l = map.at(x, y);
                const float* r = residual.at(x, y);
                auto lum = [](const float* p, int c) {
                  return c >= 3 ? rt::luminance(glm::vec3(p[0], p[1], p[2])) : p[0];
                };
                const float yl = std::max(0.f, lum(l, map.channels)), yr = std::max(0.f, lum(r, residual.channels));
                w.at(x, y)[0] = yr + weight * std::max(0.f, yl - yr);
              }
            }
            return std::make_unique<PhotonEnvironmentDistribution>(
                PhotonEnvironmentDistribution{rt::EnvironmentDistribution::build(map, &w, res.cancel())});
          })
      .distribution;
}

}  // namespace

float PhotonGiPass::kernelRadius(float C, double area, double n, bool ppm, double photons, double ppmBasePhotons,
                                 double ppmAlpha) {
  if (!(n > 0.0) || !(area > 0.0)) return 0.f;
  double h2 = double(C) * C * area / n;  // eq. 3
  if (ppm && photons > 0.0 && ppmBasePhotons > 0.0) h2 *= std::pow(photons / ppmBasePhotons, ppmAlpha);
  return static_cast<float>(std::sqrt(h2));
}

// Declared in photon_gi.json. photon_grid (a resource): the uploaded splat grid, read by specular's
// distance maps (renderer/shading/PhotonGrid.h). LS+DE: punctual light through near-mirrors
// (isSpecular() with a glossy lobe), which the tracer scatters; the caustics pass owns it when it runs.
const TechniqueInfo& PhotonGiPass::info() const {
  static const TechniqueInfo i = describedTechnique("photon_gi");
  return i;
}

Requirements PhotonGiPass::requirements(const Scene& scene, const api::RenderRequest& request) const {
  const SceneFeatures& f = scene.features;
  if (f.triangles == 0) return Requirements::skip("the scene has no triangles");
  if (f.lightCount() == 0 && !f.hasEmissive() && request.ambient == glm::vec3(0.f) && request.environment.empty())
    return Requirements::skip("nothing emits light: no lights, no emissive surfaces, no ambient or environment");
  // env_diffuse, which also supplies LD+DE, is the planner's business: photon_gi requires that class
  // (photon_gi.json, requires_paths) and is dropped where env_diffuse owns it.
  return Requirements::ok();
}

void PhotonGiPass::prepare(const Scene& scene, const Params& params, FrameResources& res) {
  const PhotonGiParams p = PhotonGiParams::from(params);
  Settings s;
  s.photons = static_cast<std::uint64_t>(p.photons);
  s.C = static_cast<float>(p.C);
  s.ppm = p.h_schedule == PhotonGiParams::HSchedule::kPpm;
  s.ppmAlpha = p.ppm_alpha;
  s.ppmBase = p.ppm_base_photons;
  s.maxBounces = p.max_bounces;
  s.environmentLightPhotons = static_cast<float>(p.environment_light_photons);
  settings_ = s;
  splat_.method = p.method == PhotonGiParams::Method::kGather ? photon_gi::Method::Gather
                                                                       : photon_gi::Method::Splat;
  splat_.kernel = p.kernel == PhotonGiParams::Kernel::kEpanechnikov ? photon_gi::Kernel::Epanechnikov
                                                                                  : photon_gi::Kernel::Biweight;
  splat_.renormalize = p.renormalize;
  splat_.minGlossyRoughness = static_cast<float>(p.min_glossy_roughness);
  const FrameView& view = res.view();
  // gather_step is in output pixels: on a k-times supersampled frame the block is k gather_step
  // samples wide, so the gather costs what it costs at k = 1 and the block's light is still spread over
  // the pixel's own surface samples (the estimator's surface test), which is what the anti-aliasing needs.
  // Left out of the request, the step grows with the frame (api::photonGatherStep, which the cost model
  // charges too). The estimate is smooth over the smallest kernel, which a framed scene shows at a size
  // that grows with the frame: at 256 x 256 px step 4 costs 0.37 of step 2 at the same error, at 64 px it
  // would lose 1.8% of the light (docs/TECHNIQUES.md, photon_gi, gather_step).
  const int k = std::max(1, view.supersampling);
  const int gatherStep = api::photonGatherStep(p.gather_step, p.given.gather_step,
                                               view.width / k, view.height / k);
  splat_.gatherStep = gatherStep * k;
  // The denoiser (renderer/shading/Denoiser.h), guided by the estimator's relative noise: sqrt(int K^2)
  // / C' with C' the photons per kernel over pi, i.e. C, or C (photons / ppm_base)^(alpha / 2) on the
  // ppm schedule (docs/TECHNIQUES.md).
  denoise_ = p.denoise;
  // The filter's steps count output pixels (k, 2k, ...: Denoiser.h baseStep); left out of the request,
  // a supersampled frame filters with 2 passes (reach 6 output pixels on each side), one at k = 1 with
  // 3 (14): within 0.6% of the former 3 passes of 1, 2, 4 samples, or below, on the Cornell boxes at
  // 64-256 px (docs/PERFORMANCE.md, "Denoiser").
  denoiseSettings_.baseStep = k;
  denoiseSettings_.iterations = p.denoise_iterations;
  if (!p.given.denoise_iterations && k >= 2) denoiseSettings_.iterations = 2;
  const double kernelNoise = splat_.kernel == photon_gi::Kernel::Epanechnikov ? 0.651 : 0.757;
  double effectiveC = s.C;
  if (s.ppm) effectiveC *= std::pow(static_cast<double>(s.photons) / s.ppmBase, 0.5 * s.ppmAlpha);
  denoiseSettings_.relativeNoise = static_cast<float>(kernelNoise / effectiveC);
  if (denoise_) denoise::declareResources(res);
  // --- Photon records: derived data of the scene, its lights and environment, never of the camera.
  const rt::RayScene& rays = sharedRayScene(res, scene);
  std::string emissionKey;
  const auto emission = photonEnvironmentDistribution(res, view, s.environmentLightPhotons, emissionKey);
  lightPhotonWeight_ = emissionKey == view.environmentKey ? 1.f : s.environmentLightPhotons;
  const nlohmann::json photonKey = {{"scene", res.sceneKey()},
                                    {"ambient", {view.ambient.x, view.ambient.y, view.ambient.z}},
                                    {"environment", emissionKey},
                                    {"seed", view.seed},
                                    {"max_bounces", s.maxBounces}};
  PhotonCache& cache = res.cached<PhotonCache>("photon_gi_photons", photonKey.dump(),
                                               [] { return std::make_unique<PhotonCache>(); });
  const rt::SceneLights lights(rays, view.environment, view.ambient, emission);
  traced_ = 0;
  traceMs_ = 0.0;
  recordsReleased_ = false;
  // The records of the first s.photons photons, traced when a splat grid is built from them (not when
  // the grid is cached and resident: the records may have been released to keep memory under its
  // target, below). The memory accountant (FrameResources::makeRoom, admit) comes first: the new
  // records (appended in waves: held once) and the splats sorted into the grid, at most one per record
  // (records per photon from this set so far, else 2; the Cornell box leaves 1.9, 55% of them
  // splatted). The grid and its buffer are charged when the splats are known, below.
  auto traceRecords = [&] {
    if (cache.set.emitted < s.photons) {
      const double recordsPerPhoton =
          cache.set.emitted > 0 ? std::max(1.0, double(cache.set.records.size()) / double(cache.set.emitted)) : 2.0;
      const auto bytes = static_cast<std::size_t>(
          recordsPerPhoton * double(s.photons - cache.set.emitted) * sizeof(rt::PhotonRecord) +
          recordsPerPhoton * double(s.photons) * sizeof(photon_gi::GpuSplat));
      res.makeRoom(bytes);
      res.admit(bytes, "/passes/photon_gi/photons");
      const auto t0 = Clock::now();
      rt::PhotonOptions o;
      o.maxBounces = s.maxBounces;
      o.seed = view.seed;
      o.cancel = res.cancel();  // a cancelled trace throws and leaves cache.set as it was (PhotonTracer.h)
      traced_ = s.photons - cache.set.emitted;
      rt::tracePhotons(rays, lights, o, s.photons, cache.set);
      traceMs_ = msSince(t0);
    }
    records_ = cache.set.recordsOfFirst(s.photons);
    capped_ = cache.set.capped;
  };

  // --- The splats: which records, their kernel radius per surface (eq. 3), coverage points.
  const bool ownsSky = res.owns("photon_gi", api::kPathSkyDE);
  // The sky's first hits of this class are shaded by the frame's sky lights (the residual's median cut,
  // with shadow maps, EnvironmentLights::skyLights) when the frame has them: the photons' estimate of
  // them had visibility only at the kernel's scale (contact shadows 1.3-2x the reference's light).
  // Their later bounces stay photons.
  const bool skyFirstHits = ownsSky && view.skyLights() == 0;
  // The glossy reflection of the sky (L(sky)GE) may belong to a prefiltered environment term in
  // `direct`, which comes first in the registry: then sky photons at their first hit are splatted with
  // the diffuse lobe only.
  const bool ownsSkyGlossy = res.owns("photon_gi", api::kPathSkyGE);
  // Light from a punctual light through metal or glass only (L(S|G)+) onto a diffuse surface is
  // LS+DE / LG+DE: when another technique owns those classes (light_volumes), such photons are not
  // splatted on surfaces that are not themselves metal or glass (docs/TECHNIQUES.md).
  const std::string narrowOwner = res.ownerOf(api::kPathLGDE);
  const bool leaveNarrowLobePaths = !narrowOwner.empty() && narrowOwner != "photon_gi";
  // Light from a punctual light that reached the surface through near-mirrors only (LS+D): the
  // caustics pass's when it owns LS+DE (its photons cover point, spot and directional lights; those
  // of emissive triangles and the sky stay here).
  const bool ownsCaustics = res.owns("photon_gi", api::kPathLSDE);
  const nlohmann::json splatKey = {{"photons", photonKey}, {"count", s.photons}, {"C", s.C}, {"sky", skyFirstHits},
                                   {"sky_glossy", ownsSkyGlossy}, {"leave_narrow_lobe_paths", leaveNarrowLobePaths},
                                   {"caustics", ownsCaustics},
                                   {"ppm", s.ppm}, {"alpha", s.ppmAlpha}, {"base", s.ppmBase},
                                   {"renormalize", splat_.renormalize},
                                   {"environment_lights", view.environmentLights && view.environmentLights->split()
                                                              ? view.lightingEnvironmentKey() : ""}};
  upload_ = false;
  rebuilt_ = false;
  buildMs_ = 0.0;
  auto buildSplats = [&] {
    upload_ = true;
    traceRecords();
    const auto t0 = Clock::now();
    auto c = std::make_unique<SplatCache>();
    c->records = records_;
    c->capped = capped_;
    // Splatted: photons with at least one earlier reflection (the paper's optimised mode: direct light
    // from punctual lights is the raster pass's), direct light from emissive triangles, which no raster
    // pass computes, and the sky's direct light when this pass owns it (the planner gives it to
    // photon_gi ahead of ambient_occlusion, whose visibility ends at its radius).
    auto splatted = [&](const rt::PhotonRecord& r) {
      const auto kind = lights.emitters()[r.light].kind;
      if (r.bounce >= 1 && (r.flags & rt::kPhotonNarrowLobePath) && leaveNarrowLobePaths &&
          kind == rt::SceneLights::Kind::Punctual && !rays.materialOf(r.mesh).scattersNarrowLobe())
        return false;
      if (r.bounce >= 1)
        return ownsCaustics || !(r.flags & rt::kPhotonSpecularChain) || kind == rt::SceneLights::Kind::Triangle ||
               kind == rt::SceneLights::Kind::Environment;
      return kind == rt::SceneLights::Kind::Triangle || (kind == rt::SceneLights::Kind::Environment && skyFirstHits);
    };
    std::vector<double> count(scene.meshes.size(), 0.0), area(scene.meshes.size(), 0.0);
    for (std::size_t i = 0; i < records_; ++i)
      if (splatted(cache.set.records[i])) count[cache.set.records[i].mesh] += 1.0;
    std::vector<float> h(scene.meshes.size(), 0.f);
    for (std::size_t m = 0; m < scene.meshes.size(); ++m) {
      area[m] = photon_gi::meshArea(scene.meshes[m]);
      h[m] = kernelRadius(s.C, area[m], count[m], s.ppm, double(s.photons), s.ppmBase, s.ppmAlpha);
      if (h[m] > 0.f) {
        c->hMin = c->hMin == 0.f ? h[m] : std::min(c->hMin, h[m]);
        c->hMax = std::max(c->hMax, h[m]);
      }
    }
    std::vector<photon_gi::GpuSplat> out;
    out.reserve(records_);
    const float invPhotons = 1.f / static_cast<float>(s.photons);
    for (std::size_t i = 0; i < records_; ++i) {
      const rt::PhotonRecord& r = cache.set.records[i];
      if (!splatted(r) || !(h[r.mesh] > 0.f)) continue;
      const glm::vec3 wi = r.wi();
      const bool diffuseOnly = r.bounce == 0 && !ownsSkyGlossy &&
                               lights.emitters()[r.light].kind == rt::SceneLights::Kind::Environment;
      // The sky's first hits carry only the residual's light: the environment's lights are `direct`'s,
      // with shadow maps (renderer/shading/EnvironmentLights.h); later bounces carry the whole map.
      const float share = r.bounce == 0 && view.environmentLights && view.environment &&
                                  lights.emitters()[r.light].kind == rt::SceneLights::Kind::Environment
                              ? view.environmentLights->residualShare(*view.environment, wi)
                              : 1.f;
      if (!(share > 0.f)) continue;
      out.push_back(photon_gi::photonSplat(r.position, h[r.mesh], r.normal(), wi, r.flux * (invPhotons * share), diffuseOnly));
    }
    c->photonSplats = out.size();
    if (splat_.renormalize)
      for (std::size_t m = 0; m < scene.meshes.size(); ++m) {
        if (!(h[m] > 0.f)) continue;
        const double kernels = area[m] / (rt::kPi * double(h[m]) * h[m]);
        photon_gi::appendCoveragePoints(
            scene.meshes[m],
            std::clamp<std::size_t>(static_cast<std::size_t>(std::ceil(kCoveragePerKernel * kernels)), 16,
                                    kMaxCoveragePerSurface),
            h[m], out);
      }
    c->coveragePoints = out.size() - c->photonSplats;
    // The records are not needed again this frame. Resident beside the grid being built and its buffer,
    // they made the peak (4M photons on the Cornell box: 351 MiB of records beside twice 232 MiB of
    // splats): when those two would take the process over its memory target, they go first, and a
    // later frame that must rebuild the grid (another C, the buffer taken by another scene) traces
    // them again.
    const std::size_t gridBytes = 2 * out.size() * sizeof(photon_gi::GpuSplat);
    res.makeRoom(gridBytes);
    const std::size_t resident = FrameResources::residentBytes();
    if (resident > 0 && resident + gridBytes > res.memoryTarget()) {
      cache.set = rt::PhotonSet{};
      recordsReleased_ = true;
    }
    res.admit(gridBytes, "/passes/photon_gi/photons");
    c->grid = photon_gi::buildSplatGrid(std::move(out));
    buildMs_ = msSince(t0);
    return c;
  };
  const std::string splatDigest = splatKey.dump();
  SplatCache& splats = res.cached<SplatCache>("photon_gi_splats", splatDigest, buildSplats);
  // A hit whose set is not the one in the splat buffers (another scene was rendered since, or the
  // resources were dropped after a failure; FrameResources::refill): without this the frame gathered
  // the other scene's photons (Fox after BoxTextured came out unlit, 2026-12-02).
  FrameResources::Refill resident = res.refill("photon_gi_splats", splatDigest, "photon_gi_splats_resident");
  if (!resident.hit()) upload_ = true;
  if (upload_ && splats.grid.splats.size() != splats.grid.count) {
    splats = std::move(*buildSplats());
    rebuilt_ = true;
  }
  grid_ = &splats.grid;
  records_ = splats.records;
  capped_ = splats.capped;
  photonSplats_ = splats.photonSplats;
  coveragePoints_ = splats.coveragePoints;
  hMin_ = splats.hMin;
  hMax_ = splats.hMax;
  photon_gi::declareSplatResources(res, *grid_, splat_, upload_);
  splatBufferBytes_ = res.buffer("photon_gi_splats").size();
  splatDigest_ = splatDigest;
  // Uploaded here, not in execute(), and published: specular, earlier in the frame, shades its distance
  // maps' diffuse texels from the same splats (the path L D+ D S+ E, docs/TECHNIQUES.md).
  if (upload_) {
    photon_gi::uploadSplatGrid(res, *grid_);
    // The GPU holds the splats now: the CPU copy would double the memory of every cached photon set. A
    // lost GL context clears the cache entry too (FrameResources::clear), so it is rebuilt, not re-uploaded.
    std::vector<photon_gi::GpuSplat>().swap(grid_->splats);
    resident.written();
  }
  PhotonGrid published;
  published.digest = splatDigest_ + "|kernel=" + std::to_string(static_cast<int>(splat_.kernel));
  published.count = grid_->count;
  published.origin = grid_->origin;
  published.cellSize = grid_->cellSize;
  published.walkReach = grid_->walkReach;
  published.dims = grid_->dims;
  published.maxPerCell = grid_->maxPerCell;
  published.kernel = static_cast<int>(splat_.kernel);
  published.minRadius = hMin_;
  published.renormalize = splat_.renormalize;
  published.splats = &res.buffer("photon_gi_splats");
  published.cells = &res.buffer("photon_gi_cells");
  publishPhotonGrid(res, published);
}

void PhotonGiPass::execute(PassContext& ctx) {
  // The receivers' layered BSDF reads the sheen directional-albedo table (common/brdf.glsl).
  ctx.gpu.sheenAlbedo.bindBase(GL_SHADER_STORAGE_BUFFER, gpu::kBindingSheenAlbedo);
  // prepare() uploaded the grid.
  if (grid_->count == 0) {
    // No photon to estimate from (a lone convex object under a map whose first hits the sky lights
    // shade: no later bounce lands): indirect is 0. Gathering nothing cost a full-resolution fix-up
    // cascade (BoxTextured: 90 ms of a 270 ms frame on llvmpipe).
    const float zero[4] = {0.f, 0.f, 0.f, 0.f};
    glClearTexImage(ctx.resources.texture("indirect").id(), 0, GL_RGBA, GL_FLOAT, zero);
    ctx.resources.markWritten("indirect");
  } else if (denoise_) {
    // The noisy estimate into indirect, filtered, then the filtered image into indirect and beauty.
    photon_gi::splatAndResolve(ctx.resources, ctx.shaders, ctx.view, splat_, *grid_, false, false);
    const gl::Texture& clean =
        denoise::run(ctx.resources, ctx.shaders, ctx.view, ctx.resources.texture("indirect"), denoiseSettings_);
    photon_gi::resolve(ctx.resources, ctx.shaders, ctx.view, clean, false, true);
  } else {
    photon_gi::splatAndResolve(ctx.resources, ctx.shaders, ctx.view, splat_, *grid_, false, true);
  }
  auto& c = ctx.stats.counters;
  c["photons"] = static_cast<double>(settings_.photons);
  c["photons_traced"] = static_cast<double>(traced_);
  c["photons_cached"] = traced_ == 0 ? 1.0 : 0.0;
  // The records were released after the grid was built, to stay under --memory-target-bytes.
  c["records_released"] = recordsReleased_ ? 1.0 : 0.0;
  c["trace_ms"] = traceMs_;
  c["splat_build_ms"] = buildMs_;
  c["records"] = static_cast<double>(records_);
  // Photons of the cached set that max_bounces ended while Russian roulette would have let them go on.
  c["photons_capped"] = static_cast<double>(capped_);
  c["photon_splats"] = static_cast<double>(photonSplats_);
  c["coverage_points"] = static_cast<double>(coveragePoints_);
  c["bytes_per_photon"] =
      settings_.photons ? double(records_ * sizeof(rt::PhotonRecord)) / double(settings_.photons) : 0.0;
  c["splat_bytes"] = static_cast<double>(grid_->count * sizeof(photon_gi::GpuSplat));
  c["splat_buffer_bytes"] = static_cast<double>(splatBufferBytes_);
  // The gather grid (Splatting.h buildSplatGrid): its cell, and the wide kernels' copies in other cells.
  c["grid_cell_size"] = grid_->cellSize;
  c["grid_copies"] = static_cast<double>(grid_->count - grid_->originals);
  c["splats_uploaded"] = upload_ ? 1.0 : 0.0;
  c["splats_rebuilt"] = rebuilt_ ? 1.0 : 0.0;
  c["h_min"] = hMin_;
  c["h_max"] = hMax_;
  c["C"] = settings_.C;
  c["denoise_iterations"] = denoise_ ? denoiseSettings_.iterations : 0;
  c["denoise_base_step"] = denoise_ ? denoiseSettings_.baseStep : 0;  // the first pass's step, in the frame's samples
  c["denoise_relative_noise"] = denoiseSettings_.relativeNoise;
  c["environment_light_photons"] = lightPhotonWeight_;  // 1: sky photons drawn by the map itself
  c["gather"] = splat_.method == photon_gi::Method::Gather ? 1.0 : 0.0;
  c["gather_step"] = splat_.method == photon_gi::Method::Gather ? splat_.gatherStep : 1;
  upload_ = false;
}

}  // namespace radiant
