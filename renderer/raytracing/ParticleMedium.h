#pragma once
// Particle systems as a participating medium of the ray-tracing core: every particle is an Embree
// user-geometry sphere, a ray query returns the chords it crosses, and the optical depth along any
// segment is the sum of the particles' closed forms (Media.h), so transmittance is exact. Densities of
// overlapping particles add. Collisions are sampled by delta tracking against a piecewise majorant
// (constant between consecutive chord end points).
//
// Used by the volumetric reference (renderer/reference/VolumeTracer.h) and by every media technique's
// CPU side. Nothing here knows about GL.
#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "api/Media.h"
#include "renderer/raytracing/Sampler.h"

namespace radiant::rt {

// One particle with its system's models resolved.
struct MediumParticle {
  glm::vec3 center{0.f};
  float radius = 1.f;
  float tau = 0.f;
  glm::vec3 albedo{0.f};
  glm::vec3 emission{0.f};  // radiance of the source (fire: emission_scale * blackbodyRgb(T)); 0 otherwise
  bool linear = false;      // linear falloff density (linear_exact, and thesis' density)
  api::PhaseModel phase = api::PhaseModel::Isotropic;
  float g = 0.f;
  int system = 0;
};

// A ray's pass through one particle: [t0, t1] within the queried segment, along a unit direction.
struct Chord {
  float t0, t1;
  int particle;
};

class ParticleMedium {
public:
  explicit ParticleMedium(const std::vector<api::ParticleSystem>& systems);
  ~ParticleMedium();
  ParticleMedium(const ParticleMedium&) = delete;
  ParticleMedium& operator=(const ParticleMedium&) = delete;

  bool empty() const { return particles_.empty(); }
  const std::vector<MediumParticle>& particles() const { return particles_; }

  // Every chord of the segment org + t dir, t in [tmin, tmax] (dir unit), unordered.
  void chords(const glm::vec3& org, const glm::vec3& dir, float tmin, float tmax, std::vector<Chord>& out) const;
  // Exact optical depth of one particle / of the medium over [tmin, tmax].
  double opticalDepth(int particle, const glm::vec3& org, const glm::vec3& dir, float tmin, float tmax) const;
  double opticalDepth(const glm::vec3& org, const glm::vec3& dir, float tmin, float tmax) const;
  float transmittance(const glm::vec3& org, const glm::vec3& dir, float tmin, float tmax) const {
    return static_cast<float>(std::exp(-opticalDepth(org, dir, tmin, tmax)));
  }
  // Extinction of particle i at x.
  float density(int particle, const glm::vec3& x) const;

  // Delta tracking over [tmin, tmax]: true with the collision distance t and the particle chosen in
  // proportion to its share of the extinction at t; false when the ray leaves the segment (which
  // happens with probability exp(-opticalDepth)). `scratch` avoids allocations.
  bool sampleCollision(const glm::vec3& org, const glm::vec3& dir, float tmin, float tmax, Sampler& sampler,
                       float& t, int& particle, std::vector<Chord>& scratch) const;

private:
  std::vector<MediumParticle> particles_;
  struct Embree;
  std::unique_ptr<Embree> embree_;
};

}  // namespace radiant::rt
