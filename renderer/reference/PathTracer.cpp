#include "renderer/reference/PathTracer.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "renderer/raytracing/CameraRays.h"
#include "renderer/raytracing/Lights.h"
#include "renderer/raytracing/RayScene.h"
#include "renderer/raytracing/Threads.h"
#include "renderer/raytracing/VolumeInterior.h"

namespace radiant::reference {
namespace {

using namespace radiant::rt;

constexpr int kTileSize = 16;
// Samples of one pixel between two polls of the cancel flag: tens of microseconds of work each.
constexpr int kCancelPollSamples = 16;
constexpr int kRussianRouletteStart = 3;

}  // namespace

struct PathTracer::Impl {
  std::unique_ptr<RayScene> owned;  // when constructed from a Scene
  const RayScene* rays = nullptr;
  mutable std::atomic<std::uint64_t> lastRays{0};
  mutable std::atomic<std::uint64_t> lastCapped{0};

  bool inRange(int k, const ReferenceOptions& o) const { return k >= o.minPathBounce && k <= o.maxPathBounce; }

  // Direct light at a scattering vertex by next-event estimation (k = the vertex's bounce count).
  // `interior`: the KHR_materials_volume medium of the path; a light segment is attenuated by the medium
  // its direction enters (VolumeInterior::towards), so a light inside an absorbing solid dims.
  glm::vec3 estimateDirect(const SurfaceHit& hit, const Shading& sh, const glm::vec3& woL, const SceneLights& lights,
                           const VolumeInterior& interior, Sampler& sampler, RayCounter& counter) const {
    const RayScene& rs = *rays;
    glm::vec3 L(0.f);
    auto visible = [&](const glm::vec3& wi, const glm::vec3& wiL) {
      // The direction must be on the side of the geometric surface that the lobe (reflection or
      // transmission) expects, or light leaks through shading-normal tricks.
      const float gs = glm::dot(wi, sh.ngFacing);
      return wiL.z > 0.f ? gs > 0.f : gs < 0.f;
    };

    // Punctual lights (KHR_lights_punctual), all of them every vertex.
    for (const Light& light : rs.scene().lights) {
      glm::vec3 wi, Li;
      float dist;
      if (!punctualLi(light, hit.p, wi, dist, Li)) continue;
      const glm::vec3 wiL = sh.frame.toLocal(wi);
      if (!visible(wi, wiL)) continue;
      const glm::vec3 f = sh.bsdf.eval(woL, wiL);
      if (maxComponent(f) <= 0.f) continue;
      Ray shadow{RayScene::offsetOrigin(hit.p, hit.ng, hit.offsetScale, wi), wi, 0.f, dist};
      if (dist != kInf) {
        const glm::vec3 d = light.position - shadow.org;
        shadow.tfar = glm::length(d);
        shadow.dir = d / shadow.tfar;
      }
      if (rs.occluded(shadow, sampler, counter)) continue;
      L += f * std::abs(wiL.z) * Li * interior.towards(rs, hit, wi).transmittance(dist);
    }

    // One emissive triangle, chosen in proportion to power, sampled uniformly by area; MIS with the BSDF.
    if (lights.hasTriangles()) {
      const float uSel = sampler.next();
      const glm::vec2 uTri = sampler.next2();
      SurfaceHit lh;
      float pSelect = 0.f;
      if (lights.sampleTriangle(uSel, uTri, lh, pSelect)) {
        const TriangleLight& tl = rs.triangleLights()[rs.emissiveOffset(lh.mesh) + lh.prim];
        const glm::vec3 d = lh.p - hit.p;
        const float d2 = glm::dot(d, d);
        if (d2 > 0.f) {
          const float dist = std::sqrt(d2);
          const glm::vec3 wi = d / dist;
          const float cosL = std::abs(glm::dot(lh.ng, wi));
          const glm::vec3 Le = rs.emissionAt(lh, wi);
          const glm::vec3 wiL = sh.frame.toLocal(wi);
          if (cosL > 0.f && maxComponent(Le) > 0.f && visible(wi, wiL)) {
            const float lightPdf = pSelect * d2 / (tl.area * cosL);  // area -> solid angle
            const glm::vec3 f = sh.bsdf.eval(woL, wiL);
            if (maxComponent(f) > 0.f) {
              Ray shadow;
              shadow.org = RayScene::offsetOrigin(hit.p, hit.ng, hit.offsetScale, wi);
              const glm::vec3 targetP = RayScene::offsetOrigin(lh.p, lh.ng, lh.offsetScale, -wi);
              const glm::vec3 sd = targetP - shadow.org;
              shadow.tfar = glm::length(sd);
              if (shadow.tfar > 0.f) {
                shadow.dir = sd / shadow.tfar;
                if (!rs.occluded(shadow, sampler, counter)) {
                  const float w = powerHeuristic(lightPdf, sh.bsdf.pdf(woL, wiL));
                  L += f * std::abs(wiL.z) * Le * interior.towards(rs, hit, wi).transmittance(dist) * (w / lightPdf);
                }
              }
            }
          }
        }
      }
    }

    // The environment, importance sampled; MIS with the BSDF.
    const EnvironmentLight& env = lights.environment();
    if (env.active()) {
      float envPdf = 0.f;
      const glm::vec3 wi = env.sample(sampler.next2(), envPdf);
      const glm::vec3 wiL = sh.frame.toLocal(wi);
      if (envPdf > 0.f && visible(wi, wiL)) {
        const glm::vec3 f = sh.bsdf.eval(woL, wiL);
        const glm::vec3 Le = env.radiance(wi);
        if (maxComponent(f) > 0.f && maxComponent(Le) > 0.f) {
          Ray shadow{RayScene::offsetOrigin(hit.p, hit.ng, hit.offsetScale, wi), wi, 0.f, kInf};
          if (!rs.occluded(shadow, sampler, counter)) {
            const float w = powerHeuristic(envPdf, sh.bsdf.pdf(woL, wiL));
            L += f * std::abs(wiL.z) * Le * interior.towards(rs, hit, wi).transmittance(kInf) * (w / envPdf);
          }
        }
      }
    }
    return L;
  }

  glm::vec3 radiance(Ray ray, const ReferenceOptions& o, const SceneLights& lights, Sampler& sampler,
                     RayCounter& counter) const {
    const EnvironmentLight& env = lights.environment();
    glm::vec3 L(0.f), beta(1.f);
    float etaScale = 1.f;  // product of eta^2 over refractions: keeps Russian roulette blind to the
                           // radiance scaling at interfaces (pbrt-v4 14.1.4)
    int k = 0;  // scattering events so far
    bool prevDelta = true;  // the camera "sampled" this direction: no MIS on directly seen emitters
    float prevPdf = 0.f;
    // L S+ D E bookkeeping (ReferenceOptions::excludeCaustics): true while the first vertex scattered
    // through a non-delta lobe and every later vertex through a delta lobe.
    bool causticChain = false;
    VolumeInterior interior;  // KHR_materials_volume: the absorbing medium the path travels in
    const int lastVertex = std::min(o.maxBounces, o.maxPathBounce);
    for (;;) {
      SurfaceHit hit;
      const bool found = rays->intersect(ray, hit, sampler, counter);
      // Beer-Lambert over the segment just travelled (an escape from inside an open mesh: infinite).
      if (interior.absorbs()) beta *= interior.transmittance(found ? hit.distance : kInf);
      if (!found) {
        if (env.active() && inRange(k, o) && !(o.excludeCaustics && causticChain && k >= 2)) {
          const float w = prevDelta ? 1.f : powerHeuristic(prevPdf, env.pdf(ray.dir));
          L += beta * env.radiance(ray.dir) * w;
        }
        break;
      }
      const Material& mat = rays->materialOf(hit.mesh);
      if (mat.unlit) {  // KHR_materials_unlit: the base colour leaves the surface, nothing scatters
        if (inRange(k, o)) L += beta * rays->unlitRadiance(hit);
        break;
      }
      if (inRange(k, o) && !(o.excludeCaustics && causticChain && k >= 2)) {
        const glm::vec3 Le = rays->emissionAt(hit, ray.dir);
        if (maxComponent(Le) > 0.f) {
          const float w = prevDelta ? 1.f : powerHeuristic(prevPdf, lights.trianglePdf(hit, ray.dir));
          L += beta * Le * w;
        }
      }
      if (k >= lastVertex) {
        if (k >= o.maxBounces) ++counter.capped;  // the cap, not the requested bounce range, ended it
        break;
      }
      ++k;

      const glm::vec3 wo = -ray.dir;
      const Shading sh = rays->shade(hit, wo);
      const glm::vec3 woL = sh.frame.toLocal(wo);
      if (inRange(k, o) && sh.bsdf.hasNonDeltaLobe(woL))
        L += beta * estimateDirect(hit, sh, woL, lights, interior, sampler, counter);

      const float uLobe = sampler.next(), uFresnel = sampler.next();
      const glm::vec2 uDir = sampler.next2();
      GltfBsdf::Sample bs;
      if (!sh.bsdf.sample(woL, uLobe, uFresnel, uDir, bs)) break;
      const glm::vec3 wi = sh.frame.toWorld(bs.wi);
      const float gs = glm::dot(wi, sh.ngFacing);
      if (bs.wi.z > 0.f ? gs <= 0.f : gs >= 0.f) break;  // leaked through the geometric surface
      beta *= bs.weight;
      causticChain = k == 1 ? !bs.delta : causticChain && bs.delta;
      if (bs.wi.z < 0.f) etaScale *= sh.bsdf.eta * sh.bsdf.eta;
      interior.scatter(*rays, hit, wi);
      prevDelta = bs.delta;
      prevPdf = bs.pdf;
      if (!(maxComponent(beta) > 0.f)) break;
      if (o.russianRoulette && k >= kRussianRouletteStart) {
        const float q = std::min(0.95f, maxComponent(beta) * etaScale);
        if (sampler.next() >= q) break;
        beta /= q;
      }
      ray = Ray{RayScene::offsetOrigin(hit.p, hit.ng, hit.offsetScale, wi), wi, 0.f, kInf};
    }
    return L;
  }

  float ambientOcclusion(const Ray& cameraRay, const ReferenceOptions& o, Sampler& sampler, RayCounter& counter) const {
    SurfaceHit hit;
    if (!rays->intersect(cameraRay, hit, sampler, counter)) return 1.f;
    const MeshInstance& m = rays->scene().meshes[hit.mesh];
    const glm::vec3 ngFacing = glm::dot(cameraRay.dir, hit.ng) < 0.f ? hit.ng : -hit.ng;
    glm::vec3 n = ngFacing;
    if (m.normals.size() == m.positions.size()) {
      const std::uint32_t* i = &m.indices[static_cast<size_t>(hit.prim) * 3];
      const glm::vec3 ni = hit.b0 * m.normals[i[0]] + hit.b1 * m.normals[i[1]] + hit.b2 * m.normals[i[2]];
      if (glm::dot(ni, ni) > 0.f) n = glm::normalize(ni);
      if (glm::dot(n, ngFacing) < 0.f) n = -n;
    }
    const ShadingFrame frame = ShadingFrame::fromNormal(n);
    const float R = o.aoRadius;
    const glm::vec2 u = sampler.next2();
    glm::vec3 wL;
    if (o.mode == ReferenceOptions::Mode::AoVolumetric) wL = sampleCosinePowerHemisphere(u, 3.f);
    else wL = sampleCosineHemisphere(u);
    if (wL.z <= 0.f) return 0.f;
    const glm::vec3 w = frame.toWorld(wL);
    if (glm::dot(w, ngFacing) <= 0.f) return 0.f;  // into the surface itself: occluded at distance 0
    // Ray length: R, or R cos(theta) for the tangent sphere (r <= R cos(theta)).
    const float length = o.mode == ReferenceOptions::Mode::AoVolumetric ? R * wL.z : R;
    Ray ray{RayScene::offsetOrigin(hit.p, hit.ng, hit.offsetScale, w), w, 0.f, length};
    switch (o.mode) {
      case ReferenceOptions::Mode::AoCosineStep:
        // eq. 4.2, step membership: estimator [d >= R] under p(w) = cos/pi.
        return rays->occluded(ray, sampler, counter) ? 0.f : 1.f;
      case ReferenceOptions::Mode::AoCubicFalloff: {
        // eq. 4.2 with mu(r) = min(1, (r/R)^3): estimator mu(d) under p(w) = cos/pi.
        SurfaceHit occ;
        if (!rays->intersect(ray, occ, sampler, counter)) return 1.f;
        const float r = std::min(occ.distance, R) / R;
        return r * r * r;
      }
      case ReferenceOptions::Mode::AoVolumetric: {
        // eq. 4.6: V = (2/pi) \int min(d/R, cos)^3 dw; with p(w) = 2 cos^3 / pi the estimator is
        // min(1, d / (R cos))^3: the visible fraction of the ray's chord through the tangent sphere, cubed.
        SurfaceHit occ;
        if (!rays->intersect(ray, occ, sampler, counter)) return 1.f;
        const float r = std::min(occ.distance, length) / length;
        return r * r * r;
      }
      default: return 0.f;
    }
  }

};

PathTracer::PathTracer(const Scene& scene) : impl_(std::make_unique<Impl>()) {
  impl_->owned = std::make_unique<RayScene>(scene);
  impl_->rays = impl_->owned.get();
}
PathTracer::PathTracer(const rt::RayScene& rays) : impl_(std::make_unique<Impl>()) { impl_->rays = &rays; }
PathTracer::~PathTracer() = default;
PathTracer::PathTracer(PathTracer&&) noexcept = default;
PathTracer& PathTracer::operator=(PathTracer&&) noexcept = default;

std::uint64_t PathTracer::raysTraced() const { return impl_->lastRays.load(); }
std::uint64_t PathTracer::pathsCapped() const { return impl_->lastCapped.load(); }

Image PathTracer::render(const Camera& camera, int width, int height, const ReferenceOptions& options) const {
  if (width <= 0 || height <= 0)
    throw std::invalid_argument("PathTracer::render(): image size " + std::to_string(width) + "x" +
                                std::to_string(height) + " is not positive");
  if (options.spp < 1) throw std::invalid_argument("PathTracer::render(): spp must be >= 1");
  if (options.mode != ReferenceOptions::Mode::Radiance && !(options.aoRadius > 0.f))
    throw std::invalid_argument("PathTracer::render(): aoRadius must be > 0");
  if (options.maxBounces < 0) throw std::invalid_argument("PathTracer::render(): maxBounces must be >= 0");

  const SceneLights lights(*impl_->rays, options.environment, options.skyRadiance, options.environmentDistribution);
  const char* aov = options.mode == ReferenceOptions::Mode::Radiance ? "beauty" : "ao";
  Image image = Image::make(aov, width, height, 3);
  const int tilesX = (width + kTileSize - 1) / kTileSize, tilesY = (height + kTileSize - 1) / kTileSize;
  std::atomic<std::uint64_t> rays{0}, capped{0};
  std::atomic<int> tilesDone{0};
  const Impl& impl = *impl_;
  const CameraRays cameraRays(camera, width, height);

  auto renderTiles = [&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, tilesX * tilesY, 1), [&](const tbb::blocked_range<int>& range) {
      RayCounter counter;
      for (int tile = range.begin(); tile != range.end(); ++tile) {
        const int x0 = (tile % tilesX) * kTileSize, y0 = (tile / tilesX) * kTileSize;
        const int x1 = std::min(width, x0 + kTileSize), y1 = std::min(height, y0 + kTileSize);
        for (int y = y0; y < y1; ++y)
          for (int x = x0; x < x1; ++x) {
            const std::uint64_t pixel = static_cast<std::uint64_t>(y) * width + x;
            glm::dvec3 sum(0.0);
            for (int s = 0; s < options.spp; ++s) {
              if (s % kCancelPollSamples == 0) options.cancel.check("the reference path tracer's tiles");
              Sampler sampler(pixel, static_cast<std::uint64_t>(s), options.seed);
              const glm::vec2 jitter = sampler.next2();
              const Ray ray = cameraRays.ray(x + jitter.x, y + jitter.y);
              glm::vec3 value;
              if (options.mode == ReferenceOptions::Mode::Radiance)
                value = impl.radiance(ray, options, lights, sampler, counter);
              else
                value = glm::vec3(impl.ambientOcclusion(ray, options, sampler, counter));
              // A non-finite sample would poison the pixel; it can only come from degenerate input.
              if (std::isfinite(value.x) && std::isfinite(value.y) && std::isfinite(value.z))
                sum += glm::dvec3(value);
            }
            float* out = image.at(x, y);
            const glm::dvec3 mean = sum / static_cast<double>(options.spp);
            out[0] = static_cast<float>(mean.x);
            out[1] = static_cast<float>(mean.y);
            out[2] = static_cast<float>(mean.z);
          }
        if (options.progress) options.progress(static_cast<double>(++tilesDone) / (tilesX * tilesY));
      }
      rays += counter.rays;
      capped += counter.capped;
    });
  };
  rt::withThreads(options.threads, renderTiles);
  impl_->lastRays = rays.load();
  impl_->lastCapped = capped.load();
  return image;
}

}  // namespace radiant::reference
