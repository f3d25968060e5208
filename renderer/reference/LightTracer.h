#pragma once
// The reference light tracer (Veach 1997 §10.3, pbrt-v4 / Mitsuba 3 `ptracer`): paths start at the
// emitters (SceneLights::sampleLe: every emitter chosen in proportion to its power) and every vertex
// with a non-delta lobe is connected to the camera (CameraRays::connect: the pixel that sees it and the
// camera's importance with the path tracer's pixel measure). It sees what a unidirectional path tracer
// cannot: a point or directional light (a delta) seen through a mirror or smooth glass (Dirac deltas),
// the caustic paths L S+ D E.
//
// Classes (LightTracerOptions::paths; S = a vertex that scattered through a Dirac-delta lobe, D = the
// vertex connected to the camera, which evaluates its non-delta lobes):
// - Caustics: exactly L S+ D E. With PathTracer's excludeCaustics the two partition the image: path
//   tracer + light tracer caustics = the whole image with every path counted once.
// - All: every path with at least one scattering event, connected at every non-delta vertex (light
//   tracing's full estimate of the image minus emitters seen directly; used to check the light tracer
//   against the path tracer on scenes without deltas).
// Bounce count k = scattering events between the emitter and the camera, the connection vertex
// included (the path tracer's k), capped by maxBounces and filtered by [minPathBounce, maxPathBounce].
//
// Particles carry flux in the importance mode of the BSDF with Veach's shading-normal correction (eq.
// 5.21), as the photon tracer does. The connection adds beta f(wp -> wc) |wp.ns| |wc.ng| / |wp.ng| x
// importance (the flux-to-radiance conversion of a particle at a surface with a shading normal).
//
// Deterministic and parallel: light path i uses Sampler(i, 0, seed); paths run in fixed blocks whose
// images are summed in block order, so the result does not depend on the number of threads.
#include <climits>
#include <functional>
#include <cstdint>
#include <memory>

#include <glm/glm.hpp>

#include "renderer/Image.h"
#include "renderer/raytracing/Cancel.h"
#include "renderer/raytracing/RayScene.h"
#include "renderer/scene/Scene.h"

namespace radiant::rt { class RayScene; }

namespace radiant::reference {

struct LightTracerOptions {
  int pathsPerPixel = 16;  // light paths traced = pathsPerPixel * width * height
  int maxBounces = rt::kDefaultMaxBounces;  // scattering events on a path, the connection vertex included
  bool russianRoulette = true;
  std::uint64_t seed = 0;
  enum class Paths { All, Caustics } paths = Paths::Caustics;
  int minPathBounce = 1, maxPathBounce = INT_MAX;  // inclusive range of k
  glm::vec3 skyRadiance{0.f};
  const Image* environment = nullptr;
  int threads = 0;  // 0 = TBB default
  std::function<void(double)> progress;  // fraction of paths traced, after each wave of blocks
  rt::Cancel cancel;  // polled every kCancelPollPaths paths of a block; render() then throws rt::Cancelled
};

class LightTracer {
public:
  // `rays` must outlive the LightTracer.
  explicit LightTracer(const rt::RayScene& rays);
  ~LightTracer();
  LightTracer(const LightTracer&) = delete;
  LightTracer& operator=(const LightTracer&) = delete;

  // RGB radiance, row 0 = top. Throws std::invalid_argument on bad sizes or options.
  Image render(const Camera& camera, int width, int height, const LightTracerOptions& options) const;
  // Rays traced by the most recent render() (path segments and camera connections).
  std::uint64_t raysTraced() const;
  // Paths of the most recent render() that maxBounces ended while alive (RayCounter::capped).
  std::uint64_t pathsCapped() const;

private:
  const rt::RayScene& rays_;
  mutable std::uint64_t lastRays_ = 0, lastCapped_ = 0;
};

// True when some material of the scene has a Dirac-delta lobe (roughness 0 reflection or
// transmission): only then can caustic paths exist.
bool sceneHasDeltaLobes(const Scene& scene);

}  // namespace radiant::reference
