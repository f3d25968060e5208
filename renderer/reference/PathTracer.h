#pragma once
// The CPU reference renderer: an unbiased unidirectional path tracer on Embree. It is the ruler every
// GPU technique is scored with, so it favours being right over being fast.
//
// Light transport (Radiance mode):
// - BSDF: the glTF 2.0 metallic-roughness BRDF (+ transmission), see renderer/raytracing/Bsdf.h; the
//   BVH, material decoding and light sampling are the shared core of renderer/raytracing/.
// - Next-event estimation to every punctual light (KHR_lights_punctual, glTF units as-is), to one
//   emissive triangle chosen in proportion to its power (area sampling), and to the environment.
//   Emissive triangles and the environment are combined with BSDF sampling by multiple importance
//   sampling (power heuristic, Veach 1997 eq. 9.13). Punctual lights are deltas: NEE only.
// - Russian roulette from the fourth scattering event on, survival probability
//   min(0.95, max channel of the path throughput), throughput divided by it (unbiased).
// - Every random number is a hash of (pixel, sample, seed, dimension), so an image does not depend on
//   the number of threads or on tile scheduling: renders are bitwise reproducible.
//
// Bounce ranges (minPathBounce..maxPathBounce, inclusive): a light contribution is classified by the
// number k of surface scattering events on its path between the camera and the emitter.
//   k = 0  emission or environment seen directly by the camera ray;
//   k = 1  direct lighting: light reaching the first visible surface straight from an emitter, a
//          punctual light or the environment, whichever strategy (NEE or BSDF sampling) found it;
//   k >= 2 indirect lighting.
// A delta (mirror / glass) interaction counts as a scattering event like any other. So:
//   "direct" AOV   = [1, 1] (add [0, 0] for visible emitters and background: [0, 1] is everything but
//                    indirect);
//   "indirect" AOV = [2, INT_MAX].
// The ranges partition the image exactly: render[0,1] + render[2,inf] == render[0,inf] up to noise.
// maxBounces caps k as well (maxBounces = 1 is direct lighting only, 0 shows emitters only).
//
// Ambient occlusion modes: the camera ray finds the first surface (shading normal faced towards the
// camera; background pixels are 1) and then:
// - AoCosineStep: classic AO, O = 1/pi \int cos+ [d(w) >= R] dw (thesis eq. 4.2 with the step
//   membership function of Fig. 4.3). Cosine-weighted directions, estimator = the step.
// - AoVolumetric: Umenhoffer's volumetric ambient occlusion, thesis eq. 4.6: the fraction of the
//   tangent sphere S (radius R/2, centre x + n R/2, Fig. 4.4) that is visible from x,
//   V = \int_S I(p) dp / |S|, |S| = 4 pi (R/2)^3 / 3, I(p) = 1 when the segment x->p is unoccluded (the
//   ray-traced form of the thesis' inner/outer indicator, equal to it under the thesis' assumption of at
//   most one intersection within R). In polar coordinates around x the sphere is r <= R cos(theta) and
//   dp = r^2 dr dw, so V = (2/pi) \int min(d(w)/R, cos theta)^3 dw. We sample p(w) = 2 cos^3/pi and
//   estimate V with min(1, d(w) / (R cos theta))^3 (exactly 1 when unoccluded: zero variance on open
//   surfaces).
// - AoCubicFalloff: thesis eq. 4.2 with the fuzzy membership mu(r) = min(1, (r/R)^3) that the thesis
//   says volumetric AO uses implicitly (Fig. 4.3 / Fig. 4.8 caption): O = 1/pi \int cos+ mu(d(w)) dw.
//   NOTE this is NOT identical to eq. 4.6: the step from eq. 4.4 to the tangent-sphere integral shrinks
//   the domain by cos(theta) instead of weighting by it, which is exact only for a linear mu. Both are
//   open-plane 1 and half-space-wall 1/2, but differ in between (see tests/unit/reference).
//   GPU volumetric AO (Algorithm 2, eq. 4.8) estimates eq. 4.6, so compare it against AoVolumetric.
//
// Conventions: RGB float output, row 0 = top, linear radiance. Box pixel filter (uniform jitter).
// Camera rays start at znear (along the view axis) and are not clipped at zfar. Emission is
// emissiveFactor * emissiveStrength (* emissive texture), from the front face (counter-clockwise
// winding) only unless the material is doubleSided. Surfaces otherwise shade two-sided.
// Alpha: MASK surfaces below the cutoff and BLEND surfaces with probability (1 - alpha) are passed
// through. Occlusion textures are ignored (the path tracer computes occlusion).
// Environment: equirectangular, row 0 = +Y (up), u = 0.5 + atan2(dir.x, -dir.z) / (2 pi) (so the image
// centre is -Z), v = acos(dir.y) / pi, nearest texel (piecewise constant, importance sampled exactly).
// When ReferenceOptions::environment is set it replaces skyRadiance.
#include <climits>
#include <functional>
#include <cstdint>
#include <memory>

#include <glm/glm.hpp>

#include "renderer/Image.h"
#include "renderer/raytracing/Cancel.h"
#include "renderer/raytracing/RayScene.h"
#include "renderer/scene/Scene.h"

namespace radiant::rt {
class RayScene;
struct EnvironmentDistribution;
}  // namespace radiant::rt

namespace radiant::reference {

struct ReferenceOptions {
  int spp = 64;
  int maxBounces = rt::kDefaultMaxBounces;  // scattering events on a path: a safety cap, roulette ends paths first
  bool russianRoulette = true;
  std::uint64_t seed = 0;
  int minPathBounce = 0, maxPathBounce = INT_MAX;  // inclusive range of k, see the header comment
  enum class Mode { Radiance, AoCosineStep, AoVolumetric, AoCubicFalloff } mode = Mode::Radiance;
  float aoRadius = 1.f;
  glm::vec3 skyRadiance{0.f};          // uniform environment radiance
  const Image* environment = nullptr;  // equirect RGB(A) linear radiance, optional; overrides skyRadiance
  // environment's importance-sampling distribution when the caller has it cached (built per render otherwise)
  std::shared_ptr<const rt::EnvironmentDistribution> environmentDistribution;
  int threads = 0;                     // 0 = TBB default
  // Called with the fraction of tiles done, from worker threads (keep it cheap and thread-safe).
  std::function<void(double)> progress;
  // Polled every kCancelPollSamples samples of a pixel (a few ms of work however high spp is): render()
  // then throws rt::Cancelled once every worker has stopped.
  rt::Cancel cancel;
  // Drop exactly the caustic paths L S+ D E (the camera's first vertex scatters through a non-delta
  // lobe, every later vertex through a Dirac delta, then an emitter or the sky), which the light tracer
  // renders (renderer/reference/LightTracer.h): path tracer with this + light tracer's caustics = the
  // whole image, each path counted once. Unlit surfaces do not scatter, so they start no chain.
  bool excludeCaustics = false;
};

class PathTracer {
public:
  // Builds the Embree BVH (one triangle geometry per MeshInstance) and the emissive-triangle light
  // distribution. `scene` must outlive the PathTracer.
  explicit PathTracer(const Scene& scene);
  // Uses a BVH built elsewhere (shared with the photon tracer); `rays` must outlive the PathTracer.
  explicit PathTracer(const rt::RayScene& rays);
  ~PathTracer();
  PathTracer(const PathTracer&) = delete;
  PathTracer& operator=(const PathTracer&) = delete;
  PathTracer(PathTracer&&) noexcept;
  PathTracer& operator=(PathTracer&&) noexcept;

  // Renders `camera` at width x height: RGB, row 0 = top. Throws std::invalid_argument on bad sizes or
  // options (spp < 1, aoRadius <= 0 in an AO mode, environment without pixels).
  Image render(const Camera& camera, int width, int height, const ReferenceOptions& options) const;

  // Rays (closest-hit + shadow) traced by the most recent render().
  std::uint64_t raysTraced() const;
  // Paths of the most recent render() that maxBounces ended while alive (RayCounter::capped): the
  // truncation the cap added; 0 in practice at the default cap with Russian roulette.
  std::uint64_t pathsCapped() const;

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace radiant::reference
