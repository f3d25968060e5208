#pragma once
// Participating-media math of the ray-tracing core, shared by the volumetric reference and the media
// techniques (their CPU sides and tests): phase functions with their samplers, the optical depth of a
// particle sphere along a ray in closed form, and black-body colour.
//
// Conventions: mu = dot(propagation in, propagation out) (so g > 0 scatters forward); tau is the
// extinction per metre at a particle's centre; lengths in metres.
#include <algorithm>
#include <cmath>

#include <glm/glm.hpp>

#include "api/Media.h"
#include "renderer/raytracing/Bsdf.h"

namespace radiant::rt {

// ---- phase functions (each integrates to 1 over the sphere) -----------------------------------

inline float isotropicPhase() { return 1.f / (4.f * kPi); }

// Henyey-Greenstein; mean cosine g.
inline float henyeyGreensteinPhase(float mu, float g) {
  const float denom = 1.f + g * g - 2.f * g * mu;
  return (1.f - g * g) / (4.f * kPi * denom * std::sqrt(std::max(denom, 1e-12f)));
}

// Cornette-Shanks (thesis eq. 1.3, which the thesis calls Henyey-Greenstein): g = 0 is Rayleigh,
// 3 (1 + mu^2) / (16 pi); the mean cosine is 3g(4 + g^2) / (5(2 + g^2)), not g.
inline float cornetteShanksPhase(float mu, float g) {
  const float denom = 1.f + g * g - 2.f * g * mu;
  return 3.f * (1.f - g * g) * (1.f + mu * mu) /
         (4.f * kPi * 2.f * (2.f + g * g) * denom * std::sqrt(std::max(denom, 1e-12f)));
}

inline float phaseValue(api::PhaseModel m, float g, float mu) {
  switch (m) {
    case api::PhaseModel::HenyeyGreenstein: return henyeyGreensteinPhase(mu, g);
    case api::PhaseModel::CornetteShanks: return cornetteShanksPhase(mu, g);
    default: return isotropicPhase();
  }
}

// The cosine of an HG-distributed direction (inverse CDF, pbrt-v4 SampleHenyeyGreenstein).
inline float sampleHenyeyGreensteinCos(float g, float u) {
  if (std::abs(g) < 1e-3f) return 1.f - 2.f * u;
  const float s = (1.f - g * g) / (1.f + g - 2.f * g * u);
  return std::clamp((1.f + g * g - s * s) / (2.f * g), -1.f, 1.f);
}

// A direction of propagation after scattering of `dir` (unit), distributed as HG with the model's g
// (isotropic for isotropic); `weight` = phase / pdf (1 for isotropic and HG; Cornette-Shanks is
// sampled through HG and weighted).
inline glm::vec3 samplePhase(api::PhaseModel m, float g, const glm::vec3& dir, glm::vec2 u, float& weight) {
  const float gs = m == api::PhaseModel::Isotropic ? 0.f : g;
  const float cosT = sampleHenyeyGreensteinCos(gs, u.x);
  const float sinT = safeSqrt(1.f - cosT * cosT), phi = 2.f * kPi * u.y;
  const ShadingFrame f = ShadingFrame::fromNormal(dir);
  const glm::vec3 out = f.toWorld(glm::vec3(sinT * std::cos(phi), sinT * std::sin(phi), cosT));
  const float pdf = gs == 0.f ? isotropicPhase() : henyeyGreensteinPhase(cosT, gs);
  weight = m == api::PhaseModel::CornetteShanks ? cornetteShanksPhase(cosT, g) / pdf : 1.f;
  return glm::normalize(out);
}

// ---- optical depth of one particle ------------------------------------------------------------

// The profile whose density the reference integrates: eq. 7.4 is an opacity heuristic, its density is
// the linear falloff it approximates.
inline bool linearDensity(api::DensityProfile p) { return p != api::DensityProfile::Constant; }

// G(t) = t sqrt(d^2 + t^2) + d^2 asinh(t / d): 2 \int_0^t sqrt(d^2 + s^2) ds.
inline double linearFalloffG(double t, double d) {
  return t * std::sqrt(d * d + t * t) + (d > 0.0 ? d * d * std::asinh(t / d) : 0.0);
}

// Optical depth of a sphere (radius r, centre tau) along a line at distance d from its centre,
// between line parameters a <= b measured from the closest point (so the chord is [-w, w],
// w = sqrt(r^2 - d^2)); [a, b] is clipped to the chord. Constant: tau (b - a). Linear falloff
// tau (1 - |x - c| / r): tau [(b - a) - (G(b) - G(a)) / (2r)] (notes §2 oracle 5).
inline double sphereOpticalDepth(bool linear, double tau, double r, double d, double a, double b) {
  if (!(d < r)) return 0.0;
  const double w = std::sqrt(r * r - d * d);
  a = std::max(a, -w), b = std::min(b, w);
  if (!(b > a)) return 0.0;
  if (!linear) return tau * (b - a);
  return std::max(0.0, tau * ((b - a) - (linearFalloffG(b, d) - linearFalloffG(a, d)) / (2.0 * r)));
}

// The full chord of the linear falloff, tau [w - (d^2 / r) ln((r + w) / d)] (tau r at d = 0).
inline double linearChordOpticalDepth(double tau, double r, double d) {
  if (!(d < r)) return 0.0;
  const double w = std::sqrt(r * r - d * d);
  return tau * (w - (d > 0.0 ? d * d / r * std::log((r + w) / d) : 0.0));
}

// Thesis eq. 7.4's exponent for a full chord: tau (1 - d/r) 2w (a heuristic: 2 tau r at d = 0,
// twice the linear profile's true tau r).
inline double thesisChordOpticalDepth(double tau, double r, double d) {
  if (!(d < r)) return 0.0;
  return tau * (1.0 - d / r) * 2.0 * std::sqrt(r * r - d * d);
}

// Extinction of one particle at distance `dist` from its centre.
inline float particleDensity(bool linear, float tau, float r, float dist) {
  if (!(dist < r)) return 0.f;
  return linear ? tau * (1.f - dist / r) : tau;
}

// ---- black body ---------------------------------------------------------------------------------

// Planck's spectral radiance B(lambda, T) in W / (m^2 sr m), with 2hc^2 (the thesis' C1 = 2 pi hc^2
// gives the exitance, 2 pi times too large for a radiance). Evaluated as lambda^-5 e^-x / (1 - e^-x),
// x = C2 / (lambda T), in double: no overflow as T -> 0 (it returns 0).
inline double planckRadiance(double lambdaMetres, double kelvin) {
  constexpr double k2hc2 = 1.191042972e-16;  // W m^2 / sr
  constexpr double kC2 = 1.438776877e-2;     // m K
  if (!(kelvin > 0.0) || !(lambdaMetres > 0.0)) return 0.0;
  const double x = kC2 / (lambdaMetres * kelvin);
  if (x > 700.0) return 0.0;
  const double l5 = std::pow(lambdaMetres, 5.0);
  return k2hc2 / l5 * std::exp(-x) / -std::expm1(-x);
}

// CIE 1931 2-degree colour-matching functions, the multi-lobe fit of Wyman, Sloan and Shirley,
// "Simple Analytic Approximations to the CIE XYZ Color Matching Functions" (JCGT 2(2), 2013), eq. 2.
inline glm::dvec3 cieXyzMatching(double lambdaNm) {
  auto g = [lambdaNm](double mu, double s1, double s2) {
    const double t = (lambdaNm - mu) / (lambdaNm < mu ? s1 : s2);
    return std::exp(-0.5 * t * t);
  };
  return {1.056 * g(599.8, 37.9, 31.0) + 0.362 * g(442.0, 16.0, 26.7) - 0.065 * g(501.1, 20.4, 26.2),
          0.821 * g(568.8, 46.9, 40.5) + 0.286 * g(530.9, 16.3, 31.1),
          1.217 * g(437.0, 11.8, 36.0) + 0.681 * g(459.0, 26.0, 13.8)};
}

// \int B(lambda, T) {xbar, ybar, zbar} dlambda over 360-830 nm (1 nm steps, midpoint rule), W/(m^2 sr).
inline glm::dvec3 blackbodyXyz(double kelvin) {
  glm::dvec3 sum(0.0);
  for (int i = 0; i < 470; ++i) {
    const double nm = 360.5 + i;
    sum += planckRadiance(nm * 1e-9, kelvin) * cieXyzMatching(nm) * 1e-9;
  }
  return sum;
}

// CIE XYZ -> linear sRGB (D65), IEC 61966-2-1.
inline glm::dvec3 xyzToLinearSrgb(const glm::dvec3& c) {
  return {3.2404542 * c.x - 1.5371385 * c.y - 0.4985314 * c.z,
          -0.9692660 * c.x + 1.8760108 * c.y + 0.0415560 * c.z,
          0.0556434 * c.x - 0.2040259 * c.y + 1.0572252 * c.z};
}

// The temperature at which a fire's emission_scale is its luminance (api::ParticleSystem).
inline constexpr double kBlackbodyReferenceKelvin = 3000.0;

// Fire radiance per unit emission_scale: the black body's linear sRGB (negative components, outside
// the gamut, clamped to 0) divided by Y(3000 K), so 3000 K has Y = 1. Finite for every T >= 0.
inline glm::vec3 blackbodyRgb(double kelvin) {
  static const double kYRef = blackbodyXyz(kBlackbodyReferenceKelvin).y;
  const glm::dvec3 rgb = xyzToLinearSrgb(blackbodyXyz(kelvin)) / kYRef;
  return glm::vec3(glm::max(rgb, glm::dvec3(0.0)));
}

}  // namespace radiant::rt
