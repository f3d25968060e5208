#include "renderer/io/ToneMap.h"

#include <algorithm>
#include <cfloat>
#include <cmath>

namespace radiant::io {
namespace {

// Radiance is finite and non-negative: NaN and negative values count as 0, +Inf as the largest float.
// In double, every operator below stays finite for any float times 2^32 (the exposure's bound).
double radiance(float v) { return v > 0.f ? std::min(static_cast<double>(v), static_cast<double>(FLT_MAX)) : 0.0; }

double saturate(double v) { return v > 0.0 ? std::min(v, 1.0) : 0.0; }  // NaN -> 0
glm::dvec3 saturate(glm::dvec3 v) { return {saturate(v.x), saturate(v.y), saturate(v.z)}; }

// The matrices below are written as three.js writes them: GLSL mat3(column0, column1, column2), which
// is glm's constructor order too.

// Stephen Hill's fit of the ACES RRT + ODT (three.js RRTAndODTFit).
double rrtAndOdtFit(double x) {
  const double a = x * (x + 0.0245786) - 0.000090537;
  const double b = x * (0.983729 * x + 0.4329510) + 0.238081;  // > 0 for every real x
  return a / b;
}

// iolite's 6th-order polynomial of AgX's default contrast sigmoid on [0, 1] (three.js
// agxDefaultContrastApprox; mean error^2 3.67e-6).
double agxDefaultContrastApprox(double x) {
  const double x2 = x * x, x4 = x2 * x2;
  return 15.5 * x4 * x2 - 40.14 * x4 * x + 31.96 * x4 - 6.868 * x2 * x + 0.4298 * x2 + 0.1191 * x - 0.00232;
}

}  // namespace

glm::dvec3 toneMapAces(glm::dvec3 v) {
  // sRGB => XYZ => D65_2_D60 => AP1 => RRT_SAT
  static const glm::dmat3 kAcesInput(glm::dvec3(0.59719, 0.07600, 0.02840), glm::dvec3(0.35458, 0.90834, 0.13383),
                                     glm::dvec3(0.04823, 0.01566, 0.83777));
  // ODT_SAT => XYZ => D60_2_D65 => sRGB
  static const glm::dmat3 kAcesOutput(glm::dvec3(1.60475, -0.10208, -0.00327), glm::dvec3(-0.53108, 1.10813, -0.07276),
                                      glm::dvec3(-0.07367, -0.00605, 1.07602));
  glm::dvec3 c = kAcesInput * (v / 0.6);  // three.js: toneMappingExposure / 0.6
  c = {rrtAndOdtFit(c.x), rrtAndOdtFit(c.y), rrtAndOdtFit(c.z)};
  return saturate(kAcesOutput * c);
}

glm::dvec3 toneMapKhronosPbrNeutral(glm::dvec3 color) {
  constexpr double kStartCompression = 0.8 - 0.04;
  constexpr double kDesaturation = 0.15;
  // The offset removes a little of the darkest channel (at most 0.04) so that saturated colours keep
  // their hue under the compression.
  const double x = std::min({color.r, color.g, color.b});
  const double offset = x < 0.08 ? x - 6.25 * x * x : 0.04;
  color -= offset;
  const double peak = std::max({color.r, color.g, color.b});
  if (peak < kStartCompression) return saturate(color);
  const double d = 1.0 - kStartCompression;
  const double newPeak = 1.0 - d * d / (peak + d - kStartCompression);
  color *= newPeak / peak;
  const double g = 1.0 - 1.0 / (kDesaturation * (peak - newPeak) + 1.0);
  return saturate(glm::mix(color, glm::dvec3(newPeak), g));
}

glm::dvec3 toneMapAgx(glm::dvec3 color) {
  // Rec. ITU-R BT.2407 (three.js LINEAR_SRGB_TO_LINEAR_REC2020 and back).
  static const glm::dmat3 kSrgbToRec2020(glm::dvec3(0.6274, 0.0691, 0.0164), glm::dvec3(0.3293, 0.9195, 0.0880),
                                         glm::dvec3(0.0433, 0.0113, 0.8956));
  static const glm::dmat3 kRec2020ToSrgb(glm::dvec3(1.6605, -0.1246, -0.0182), glm::dvec3(-0.5876, 1.1329, -0.1006),
                                         glm::dvec3(-0.0728, -0.0083, 1.1187));
  static const glm::dmat3 kAgxInset(glm::dvec3(0.856627153315983, 0.137318972929847, 0.11189821299995),
                                    glm::dvec3(0.0951212405381588, 0.761241990602591, 0.0767994186031903),
                                    glm::dvec3(0.0482516061458583, 0.101439036467562, 0.811302368396859));
  static const glm::dmat3 kAgxOutset(glm::dvec3(1.1271005818144368, -0.1413297634984383, -0.14132976349843826),
                                     glm::dvec3(-0.11060664309660323, 1.157823702216272, -0.11060664309660294),
                                     glm::dvec3(-0.016493938717834573, -0.016493938717834257, 1.2519364065950405));
  constexpr double kMinEv = -12.47393;  // log2(2^-10 * 0.18): LOG2_MIN at middle grey
  constexpr double kMaxEv = 4.026069;   // log2(2^6.5 * 0.18): LOG2_MAX at middle grey
  glm::dvec3 v = kAgxInset * (kSrgbToRec2020 * color);
  for (int c = 0; c < 3; ++c) {
    const double encoded = (std::log2(std::max(v[c], 1e-10)) - kMinEv) / (kMaxEv - kMinEv);  // log2 encoding
    v[c] = agxDefaultContrastApprox(std::clamp(encoded, 0.0, 1.0));
  }
  v = kAgxOutset * v;
  for (int c = 0; c < 3; ++c) v[c] = std::pow(std::max(v[c], 0.0), 2.2);  // linearise
  return saturate(kRec2020ToSrgb * v);
}

glm::vec3 toneMap(api::ToneMap op, glm::vec3 linear, float exposureEV) {
  const double scale = std::exp2(static_cast<double>(exposureEV));
  const glm::dvec3 v = glm::dvec3(radiance(linear.r), radiance(linear.g), radiance(linear.b)) * scale;
  glm::dvec3 out;
  switch (op) {
    case api::ToneMap::Aces: out = toneMapAces(v); break;
    case api::ToneMap::KhronosPbrNeutral: out = toneMapKhronosPbrNeutral(v); break;
    case api::ToneMap::Agx: out = toneMapAgx(v); break;
    case api::ToneMap::Standard:
    default: out = saturate(v); break;
  }
  return glm::vec3(out);
}

}  // namespace radiant::io
