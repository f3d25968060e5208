#include "renderer/reference/VolumeTracer.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "renderer/raytracing/CameraRays.h"
#include "renderer/raytracing/Lights.h"
#include "renderer/raytracing/Media.h"
#include "renderer/raytracing/ParticleMedium.h"
#include "renderer/raytracing/RayScene.h"
#include "renderer/raytracing/Threads.h"

namespace radiant::reference {

using rt::Chord;
using rt::MediumParticle;
using rt::Ray;
using rt::RayCounter;
using rt::Sampler;

const char* toString(MediaMode m) {
  switch (m) {
    case MediaMode::EmissionAbsorption: return "emission_absorption";
    case MediaMode::SingleScatter: return "single_scatter";
    case MediaMode::Full: return "full";
    default: return "single_scatter_unshadowed";
  }
}

MediaMode mediaModeFromString(const std::string& name) {
  for (MediaMode m : {MediaMode::EmissionAbsorption, MediaMode::SingleScatterUnshadowed, MediaMode::SingleScatter,
                      MediaMode::Full})
    if (name == toString(m)) return m;
  throw std::invalid_argument("unknown media mode '" + name + "'");
}

VolumeTracer::VolumeTracer(const rt::RayScene& surfaces, const rt::ParticleMedium& media)
    : surfaces_(surfaces), media_(media) {}

namespace {

struct Context {
  const rt::RayScene& surfaces;
  const rt::ParticleMedium& media;
  const VolumeOptions& o;
  const std::vector<Light>& lights;
};

// Light arriving at x from every punctual light, weighted by particle p's phase for light leaving
// along -dir (towards the previous vertex of a path traced along dir), with the shadowing of the mode.
glm::vec3 inScattered(const Context& c, const MediumParticle& p, const glm::vec3& x, const glm::vec3& dir,
                      bool shadowed, Sampler& sampler, RayCounter& counter) {
  glm::vec3 sum(0.f);
  for (const Light& light : c.lights) {
    glm::vec3 wi, Li;
    float dist;
    if (!rt::punctualLi(light, x, wi, dist, Li)) continue;
    if (shadowed) {
      Ray shadow{x, wi, 0.f, dist == rt::kInf ? rt::kInf : dist * (1.f - 1e-5f)};
      if (c.surfaces.occluded(shadow, sampler, counter)) continue;
      Li *= c.media.transmittance(x, wi, 0.f, std::min(shadow.tfar, 3.0e38f));
    }
    // Light propagates along -wi into x and leaves along -dir: mu = dot(-wi, -dir).
    sum += rt::phaseValue(p.phase, p.g, glm::dot(wi, dir)) * Li;
  }
  if (rt::maxComponent(c.o.sky) > 0.f) {
    if (!shadowed) {
      sum += c.o.sky;  // the phase function integrates to 1
    } else {
      const glm::vec3 wi = rt::sampleUniformSphere(sampler.next2());
      Ray shadow{x, wi, 0.f, rt::kInf};
      if (!c.surfaces.occluded(shadow, sampler, counter))
        sum += c.o.sky * c.media.transmittance(x, wi, 0.f, 3.0e38f) *
               rt::phaseValue(p.phase, p.g, glm::dot(wi, dir)) / rt::uniformSpherePdf();
    }
  }
  return sum;
}

// Deterministic integration along [tmin, tmax] (EmissionAbsorption and the single-scatter modes).
glm::vec3 integrate(const Context& c, const Ray& ray, float tmax, Sampler& sampler, RayCounter& counter,
                    std::vector<Chord>& chords, float& transmittance) {
  const MediaMode mode = c.o.mode;
  c.media.chords(ray.org, ray.dir, ray.tnear, tmax, chords);
  // Sweep the chord ends in order, keeping the chords that cover the current interval, so each piece
  // evaluates only the particles it lies in.
  std::vector<std::pair<float, int>> events;  // (t, chord + 1 when it starts, -(chord + 1) when it ends)
  for (std::size_t j = 0; j < chords.size(); ++j) {
    events.emplace_back(chords[j].t0, static_cast<int>(j) + 1);
    events.emplace_back(chords[j].t1, -static_cast<int>(j) - 1);
  }
  std::sort(events.begin(), events.end());
  std::vector<int> active;
  std::vector<double> depth;
  glm::dvec3 L(0.0);
  double T = 1.0;
  for (std::size_t k = 0; k + 1 < events.size(); ++k) {
    const int e = events[k].second;
    if (e > 0) active.push_back(e - 1);
    else active.erase(std::find(active.begin(), active.end(), -e - 1));
    const float a = events[k].first, b = events[k + 1].first;
    if (!(b > a) || active.empty()) continue;
    depth.resize(active.size());
    for (int piece = 0; piece < c.o.pieces; ++piece) {
      const float p0 = a + (b - a) * piece / c.o.pieces, p1 = a + (b - a) * (piece + 1) / c.o.pieces;
      double total = 0.0;
      for (std::size_t i = 0; i < active.size(); ++i)
        total += depth[i] = c.media.opticalDepth(chords[static_cast<std::size_t>(active[i])].particle, ray.org,
                                                 ray.dir, p0, p1);
      if (!(total > 0.0)) continue;
      const glm::vec3 x = ray.org + 0.5f * (p0 + p1) * ray.dir;
      glm::dvec3 source(0.0);
      for (std::size_t i = 0; i < active.size(); ++i) {
        if (!(depth[i] > 0.0)) continue;
        const MediumParticle& p = c.media.particles()[static_cast<std::size_t>(chords[static_cast<std::size_t>(active[i])].particle)];
        glm::vec3 s = (1.f - p.albedo) * p.emission;
        if (mode != MediaMode::EmissionAbsorption && rt::maxComponent(p.albedo) > 0.f)
          s += p.albedo * inScattered(c, p, x, ray.dir, mode == MediaMode::SingleScatter, sampler, counter);
        source += depth[i] / total * glm::dvec3(s);
      }
      L += T * -std::expm1(-total) * source;
      T *= std::exp(-total);
    }
  }
  transmittance = static_cast<float>(T);
  return glm::vec3(L);
}

// Punctual lights at a surface vertex: BSDF x cosine x Li x visibility x the media's transmittance.
glm::vec3 surfaceDirect(const Context& c, const rt::SurfaceHit& hit, const rt::Shading& sh, const glm::vec3& woL,
                        Sampler& sampler, RayCounter& counter) {
  glm::vec3 L(0.f);
  for (const Light& light : c.lights) {
    glm::vec3 wi, Li;
    float dist;
    if (!rt::punctualLi(light, hit.p, wi, dist, Li)) continue;
    const glm::vec3 wiL = sh.frame.toLocal(wi);
    const float gs = glm::dot(wi, sh.ngFacing);
    if (wiL.z > 0.f ? gs <= 0.f : gs >= 0.f) continue;
    const glm::vec3 f = sh.bsdf.eval(woL, wiL);
    if (rt::maxComponent(f) <= 0.f) continue;
    Ray shadow{rt::RayScene::offsetOrigin(hit.p, hit.ng, hit.offsetScale, wi), wi, 0.f, dist};
    if (dist != rt::kInf) shadow.tfar = glm::length(light.position - shadow.org) * (1.f - 1e-5f);
    if (c.surfaces.occluded(shadow, sampler, counter)) continue;
    L += f * std::abs(wiL.z) * Li * c.media.transmittance(shadow.org, wi, 0.f, std::min(shadow.tfar, 3.0e38f));
  }
  return L;
}

// Every order of scattering by delta tracking, for light whose last scattering towards the camera
// happened in the media (the camera ray itself stops at the first surface). Before that, the path
// may scatter on surfaces too: their emission is found by hitting them, punctual lights by NEE at
// every vertex (medium or surface), the sky by escaping.
glm::vec3 pathTrace(const Context& c, Ray ray, float tmax, Sampler& sampler, RayCounter& counter,
                    std::vector<Chord>& chords) {
  glm::vec3 L(0.f), throughput(1.f);
  rt::SurfaceHit hit;
  // Russian roulette from the fourth scattering event on, surviving with probability min(0.95, max
  // throughput) as the path tracer's (PathTracer.cpp): every path ends, even in an albedo-1 medium, long
  // before maxScattering, which stays a safety cap.
  int events = 0;
  auto roulette = [&] {
    if (++events < 4) return true;
    const float q = std::min(0.95f, rt::maxComponent(throughput));
    if (sampler.next() >= q) return false;
    throughput /= q;
    return true;
  };
  for (int bounce = 0; bounce <= c.o.maxScattering; ++bounce) {
    float t;
    int j;
    if (!c.media.sampleCollision(ray.org, ray.dir, ray.tnear, tmax, sampler, t, j, chords)) {
      if (bounce == 0) return L;  // the camera ray reached its surface or the background
      if (tmax == rt::kInf) return L + throughput * c.o.sky;
      // A surface after scattering in the media: its emission, then it scatters in turn.
      const Material& mat = c.surfaces.materialOf(hit.mesh);
      if (mat.unlit) return L + throughput * c.surfaces.unlitRadiance(hit);
      L += throughput * c.surfaces.emissionAt(hit, ray.dir);
      const glm::vec3 wo = -ray.dir;
      const rt::Shading sh = c.surfaces.shade(hit, wo);
      const glm::vec3 woL = sh.frame.toLocal(wo);
      if (sh.bsdf.hasNonDeltaLobe(woL)) L += throughput * surfaceDirect(c, hit, sh, woL, sampler, counter);
      const float uLobe = sampler.next(), uFresnel = sampler.next();
      rt::GltfBsdf::Sample bs;
      if (!sh.bsdf.sample(woL, uLobe, uFresnel, sampler.next2(), bs)) return L;
      const glm::vec3 wi = sh.frame.toWorld(bs.wi);
      const float gs = glm::dot(wi, sh.ngFacing);
      if (bs.wi.z > 0.f ? gs <= 0.f : gs >= 0.f) return L;
      throughput *= bs.weight;
      if (!(rt::maxComponent(throughput) > 0.f) || !roulette()) return L;
      ray = Ray{rt::RayScene::offsetOrigin(hit.p, hit.ng, hit.offsetScale, wi), wi, 0.f, rt::kInf};
      tmax = c.surfaces.intersect(ray, hit, sampler, counter) ? hit.distance : rt::kInf;
      continue;
    }
    const MediumParticle& p = c.media.particles()[static_cast<std::size_t>(j)];
    const glm::vec3 x = ray.org + t * ray.dir;
    L += throughput * (1.f - p.albedo) * p.emission;
    if (rt::maxComponent(p.albedo) <= 0.f) return L;
    throughput *= p.albedo;
    // Punctual lights are deltas: next-event estimation only.
    for (const Light& light : c.lights) {
      glm::vec3 wi, Li;
      float dist;
      if (!rt::punctualLi(light, x, wi, dist, Li)) continue;
      Ray shadow{x, wi, 0.f, dist == rt::kInf ? rt::kInf : dist * (1.f - 1e-5f)};
      if (c.surfaces.occluded(shadow, sampler, counter)) continue;
      L += throughput * Li * c.media.transmittance(x, wi, 0.f, std::min(shadow.tfar, 3.0e38f)) *
           rt::phaseValue(p.phase, p.g, glm::dot(wi, ray.dir));  // mu = dot(-wi, -ray.dir)
    }
    if (!roulette()) return L;
    float weight = 1.f;
    const glm::vec3 dir = rt::samplePhase(p.phase, p.g, ray.dir, sampler.next2(), weight);
    throughput *= weight;
    ray = Ray{x, dir, 0.f, rt::kInf};
    tmax = c.surfaces.intersect(ray, hit, sampler, counter) ? hit.distance : rt::kInf;
  }
  return L;
}

}  // namespace

Image VolumeTracer::render(const Camera& camera, int width, int height, const VolumeOptions& o) const {
  if (width <= 0 || height <= 0) throw std::invalid_argument("VolumeTracer::render(): image size is not positive");
  if (o.spp < 1 || o.pieces < 1) throw std::invalid_argument("VolumeTracer::render(): spp and pieces must be >= 1");
  Image image = Image::make("media", width, height, 4);
  const Context c{surfaces_, media_, o, surfaces_.scene().lights};
  const rt::CameraRays cameraRays(camera, width, height);
  auto rows = [&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, height), [&](const tbb::blocked_range<int>& range) {
      RayCounter counter;
      std::vector<Chord> chords;
      for (int y = range.begin(); y != range.end(); ++y)
        for (int x = 0; x < width; ++x) {
          glm::dvec4 sum(0.0);
          for (int s = 0; s < o.spp; ++s) {
            // Full mode's paths scatter up to maxScattering times among many particles: poll often.
            if (s % 4 == 0) o.cancel.check("the volumetric reference's rows");
            Sampler sampler(static_cast<std::uint64_t>(y) * width + x, static_cast<std::uint64_t>(s), o.seed);
            const glm::vec2 jitter = o.spp == 1 ? glm::vec2(0.5f) : sampler.next2();
            Ray ray = cameraRays.ray(x + jitter.x, y + jitter.y);
            rt::SurfaceHit hit;
            const float tmax = surfaces_.intersect(ray, hit, sampler, counter) ? hit.distance : rt::kInf;
            const float T = media_.transmittance(ray.org, ray.dir, ray.tnear, std::min(tmax, 3.0e38f));
            glm::vec3 L;
            if (o.mode == MediaMode::Full) {
              L = pathTrace(c, ray, tmax, sampler, counter, chords);
            } else {
              float unused;
              L = integrate(c, ray, std::min(tmax, 3.0e38f), sampler, counter, chords, unused);
            }
            if (std::isfinite(L.x) && std::isfinite(L.y) && std::isfinite(L.z)) sum += glm::dvec4(glm::dvec3(L), T);
            else sum.w += T;
          }
          const glm::dvec4 mean = sum / static_cast<double>(o.spp);
          float* out = image.at(x, y);
          for (int k = 0; k < 4; ++k) out[k] = static_cast<float>(mean[k]);
        }
    });
  };
  rt::withThreads(o.threads, rows);
  return image;
}

}  // namespace radiant::reference
