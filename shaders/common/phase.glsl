// Phase functions of participating media, the GLSL twins of renderer/raytracing/Media.h (isotropic,
// Henyey-Greenstein, Cornette-Shanks = thesis eq. 1.3). mu = dot(propagation in, propagation out).
#ifndef RADIANT_COMMON_PHASE
#define RADIANT_COMMON_PHASE
#include "common/shared.h"

const float kPhasePi = 3.14159265358979323846;

float henyeyGreensteinPhase(float mu, float g) {
  const float denom = 1.0 + g * g - 2.0 * g * mu;
  return (1.0 - g * g) / (4.0 * kPhasePi * denom * sqrt(max(denom, 1e-12)));
}

float cornetteShanksPhase(float mu, float g) {
  const float denom = 1.0 + g * g - 2.0 * g * mu;
  return 3.0 * (1.0 - g * g) * (1.0 + mu * mu) / (8.0 * kPhasePi * (2.0 + g * g) * denom * sqrt(max(denom, 1e-12)));
}

float phaseValue(int model, float g, float mu) {
  if (model == kPhaseHenyeyGreenstein) return henyeyGreensteinPhase(mu, g);
  if (model == kPhaseCornetteShanks) return cornetteShanksPhase(mu, g);
  return 1.0 / (4.0 * kPhasePi);
}
#endif
