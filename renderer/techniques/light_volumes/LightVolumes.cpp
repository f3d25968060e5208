#include "renderer/techniques/light_volumes/LightVolumes.h"
#include "params/light_volumes_params.h"

#include <algorithm>
#include <chrono>

#include <glm/gtc/type_ptr.hpp>
#include <nlohmann/json.hpp>

#include "api/Presets.h"
#include "renderer/frame/Beauty.h"
#include "renderer/frame/PassContext.h"
#include "renderer/frame/RayScenes.h"
#include "renderer/shading/GBufferInputs.h"

namespace radiant {
namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

// Beams per dispatch of the linear traversal (llvmpipe's loop limit is 65535 iterations).
constexpr int kLinearSlice = 16384;
constexpr std::size_t kReportedScatterers = 16;
constexpr GLuint kBindingBeams = 8, kBindingCones = 9, kBindingNodes = 10, kBindingPrims = 11;

bool hasScatterer(const Scene& scene) {
  for (const MeshInstance& m : scene.meshes)
    if (scene.material(m.material).scattersNarrowLobe() && m.triangleCount() > 0) return true;
  return false;
}

nlohmann::json lightsKey(const Scene& scene) {
  nlohmann::json j = nlohmann::json::array();
  for (const Light& l : scene.lights)
    j.push_back({static_cast<int>(l.type), l.position.x, l.position.y, l.position.z, l.direction.x, l.direction.y,
                 l.direction.z, l.color.x, l.color.y, l.color.z, l.intensity, l.range, l.innerConeAngle,
                 l.outerConeAngle});
  return j;
}

template <class T>
std::size_t bytesOf(const std::vector<T>& v) { return std::max<std::size_t>(1, v.size()) * sizeof(T); }

}  // namespace

// Declared in light_volumes.json. Not on by default: on coarse glossy meshes (the Glosbox's block) the
// tessellation fallback gives sharp specular beams where photon_gi, which owns LG+DE paths otherwise,
// gets the blur right.
const TechniqueInfo& LightVolumesPass::info() const {
  static const TechniqueInfo i = describedTechnique("light_volumes");
  return i;
}

Requirements LightVolumesPass::requirements(const Scene& scene, const api::RenderRequest&) const {
  if (scene.lights.empty()) return Requirements::skip("the scene has no point, spot or directional light");
  if (!hasScatterer(scene))
    return Requirements::skip("no specular or glossy scatterer (metal or glass with roughness <= 0.5)");
  return Requirements::ok();
}

void LightVolumesPass::addCostCounts(const Scene& scene, api::SceneCounts& counts) const {
  counts.beams = light_volumes::beamCountBound(scene);
}

std::vector<int> LightVolumesPass::shadowMapExclusions(const Scene& scene, const Params& params) const {
  const LightVolumesParams p = LightVolumesParams::from(params);
  // Negative beams are the scatterers' first-order shadows: the shadow maps must not add theirs too
  // (notes A7).
  std::vector<int> out;
  if (p.shadows != LightVolumesParams::Shadows::kNegativeBeams) return out;
  for (std::size_t m = 0; m < scene.meshes.size(); ++m)
    if (scene.material(scene.meshes[m].material).scattersNarrowLobe()) out.push_back(static_cast<int>(m));
  return out;
}

void LightVolumesPass::prepare(const Scene& scene, const Params& params, FrameResources& res) {
  const LightVolumesParams p = LightVolumesParams::from(params);
  light_volumes::BeamOptions o;
  o.sigmaScale = static_cast<float>(p.sigma_scale);
  o.negativeBeams = p.shadows == LightVolumesParams::Shadows::kNegativeBeams;
  o.maxConcentration = static_cast<float>(p.max_concentration);
  o.maxTriangleSigma = static_cast<float>(p.max_triangle_sigma);
  o.specularFallback = p.tessellation_fallback == LightVolumesParams::TessellationFallback::kSpecular;
  o.cullSigmas = static_cast<float>(p.cull_sigmas);
  o.maxSubdivisionBeams = static_cast<std::size_t>(std::max(0, p.max_subdivision_beams));
  o.cancel = res.cancel();
  split_ = p.split == LightVolumesParams::Split::kPaper ? light_volumes::Split::Paper : light_volumes::Split::TwoD;
  bvh_ = p.traversal == LightVolumesParams::Traversal::kBvh;
  // Every light path is counted once: beauty takes the beams of the classes this pass owns (specular
  // scatterers' LS+DE, glossy ones' LG+DE; caustics or photon_gi may own LS+DE while this pass, planned
  // for its AOV, owns LG+DE) and every shadow beam (the scatterers' shadows, which the shadow maps leave
  // out); the AOV holds every beam.
  beautyClasses_ = (res.owns("light_volumes", api::kPathLSDE) ? light_volumes::glsl::kLvClassSpecular : 0) |
                   (res.owns("light_volumes", api::kPathLGDE) ? light_volumes::glsl::kLvClassGlossy : 0);

  const nlohmann::json key = {{"scene", res.sceneKey()},
                              {"lights", lightsKey(scene)},
                              {"params", cacheKey(p.sigma_scale, p.shadows, p.max_concentration, p.max_triangle_sigma,
                                                  p.tessellation_fallback, p.cull_sigmas, p.max_subdivision_beams)}};
  built_ = false;
  const Cache& cache = res.cached<Cache>("light_volumes_beams", key.dump(), [&] {
    built_ = true;
    auto c = std::make_unique<Cache>();
    auto t0 = Clock::now();
    const rt::RayScene& rays = sharedRayScene(res, scene);
    const float eps = 1e-4f * std::max(scene.features.bounds.radius(), 1e-6f);
    auto receiverDistance = [&](const glm::vec3& origin, const glm::vec3& dir) {
      rt::Sampler sampler(0, 0, 0);
      rt::RayCounter counter;
      rt::SurfaceHit hit;
      const rt::Ray ray{origin + eps * dir, dir, 0.f, rt::kInf};
      return rays.intersect(ray, hit, sampler, counter) ? hit.distance + eps : -1.f;
    };
    c->beams = light_volumes::buildBeams(scene, o, receiverDistance);
    c->setupMs = msSince(t0);
    t0 = Clock::now();
    c->bvh = light_volumes::buildBeamBvh(c->beams.beams, c->beams.cones, scene.features.bounds, res.cancel());
    c->bvhMs = msSince(t0);
    return c;
  });
  cache_ = &cache;
  res.buffer("light_volumes_beams", bytesOf(cache.beams.beams));
  res.buffer("light_volumes_cones", bytesOf(cache.beams.cones));
  res.buffer("light_volumes_nodes", bytesOf(cache.bvh.nodes));
  res.buffer("light_volumes_prims", bytesOf(cache.bvh.primitives));
  // The buffers hold the beams last uploaded, maybe another scene's (FrameResources::refill).
  uploaded_ = res.refill("light_volumes_beams", key.dump(), "light_volumes_upload");
  // Declared outputs: allocated by the Renderer (renderer/frame/FrameAllocation.h).
  res.texture("light_volumes").setFilter(GL_NEAREST, GL_NEAREST);
}

void LightVolumesPass::execute(PassContext& ctx) {
  FrameResources& res = ctx.resources;
  const Cache& c = *cache_;
  gl::Buffer& beams = res.buffer("light_volumes_beams");
  gl::Buffer& cones = res.buffer("light_volumes_cones");
  gl::Buffer& nodes = res.buffer("light_volumes_nodes");
  gl::Buffer& prims = res.buffer("light_volumes_prims");
  if (!uploaded_.hit()) {
    if (!c.beams.beams.empty()) beams.upload(c.beams.beams.data(), c.beams.beams.size() * sizeof(light_volumes::Beam));
    if (!c.beams.cones.empty()) cones.upload(c.beams.cones.data(), c.beams.cones.size() * sizeof(light_volumes::BeamCone));
    if (!c.bvh.nodes.empty()) nodes.upload(c.bvh.nodes.data(), c.bvh.nodes.size() * sizeof(light_volumes::BeamBvhNode));
    if (!c.bvh.primitives.empty()) prims.upload(c.bvh.primitives.data(), c.bvh.primitives.size() * sizeof(glm::vec4));
    uploaded_.written();
  }
  using gbuffer::Attachment;
  gbuffer::bind(res, {Attachment::Position, Attachment::Normal, Attachment::Albedo, Attachment::Material,
                      Attachment::Emission});
  beams.bindBase(GL_SHADER_STORAGE_BUFFER, kBindingBeams);
  cones.bindBase(GL_SHADER_STORAGE_BUFFER, kBindingCones);
  nodes.bindBase(GL_SHADER_STORAGE_BUFFER, kBindingNodes);
  prims.bindBase(GL_SHADER_STORAGE_BUFFER, kBindingPrims);
  gl::Texture& out = res.texture("light_volumes");
  out.bindImage(0, GL_READ_WRITE);
  BeautyWrite beauty = BeautyWrite::image(res, 1);

  const FrameView& view = ctx.view;
  const gl::Program& prog = ctx.shaders.program({"light_volumes/gather.comp"});
  prog.use();
  const int size[2] = {view.width, view.height};
  glUniform2iv(glGetUniformLocation(prog.id(), "u_size"), 1, size);
  prog.set("u_split", static_cast<int>(split_));
  prog.set("u_narrowLobeRoughness", Material::kNarrowLobeRoughness);
  prog.set("u_traversal", bvh_ ? 1 : 0);
  // One dispatch per slice (linear) or group (bvh); at least one, which clears the AOV.
  std::vector<std::pair<int, int>> work;  // linear: [begin, end); bvh: (root, 0)
  const int count = static_cast<int>(c.beams.beams.size());
  prog.set("u_beautyClasses", beautyClasses_);
  if (bvh_) {
    for (int root : c.bvh.roots)
      if (root >= 0) work.push_back({root, 0});
  } else {
    for (int b = 0; b < count; b += kLinearSlice) work.push_back({b, std::min(count, b + kLinearSlice)});
  }
  if (work.empty()) work.push_back(bvh_ ? std::pair{-1, 0} : std::pair{0, 0});
  for (std::size_t k = 0; k < work.size(); ++k) {
    // One slice or BVH group per stretch of GPU work, a cancel check between them.
    if (k > 0) ctx.cancel.check("light_volumes' gather, stretch " + std::to_string(k) + " of " + std::to_string(work.size()));
    if (bvh_) prog.set("u_root", work[k].first);
    else {
      prog.set("u_begin", work[k].first);
      prog.set("u_end", work[k].second);
    }
    prog.set("u_accumulate", k > 0 ? 1 : 0);
    prog.set("u_addToBeauty", 1);
    glDispatchCompute((view.width + 7) / 8, (view.height + 7) / 8, 1);
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
  }
  glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_FRAMEBUFFER_BARRIER_BIT);
  beauty.commit();
  res.markWritten("light_volumes");

  auto& s = ctx.stats.counters;
  const auto& b = c.beams;
  s["beams"] = static_cast<double>(b.beams.size());
  s["beams_scattered"] = static_cast<double>(b.scattered);
  s["beams_shadow"] = static_cast<double>(b.shadow);
  s["beams_glossy"] = static_cast<double>(b.glossy);
  s["triangles_backfacing"] = static_cast<double>(b.backfacing);
  s["beams_tir_dropped"] = static_cast<double>(b.tirDropped);
  s["triangles_degenerate"] = static_cast<double>(b.degenerate);
  s["beams_volume_attenuated"] = static_cast<double>(b.volumeAttenuated);
  s["tessellation_checked"] = static_cast<double>(b.tessellationChecked);
  s["tessellation_failed"] = static_cast<double>(b.tessellationFailed);
  s["tessellation_worst_triangle_sigma"] = b.worstTriangleSigma;
  s["tessellation_specular_fallbacks"] = static_cast<double>(b.specularFallbacks);
  s["subdivision_scatterers"] = static_cast<double>(b.subdividedScatterers);
  s["subdivision_beams_split"] = static_cast<double>(b.subdividedBeams);
  s["subdivision_beams_added"] = static_cast<double>(b.subdivisionBeamsAdded);
  s["subdivision_still_failing"] = static_cast<double>(b.subdivisionStillFailing);
  s["subdivision_budget_exhausted"] = static_cast<double>(b.subdivisionBudgetExhausted);
  // The condition per scatterer, "tessellation/<mesh index>:<mesh name>/light<index>/...", for the
  // first kReportedScatterers (the totals above count them all).
  for (std::size_t k = 0; k < std::min(b.scatterers.size(), kReportedScatterers); ++k) {
    const auto& r = b.scatterers[k];
    const std::string key = "tessellation/" + std::to_string(r.mesh) + ":" + r.meshName + "/light" +
                            std::to_string(r.light) + "/";
    s[key + "checked"] = static_cast<double>(r.checked);
    s[key + "failed"] = static_cast<double>(r.failed);
    s[key + "worst_triangle_sigma"] = r.worstTriangleSigma;
    s[key + "specular_fallback"] = r.specularFallback ? 1.0 : 0.0;
    s[key + "subdivided_beams"] = static_cast<double>(r.subdividedBeams);
    s[key + "beams_added"] = static_cast<double>(r.beamsAdded);
    s[key + "budget_exhausted"] = r.budgetExhausted ? 1.0 : 0.0;
  }
  s["beam_flux"] = b.flux.x + b.flux.y + b.flux.z;
  s["setup_ms"] = built_ ? c.setupMs : 0.0;
  s["bvh_ms"] = built_ ? c.bvhMs : 0.0;
  s["beams_cached"] = built_ ? 0.0 : 1.0;
  s["bvh_nodes"] = static_cast<double>(c.bvh.nodes.size());
  s["bvh_segments"] = static_cast<double>(c.bvh.primitives.size());
  s["bvh_depth"] = c.bvh.depth;
  s["traversal_bvh"] = bvh_ ? 1.0 : 0.0;
  s["dispatches"] = static_cast<double>(work.size());
  // Its classes in beauty: 1 LS+DE, 2 LG+DE, 3 both (shadow beams always).
  s["owns_light_paths"] = beautyClasses_ != 0 ? 1.0 : 0.0;
  s["beauty_classes"] = beautyClasses_;
}

}  // namespace radiant
