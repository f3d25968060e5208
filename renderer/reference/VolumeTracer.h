#pragma once
// The volumetric reference: light that particle media (api/Media.h) send towards the camera, and the
// transmittance of the camera ray up to the first opaque surface, rendered on the ray-tracing core
// (surfaces: rt::RayScene; particles: rt::ParticleMedium with exact per-sphere optical depth).
//
// Output: RGBA, row 0 = top. RGB = the media's radiance reaching the camera from in front of the first
// surface (premultiplied; it does not contain the surface or the background), A = the transmittance to
// that surface (or to infinity). A frame composes as beauty = opaque * A + RGB, which is what the media
// techniques' "media" AOV holds, so each scores against the mode matching the model it solves:
//   EmissionAbsorption       emission (fire: (1 - albedo) sigma_t L_e) and extinction only;
//   SingleScatterUnshadowed  + light scattered once, lights seen without any shadowing (neither media
//                            nor surfaces): what spherical billboards compute (thesis 7.2.1);
//   SingleScatter            + the light's transmittance through the media and surface visibility;
//   Full                     every order of scattering by delta tracking, in the media and on the
//                            surfaces (glTF BSDF) before the last medium vertex: surface emission is
//                            found by hitting it, punctual lights by next-event estimation at every
//                            vertex, the sky by escaping. Only light whose last scattering towards
//                            the camera is in the media counts (the camera ray stops at its surface).
// Lights: KHR_lights_punctual (glTF units) and a uniform sky `sky` (the map's average for an
// environment), which in the single-scatter modes adds albedo * sky (unshadowed) or a sampled
// direction with its visibility (shadowed). Emissive triangles do not light the media.
// EmissionAbsorption and the single-scatter modes integrate the camera ray deterministically over
// pieces between chord ends (`pieces` per interval): per piece the exact optical depths of the
// particles weight their sources, so a lone particle's emission 1 - e^(-tau chord) is exact. Thesis
// profile particles are rendered with the linear-falloff density they approximate.
#include <cstdint>

#include <glm/glm.hpp>

#include "renderer/Image.h"
#include "renderer/raytracing/Cancel.h"
#include "renderer/scene/Scene.h"

namespace radiant::rt {
class RayScene;
class ParticleMedium;
}  // namespace radiant::rt

namespace radiant::reference {

enum class MediaMode { EmissionAbsorption, SingleScatterUnshadowed, SingleScatter, Full };
const char* toString(MediaMode m);  // "emission_absorption" | ... | "full"
// Throws std::invalid_argument for an unknown name.
MediaMode mediaModeFromString(const std::string& name);

struct VolumeOptions {
  MediaMode mode = MediaMode::SingleScatterUnshadowed;
  int spp = 16;            // pixel jitter (and, in Full and SingleScatter with a sky, the paths)
  int pieces = 8;          // quadrature pieces per chord interval (deterministic modes)
  int maxScattering = 1024;  // Full: scattering events per path, a safety cap (roulette ends paths first)
  std::uint64_t seed = 0;
  glm::vec3 sky{0.f};
  int threads = 0;  // 0 = TBB default
  rt::Cancel cancel;  // polled every few samples of a pixel; render() then throws rt::Cancelled
};

class VolumeTracer {
public:
  // `surfaces` occlude (its scene supplies the lights), `media` scatters; both must outlive this.
  VolumeTracer(const rt::RayScene& surfaces, const rt::ParticleMedium& media);
  Image render(const Camera& camera, int width, int height, const VolumeOptions& options) const;

private:
  const rt::RayScene& surfaces_;
  const rt::ParticleMedium& media_;
};

}  // namespace radiant::reference
