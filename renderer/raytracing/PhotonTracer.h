#pragma once
// Photon tracing (Stürzlinger & Bastos 1997, §2.1): particles leave every emitter in proportion to its
// power, scatter by the glTF BSDF in importance mode with unbiased Russian roulette, and leave a record
// at every hit on a surface that has a non-delta lobe. The records are derived data: they depend on the
// scene, its lights and environment, the seed and the bounce limit, never on the camera.
//
// Power (eq. 1): photon j carries phi_j = Phi_total / m * rho_j. A record stores Phi_total * rho_j (the
// flux of one emission sample, `flux`); a consumer divides by the number of photons m it uses. So a set
// of m photons grows to m + m' by tracing photons m .. m + m' - 1 and appending: the old records are
// "rescaled" by using 1 / (m + m') instead of 1 / m, and the result is exactly a fresh run of m + m'
// photons with the same seed (photon i's random numbers depend only on (i, seed)).
//
// A delta (mirror, smooth glass) scattering ends a photon whose path has had no other scattering: what
// it would carry is LS+D light, caustics, which this tracer does not own. After a diffuse or glossy
// vertex the photon follows delta scatterings (L D S+ D, as the reference's paths). Near-mirrors (Material::isSpecular() with roughness > 0) have a
// glossy lobe and are scattered by it; a record whose earlier vertices all lie on such surfaces is
// flagged kPhotonSpecularChain (class LS+D), so that a consumer can leave it to the caustics pass.
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "renderer/raytracing/Cancel.h"
#include "renderer/raytracing/Lights.h"
#include "renderer/raytracing/RayScene.h"

namespace radiant::rt {

// Unit vectors in 2 x `bits` bits (at most 16): the octahedral map (Meyer et al. 2010, "On
// floating-point normal vectors") with signed-normalised coordinates, x in the low `bits`, y above
// (the convention of shaders/common/octahedral.glsl). At 16 bits the decoded vector is within 1e-4
// radians (0.006 degrees) of the encoded one (6.4e-5 measured, tested), far below what a photon's
// direction or its surface's normal is used for (the kernel's plane and normal tests, a BRDF of
// roughness >= 0.2); photon_gi's splats use 15. Zero or non-finite input encodes +z.
std::uint32_t octEncode(const glm::vec3& unit, int bits = 16);
glm::vec3 octDecode(std::uint32_t packed, int bits = 16);

// 48 bytes: the normal and the direction are octahedral-encoded (4M photons leave about 7.7M records on
// the Cornell box: 368 MB, not the 490 MB of three-float vectors; issue 30's memory goal).
struct PhotonRecord {
  glm::vec3 position{0.f};
  std::int32_t mesh = -1;       // MeshInstance index of the surface hit (the paper's surface id)
  glm::vec3 flux{0.f};          // Phi_total * rho_j (W); divide by the photons used
  std::uint32_t light = 0;      // index into SceneLights::emitters()
  std::uint32_t photon = 0;     // index of the emitted photon; records are sorted by it
  std::uint32_t normalOct = 0;  // octEncode: unit geometric normal on the side the photon arrived from
  std::uint32_t wiOct = 0;      // octEncode: unit direction towards where the photon came from
  std::uint16_t bounce = 0;     // scattering events before this hit (0 = straight from the emitter)
  std::uint16_t flags = 0;      // kPhoton* bits
  glm::vec3 normal() const { return octDecode(normalOct); }
  glm::vec3 wi() const { return octDecode(wiOct); }
};
static_assert(sizeof(PhotonRecord) == 48, "PhotonRecord is 48 bytes");
// bounce >= 1 and every scattering vertex before this hit was on a Material::isSpecular() surface:
// the photon's path so far is L S+ D (what the caustics pass supplies for punctual lights).
inline constexpr std::uint16_t kPhotonSpecularChain = 1u;
// bounce >= 1 and every scattering event before this hit was a glossy or specular lobe of a metal or
// glass (Material::scattersNarrowLobe()): the path so far is L(S|G)+, which light_volumes supplies
// (classes LS+DE, LG+DE) when it owns them.
inline constexpr std::uint16_t kPhotonNarrowLobePath = 2u;

struct PhotonOptions {
  // Most scattering events a path may have counting the surface the photon lands on as seen by the
  // camera, like the reference's max_bounces: records hold bounce <= maxBounces - 1.
  int maxBounces = kDefaultMaxBounces;  // a safety cap: Russian roulette ends photons first
  bool russianRoulette = true;
  std::uint64_t seed = 0;
  int threads = 0;  // 0 = TBB default
  // Polled every kCancelPollPhotons photons: tracePhotons() then throws Cancelled and leaves `set` as it
  // was (the records appended by the waves before it are removed again), so a cached set stays whole.
  Cancel cancel;
};

struct PhotonSet {
  std::vector<PhotonRecord> records;  // sorted by photon index
  std::uint64_t emitted = 0;          // photons 0 .. emitted - 1 are traced
  std::uint64_t rays = 0;             // rays traced in total
  std::uint64_t capped = 0;           // photons maxBounces ended while alive (RayCounter::capped)
  // Records of the first n photons (a prefix of `records`).
  std::size_t recordsOfFirst(std::uint64_t n) const;
};

// Traces photons set.emitted .. count - 1 and appends their records (nothing when count <= emitted).
// Deterministic for a seed and independent of the thread count.
void tracePhotons(const RayScene& rays, const SceneLights& lights, const PhotonOptions& options,
                  std::uint64_t count, PhotonSet& set);

}  // namespace radiant::rt
