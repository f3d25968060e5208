// Final gathering over a receiver's low-resolution cube map (thesis Algorithm 1): every texel is a
// homogeneous area light, the quad between the points seen through its four corners.
// The quads are built by env_diffuse/quads.comp; the C++ mirror of the layout is EnvQuad in
// renderer/techniques/env_diffuse/EnvDiffuse.cpp (std430, 7 x vec4).
#ifndef RADIANT_ENV_DIFFUSE_GATHER
#define RADIANT_ENV_DIFFUSE_GATHER
#include "env_diffuse/form_factor.glsl"

#define ENV_METHOD_POLYGON 0
#define ENV_METHOD_POINT 1
#define ENV_METHOD_CLASSIC 2

struct EnvQuad {
  vec4 corner[4];     // world position (w = 1) or unit direction of a corner at infinity (w = 0)
  vec4 radiance;      // rgb: the texel's average radiance
  vec4 vplPosition;   // texel centre: world position (w = 1) or unit direction at infinity (w = 0)
  vec4 vplNormalArea; // xyz averaged normal, w: area (finite) or solid angle (at infinity)
};
layout(std430, binding = 4) readonly buffer EnvQuads { EnvQuad envQuads[]; };
uniform int u_quadCount;

// Irradiance E(x, n) = sum_i L_i F_i (F = projected solid angle, see form_factor.glsl).
vec3 gatherIrradiance(vec3 x, vec3 n, int method, bool horizonClip) {
  vec3 E = vec3(0.0);
  for (int i = 0; i < u_quadCount; ++i) {
    float F;
    if (method == ENV_METHOD_POINT) {
      vec4 y = envQuads[i].vplPosition;
      vec4 na = envQuads[i].vplNormalArea;
      F = y.w > 0.5 ? formFactorPointToPoint(x, n, y.xyz, na.xyz, na.w) : max(0.0, dot(n, y.xyz)) * na.w;
    } else {
      vec4 c0 = envQuads[i].corner[0], c1 = envQuads[i].corner[1];
      vec4 c2 = envQuads[i].corner[2], c3 = envQuads[i].corner[3];
      F = formFactorQuadToPoint(c0.w > 0.5 ? c0.xyz - x : c0.xyz, c1.w > 0.5 ? c1.xyz - x : c1.xyz,
                                c2.w > 0.5 ? c2.xyz - x : c2.xyz, c3.w > 0.5 ? c3.xyz - x : c3.xyz, n,
                                horizonClip);
    }
    E += envQuads[i].radiance.rgb * F;
  }
  return E;
}
#endif
