// KHR_lights_punctual evaluation with glTF's numbers as they are: point and spot intensity I gives
// irradiance I cos / d^2; directional intensity is the irradiance itself. So a point light of
// intensity I lights a white Lambertian plane head-on at distance d with radiance I / (pi d^2).
#ifndef RADIANT_COMMON_LIGHTS
#define RADIANT_COMMON_LIGHTS
#include "common/scene.glsl"

// Incident direction (towards the light), distance, and the unshadowed irradiance factor
// (radiant intensity * falloff / d^2; without the cosine).
struct LightSample { vec3 wi; float dist; vec3 intensity; };

// KHR_lights_punctual's recommended range window (README, "Range Property"):
//   attenuation = max(min(1 - (d / range)^4, 1), 0) / d^2, range 0 = infinite.
// Not squared (that is Karis 2013's window, not the spec's). The one GLSL definition; rt::rangeWindow
// (renderer/raytracing/Lights.h) is the C++ one, and the parity test holds them equal.
float rangeWindow(float d, float range) {
  if (!(range > 0.0)) return 1.0;
  float q = d / range;
  return clamp(1.0 - (q * q) * (q * q), 0.0, 1.0);
}

// The spec's smooth spot falloff between cos(outer) and cos(inner), squared (README, "Inner and
// Outer Cone Angles"); rt::spotFalloff is the C++ twin.
float spotFalloff(Light l, vec3 wi) {
  float cd = dot(l.directionRange.xyz, -wi);
  float scale = 1.0 / max(0.001, l.spotCone.y - l.spotCone.x);
  float a = clamp(cd * scale - l.spotCone.x * scale, 0.0, 1.0);
  return a * a;
}

LightSample sampleLight(Light l, vec3 p) {
  LightSample s;
  int type = int(l.positionType.w);
  if (type == LIGHT_DIRECTIONAL) {
    s.wi = -l.directionRange.xyz;
    s.dist = 1e30;
    s.intensity = l.radiantIntensity.rgb;
    return s;
  }
  vec3 toLight = l.positionType.xyz - p;
  float d2 = max(dot(toLight, toLight), 1e-30);
  s.dist = sqrt(d2);
  s.wi = toLight / s.dist;
  s.intensity = l.radiantIntensity.rgb * rangeWindow(s.dist, l.directionRange.w) / d2;
  if (type == LIGHT_SPOT) s.intensity *= spotFalloff(l, s.wi);
  return s;
}
#endif
