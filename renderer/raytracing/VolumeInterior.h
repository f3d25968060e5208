#pragma once
// KHR_materials_volume on the CPU paths (path tracer, photon tracer, light tracer): the homogeneous
// absorbing medium a ray segment travels in, and its Beer-Lambert transmittance over the segment's real
// length (the spec's thickness is a rasterizer's stand-in for that length: the tracers do not need it).
//
// Which medium: a material with a volume (Material::hasVolume) bounds a closed mesh whose outward side is
// its front face (counter-clockwise winding, as RayScene's geometric normal), so after scattering at
// such a surface the next segment is inside when it leaves against the geometric normal (a refraction
// in, or a reflection inside: total internal reflection keeps it inside) and outside otherwise. The BSDF's sampled side decides, nothing
// is counted by hand. A surface without a volume leaves the medium as it is (an object immersed in a
// medium). Nested volumes are not tracked: leaving an inner one puts the ray outside every medium.
#include <cmath>

#include <glm/glm.hpp>

#include "renderer/raytracing/RayScene.h"

namespace radiant::rt {

struct VolumeInterior {
  glm::vec3 sigmaT{0.f};  // extinction coefficient of the medium the ray is in (0: outside every medium)

  bool absorbs() const { return sigmaT.x > 0.f || sigmaT.y > 0.f || sigmaT.z > 0.f; }

  // Beer-Lambert: T = exp(-sigma_t t) per channel over a segment of length t >= 0. t = infinity (a ray
  // that escapes an open mesh from inside) gives 0 in every absorbing channel and 1 elsewhere; sigma_t is
  // finite (Material::attenuationCoefficient), so 0 x sigma_t never makes a NaN.
  glm::vec3 transmittance(float t) const {
    glm::vec3 T(1.f);
    for (int k = 0; k < 3; ++k)
      if (sigmaT[k] > 0.f) T[k] = std::exp(-sigmaT[k] * t);
    return T;
  }

  // The medium after scattering at `hit` into the world direction wi (unit).
  void scatter(const RayScene& rays, const SurfaceHit& hit, const glm::vec3& wi) {
    const Material& m = rays.materialOf(hit.mesh);
    if (!m.hasVolume()) return;
    sigmaT = glm::dot(wi, hit.ng) < 0.f ? m.attenuationCoefficient() : glm::vec3(0.f);
  }

  // The medium a direction wi from `hit` travels in, without changing this one (next-event estimation
  // and camera connections: their segment starts where the path's next one would).
  VolumeInterior towards(const RayScene& rays, const SurfaceHit& hit, const glm::vec3& wi) const {
    VolumeInterior v = *this;
    v.scatter(rays, hit, wi);
    return v;
  }
};

}  // namespace radiant::rt
