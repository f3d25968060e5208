#pragma once
// The step every light-particle integrator shares (photon tracer, light tracer): after a BSDF sample
// at a shaded hit, the particle leaves along s.wi with its flux scaled by s.weight times the adjoint
// BSDF's shading-normal correction (Veach 1997, eq. 5.21: |wo.ns| |wi.ng| / (|wo.ng| |wi.ns|)) and, when
// `roulette`, Russian roulette with survival min(0.95, max channel of the weight), the survivors
// re-weighted (unbiased; an albedo-1 path still ends). False when the particle ends: the direction
// leaks through the geometric surface, the geometry factor degenerates, or roulette ends it.
// `interior` follows the KHR_materials_volume medium the particle enters or leaves (VolumeInterior.h):
// the caller attenuates the flux by interior.transmittance(hit.distance) at the next hit.
#include <algorithm>
#include <cmath>

#include <glm/glm.hpp>

#include "renderer/raytracing/RayScene.h"
#include "renderer/raytracing/VolumeInterior.h"

namespace radiant::rt {

inline constexpr float kParticleMaxSurvival = 0.95f;

// wo: unit direction towards where the particle came from; woL: wo in the shading frame.
inline bool continueParticle(const RayScene& rays, const SurfaceHit& hit, const Shading& sh, const glm::vec3& wo, const glm::vec3& woL,
                             const GltfBsdf::Sample& s, bool roulette, Sampler& sampler, glm::vec3& flux, Ray& ray,
                             VolumeInterior& interior) {
  const glm::vec3 wi = sh.frame.toWorld(s.wi);
  const float gi = glm::dot(wi, sh.ngFacing);
  if (s.wi.z > 0.f ? gi <= 0.f : gi >= 0.f) return false;  // leaked through the geometric surface
  const float den = std::abs(glm::dot(wo, sh.ngFacing)) * std::abs(s.wi.z);
  const float num = std::abs(woL.z) * std::abs(gi);
  if (!(den > 0.f)) return false;
  glm::vec3 weight = s.weight * (num / den);
  if (roulette) {
    const float q = std::min(kParticleMaxSurvival, maxComponent(weight));
    if (!(q > 0.f) || sampler.next() >= q) return false;
    weight /= q;
  }
  flux *= weight;
  interior.scatter(rays, hit, wi);
  ray = Ray{RayScene::offsetOrigin(hit.p, hit.ng, hit.offsetScale, wi), wi, 0.f, kInf};
  return true;
}

}  // namespace radiant::rt
