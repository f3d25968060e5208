// Optical depth of a particle sphere along a line, the GLSL twin of rt::sphereOpticalDepth
// (renderer/raytracing/Media.h); read by the media techniques (spherical_billboards, depth_impostors).
#ifndef RADIANT_COMMON_PARTICLE_DENSITY
#define RADIANT_COMMON_PARTICLE_DENSITY
#include "common/shared.h"

// 2 \int_0^t sqrt(d^2 + s^2) ds.
float falloffG(float t, float d) { return t * sqrt(d * d + t * t) + (d > 0.0 ? d * d * asinh(t / d) : 0.0); }

// Optical depth of [a, b] (line parameters from the closest point to the centre, at distance d).
float segmentDepth(int profile, float tau, float r, float d, float a, float b) {
  if (!(b > a)) return 0.0;
  if (profile == kProfileConstant) return tau * (b - a);
  if (profile == kProfileThesis) return tau * (1.0 - d / r) * (b - a);  // eq. 7.4
  return max(0.0, tau * ((b - a) - (falloffG(b, d) - falloffG(a, d)) / (2.0 * r)));
}
#endif
