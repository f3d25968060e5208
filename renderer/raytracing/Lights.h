#pragma once
// Light sources of the ray-tracing core, in both directions (pbrt-v4 lights, Mitsuba emitters):
// - sampleLi / pdfLi: incident light at a surface point (next-event estimation of the path tracer);
// - sampleLe / power: emission of light particles (photon tracing, light tracing), every emitter
//   chosen in proportion to its power by one light sampler.
// Emitters: KHR_lights_punctual point, spot and directional lights (glTF units as they are: candela,
// lux), emissive triangles (emissiveFactor * emissiveStrength * texture, front face unless
// doubleSided), and the environment (an equirect map or a uniform sky).
#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <vector>

#include <glm/glm.hpp>

#include "renderer/Image.h"
#include "renderer/raytracing/Cancel.h"
#include "renderer/raytracing/RayScene.h"
#include "renderer/scene/Environment.h"

namespace radiant::rt {

// KHR_lights_punctual's recommended range window, clamp(1 - (d / range)^4, 0, 1), applied to the
// inverse-square law; range 0 = no window. The one definition for every CPU consumer.
inline float rangeWindow(float distance, float range) {
  if (!(range > 0.f)) return 1.f;
  const float r = distance / range;
  return std::clamp(1.f - (r * r) * (r * r), 0.f, 1.f);
}

// KHR_lights_punctual spot falloff: t = saturate(cd * scale + offset), scale = 1 / max(0.001,
// cos(inner) - cos(outer)), offset = -cos(outer) * scale; intensity scales by t^2. cd = cosine between
// the spot axis and the direction of emission.
inline float spotFalloff(const Light& light, float cd) {
  const float cosOuter = std::cos(light.outerConeAngle), cosInner = std::cos(light.innerConeAngle);
  const float scale = 1.f / std::max(0.001f, cosInner - cosOuter);
  const float t = std::clamp(cd * scale - cosOuter * scale, 0.f, 1.f);
  return t * t;
}

// Radiant flux of a punctual light of intensity I (W/sr): 4 pi I for a point light; for a spot,
// 2 pi I ((1 - cos_inner) + (cos_inner - cos_outer) / 3), the integral of spotFalloff over the sphere
// (t is linear in cos between the cone angles, so t^2 integrates to a third of that band). Without
// range windowing. A directional light's power depends on the area it covers (see SceneLights).
glm::vec3 punctualPower(const Light& light);

// Incident light at p from a punctual light: direction wi towards the light, distance (kInf for
// directional) and the light's contribution Li (irradiance normal to wi: I window / d^2, or E).
// False when the light cannot reach p (zero intensity, outside a spot's cone, beyond its range).
bool punctualLi(const Light& light, const glm::vec3& p, glm::vec3& wi, float& distance, glm::vec3& Li);

// Largest i in [0, n) with cdf[i] <= value and cdf[i + 1] > cdf[i] when possible (cdf has n + 1
// entries, cdf[0] = 0).
inline int findInterval(const float* cdf, int n, float value) {
  const float* it = std::upper_bound(cdf, cdf + n + 1, value);
  int i = static_cast<int>(it - cdf) - 1;
  i = std::clamp(i, 0, n - 1);
  while (i > 0 && cdf[i + 1] <= cdf[i]) --i;         // skip zero-probability cells (value at an edge)
  while (i < n - 1 && cdf[i + 1] <= cdf[i]) ++i;
  return i;
}

// The importance-sampling distribution of an equirectangular map: a piecewise-constant 2D distribution
// over texels weighted by luminance * sin(theta) (pbrt-v3 14.2.4), and the map's integral over the
// sphere. O(texels) to build, so it is derived data of the environment: FrameResources caches it per
// environment digest and size ("environment_distribution", renderer/frame/RayScenes.h), and every
// render with the same map reuses it.
// With `weight` (an image of the map's size) the texels are drawn by weight's luminance instead, while
// `integral` stays the map's: photon_gi draws fewer photons from the environment's lights, whose first
// hits are `direct`'s (renderer/techniques/photon_gi/PhotonGi.cpp). The weight must be positive
// wherever the map is, or the estimate loses that light.
struct EnvironmentDistribution {
  int width = 0, height = 0;
  std::vector<float> conditional, marginal;  // h rows of (w + 1) CDF entries; h + 1 row sums
  float total = 0.f;
  glm::vec3 integral{0.f};  // \int L(w) dw, per channel
  // O(texels); `cancel` is polled every 64 rows.
  static std::shared_ptr<const EnvironmentDistribution> build(const Image& map, const Image* weight = nullptr,
                                                              const Cancel& cancel = {});
};

// The environment: uniform sky or an equirectangular map importance sampled by its
// EnvironmentDistribution.
class EnvironmentLight {
public:
  // `map` (equirect RGB(A) linear radiance) replaces `sky` when set; it must outlive the light.
  // `distribution` is map's (EnvironmentDistribution::build, usually cached); built here when null.
  EnvironmentLight(const Image* map, glm::vec3 sky, std::shared_ptr<const EnvironmentDistribution> distribution = nullptr)
      : map_(map), sky_(sky), dist_(std::move(distribution)) {
    if (map_) {
      if (map_->width <= 0 || map_->height <= 0 || map_->channels <= 0 ||
          map_->pixels.size() < static_cast<size_t>(map_->width) * map_->height * map_->channels)
        throw std::invalid_argument("EnvironmentLight: environment image has no pixels");
      if (!dist_) dist_ = EnvironmentDistribution::build(*map_);
      if (dist_->width != map_->width || dist_->height != map_->height)
        throw std::invalid_argument("EnvironmentLight: the distribution is of another map");
      active_ = dist_->total > 0.f;
    } else {
      active_ = maxComponent(sky_) > 0.f;
    }
  }
  bool active() const { return active_; }

  // \int L(w) dw over the sphere, per channel (4 pi sky for a uniform sky).
  glm::vec3 integral() const { return map_ ? dist_->integral : 4.f * kPi * sky_; }

  glm::vec3 radiance(const glm::vec3& dir) const {
    if (!map_) return sky_;
    int x, y;
    texelOf(dir, x, y);
    return texelAt(x, y);
  }

  float pdf(const glm::vec3& dir) const {
    if (!active_) return 0.f;
    if (!map_) return uniformSpherePdf();
    const float sinTheta = safeSqrt(1.f - dir.y * dir.y);
    if (sinTheta <= 0.f) return 0.f;
    int x, y;
    texelOf(dir, x, y);
    const int w = map_->width, h = map_->height;
    const float* cdf = &dist_->conditional[static_cast<size_t>(y) * (w + 1)];
    const float p = (cdf[x + 1] - cdf[x]) / dist_->total;  // discrete texel probability
    return p * w * h / (2.f * kPi * kPi * sinTheta);  // uv density -> solid angle: dw = 2 pi^2 sin(theta) du dv
  }

  glm::vec3 sample(glm::vec2 u, float& pdfOut) const {
    if (!map_) {
      pdfOut = uniformSpherePdf();
      return sampleUniformSphere(u);
    }
    const int w = map_->width, h = map_->height;
    const float total = dist_->total;
    const int y = findInterval(dist_->marginal.data(), h, u.y * total);
    const float rowLo = dist_->marginal[y], rowHi = dist_->marginal[y + 1];
    const float fy = rowHi > rowLo ? std::clamp((u.y * total - rowLo) / (rowHi - rowLo), 0.f, 1.f) : 0.5f;
    const float* cdf = &dist_->conditional[static_cast<size_t>(y) * (w + 1)];
    const int x = findInterval(cdf, w, u.x * cdf[w]);
    const float colLo = cdf[x], colHi = cdf[x + 1];
    const float fx = colHi > colLo ? std::clamp((u.x * cdf[w] - colLo) / (colHi - colLo), 0.f, 1.f) : 0.5f;
    const float uu = (x + fx) / w, vv = (y + fy) / h;
    const float theta = kPi * vv, phi = 2.f * kPi * (uu - 0.5f);
    const float sinTheta = std::sin(theta);
    const glm::vec3 dir(sinTheta * std::sin(phi), std::cos(theta), -sinTheta * std::cos(phi));
    if (sinTheta <= 0.f) { pdfOut = 0.f; return dir; }
    pdfOut = (colHi - colLo) / total * w * h / (2.f * kPi * kPi * sinTheta);
    return dir;
  }

private:
  glm::vec3 texelAt(int x, int y) const {
    const float* p = map_->at(x, y);
    return map_->channels >= 3 ? glm::vec3(p[0], p[1], p[2]) : glm::vec3(p[0]);
  }
  void texelOf(const glm::vec3& dir, int& x, int& y) const { equirectTexel(*map_, dir, x, y); }
  const Image* map_;
  glm::vec3 sky_;
  std::shared_ptr<const EnvironmentDistribution> dist_;
  bool active_ = false;
};

inline std::shared_ptr<const EnvironmentDistribution> EnvironmentDistribution::build(const Image& map,
                                                                                     const Image* weight,
                                                                                     const Cancel& cancel) {
  auto d = std::make_shared<EnvironmentDistribution>();
  const int w = map.width, h = map.height;
  if (weight && (weight->width != w || weight->height != h || weight->channels < 1))
    throw std::invalid_argument("EnvironmentDistribution: the weight is not of the map's size");
  d->width = w;
  d->height = h;
  d->conditional.assign(static_cast<size_t>(h) * (w + 1), 0.f);
  d->marginal.assign(h + 1, 0.f);
  glm::dvec3 sum(0.0);
  for (int y = 0; y < h; ++y) {
    if ((y & 63) == 0) cancel.check("the environment's sampling distribution (environment_distribution)");
    const float sinTheta = std::sin(kPi * (y + 0.5f) / h);
    const double dOmega = 2.0 * kPi * kPi * std::sin(kPi * (y + 0.5) / h) / (double(w) * h);
    float* cdf = &d->conditional[static_cast<size_t>(y) * (w + 1)];
    for (int x = 0; x < w; ++x) {
      const float* p = map.at(x, y);
      const glm::vec3 L = map.channels >= 3 ? glm::vec3(p[0], p[1], p[2]) : glm::vec3(p[0]);
      const float* q = weight ? weight->at(x, y) : p;
      const int channels = weight ? weight->channels : map.channels;
      const glm::vec3 W = channels >= 3 ? glm::vec3(q[0], q[1], q[2]) : glm::vec3(q[0]);
      cdf[x + 1] = cdf[x] + std::max(0.f, luminance(W)) * sinTheta;
      sum += dOmega * glm::dvec3(L);
    }
    d->marginal[y + 1] = d->marginal[y] + cdf[w];
  }
  d->total = d->marginal[h];
  d->integral = glm::vec3(sum);
  return d;
}


// One emission sample of one emitter (pbrt-v4 Light::SampleLe): the ray leaving it, what it carries
// along the ray and the densities it was drawn with.
// - L: the emitted radiance for an area emitter (triangle, environment); the intensity I(w) (W/sr) of
//   a point or spot light; the irradiance E normal to the beam (lux) of a directional light.
// - pdfPos: density of the origin over the emitting area (m^-2); 1 for point and spot lights (a delta
//   in position).
// - pdfDir: density of the direction over solid angle (sr^-1); 1 for a directional light (a delta in
//   direction).
// - cosine: |n . dir| at a triangle's emitting side, 1 otherwise.
// The flux of the sample is L cosine / (pdfPos pdfDir); its mean over samples is the emitter's power.
struct LeSample {
  Ray ray;
  glm::vec3 L{0.f};
  float pdfPos = 0.f, pdfDir = 0.f, cosine = 1.f;
};

// A photon (or light-tracing particle) leaving an emitter: the ray and its flux, already divided by
// the probability of choosing this emitter and this ray, so the mean over N emissions of
// flux / N ... sums to the emitted power.
struct Emission {
  Ray ray;
  glm::vec3 flux{0.f};
  int light = -1;            // index into SceneLights::emitters()
  float windowRange = 0.f;   // > 0: multiply by rangeWindow(first-hit distance, windowRange)
};

class SceneLights {
public:
  enum class Kind { Punctual, Triangle, Environment };
  struct Emitter {
    Kind kind;
    int index;          // Scene::lights index or RayScene::triangleLights() index; -1 for the environment
    glm::vec3 power;    // radiant flux (W), per channel
  };

  // The environment (map or sky) and the emitters of `rays`' scene. Directional lights and the
  // environment emit through a disk around the scene's bounding sphere.
  // `environmentDistribution`: environmentMap's, when the caller has it cached (built here otherwise).
  SceneLights(const RayScene& rays, const Image* environmentMap, glm::vec3 skyRadiance,
              std::shared_ptr<const EnvironmentDistribution> environmentDistribution = nullptr);

  const EnvironmentLight& environment() const { return environment_; }
  const std::vector<Emitter>& emitters() const { return emitters_; }
  float totalPower() const { return total_; }  // sum of the emitters' selection weights (mean flux)

  // Next-event estimation on emissive triangles: one triangle chosen in proportion to its power,
  // a point uniform on it. Returns the point as a hit and the probability of choosing the triangle.
  bool hasTriangles() const { return triangleTotal_ > 0.f; }
  bool sampleTriangle(float uSelect, glm::vec2 uPoint, SurfaceHit& point, float& pSelect) const;
  // Solid-angle pdf with which sampleTriangle() would have picked `hit` seen along dir from a point
  // at hit.distance.
  float trianglePdf(const SurfaceHit& hit, const glm::vec3& dir) const;

  // Emission of one particle (eq. 1 of Stürzlinger & Bastos: m_i proportional to Phi_i, each photon
  // carrying Phi / m): an emitter chosen in proportion to its power, then sampleLe(emitter). False when
  // nothing emits.
  bool sampleLe(Sampler& sampler, Emission& out) const;

  // Emission of emitter `i` (an emitters() index) from two uniform pairs (pbrt-v4 SampleLe):
  // - point: direction uniform on the sphere (u1); spot: uniform in the outer cone (u1);
  // - directional: origin uniform on the disk of the scene's bounding sphere across the beam (u1);
  // - triangle: origin uniform by area (u1), side (double-sided: u2.x < 1/2 is the back) and direction
  //   cosine-weighted about that side's normal (u2);
  // - environment: direction towards the sky by the map's importance (u1, EnvironmentLight::sample),
  //   origin uniform on the bounding disk across it (u2), travelling inwards.
  // False when the sample carries nothing (outside a spot's falloff, a zero-pdf direction).
  bool sampleLe(int i, glm::vec2 u1, glm::vec2 u2, LeSample& out) const;
  // The densities sampleLe(i) draws `ray` with (pbrt-v4 PDF_Le), for rays of the emitter's support
  // (a triangle's: origin on it): pdfPos over area, pdfDir over solid angle; 0 for the delta parts
  // (the position of a point or spot light, the direction of a directional light), which no other
  // strategy can hit, and 0 outside the support (beyond a spot's cone or the disk, behind a one-sided
  // triangle).
  void pdfLe(int i, const Ray& ray, float& pdfPos, float& pdfDir) const;
  // Radiant flux of emitter i (W, per channel): point 4 pi I, spot punctualPower, directional
  // E pi r^2 and environment pi r^2 \int L dw over the bounding disk of radius r, triangle
  // pi A L (twice for double-sided).
  const glm::vec3& power(int i) const { return emitters_.at(i).power; }
  // The disk directional light and the environment emit through (the scene's bounding sphere).
  glm::vec3 center() const { return center_; }
  float radius() const { return radius_; }

private:
  const RayScene& rays_;
  EnvironmentLight environment_;
  std::vector<Emitter> emitters_;
  std::vector<float> emitterCdf_;   // size + 1, by mean-channel power
  float total_ = 0.f;
  // Emissive triangles only (for NEE): power-proportional CDF over RayScene::triangleLights().
  std::vector<float> triangleCdf_;
  float triangleTotal_ = 0.f;
  glm::vec3 center_{0.f};
  float radius_ = 0.f;  // bounding sphere of the scene
};

}  // namespace radiant::rt
