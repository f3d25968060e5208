// GPU half of the GPU/CPU parity test (tests/gl/materials/parity_test.cpp): evaluates the GLSL
// material model on inputs written by the test, one invocation per case. One of PARITY_BRDF,
// PARITY_SAMPLE, PARITY_LIGHT, PARITY_MATERIAL is defined. The results are compared with the C++ twins.
// Compute shaders have no derivatives: material textures are read at their base level (surfaceUvPoint).
#include "common/brdf.glsl"
#include "common/lights.glsl"
#include "common/material.glsl"

layout(local_size_x = 64) in;
uniform int u_count;

#if defined(PARITY_BRDF)
// n, wo, wi (w = eta), the decoded material, the clear coat's normal.
struct BrdfCase { vec4 n; vec4 wo; vec4 wi; MaterialParams p; vec4 nc; };
layout(std430, binding = 3) readonly buffer Cases { BrdfCase cases[]; };
layout(std430, binding = 4) writeonly buffer Results { vec4 results[]; };
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= uint(u_count)) return;
  BrdfCase c = cases[i];
  results[i] = vec4(gltfBsdfCos(c.n.xyz, c.nc.xyz, c.wo.xyz, c.wi.xyz, c.p, c.wi.w), 0.0);
}

#elif defined(PARITY_SAMPLE)
// The BRDF case (wi unused but for w = eta), the random numbers, and x = 1 for importance transport.
struct SampleCase { vec4 n; vec4 wo; vec4 wi; MaterialParams p; vec4 nc; vec4 u; vec4 mode; };
layout(std430, binding = 3) readonly buffer Cases { SampleCase cases[]; };
// Per case: (wi, pdf), (weight, flags), (valid, delta, 0, 0).
layout(std430, binding = 4) writeonly buffer Results { vec4 results[]; };
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= uint(u_count)) return;
  SampleCase c = cases[i];
  MaterialSample s = sampleMaterial(c.n.xyz, c.nc.xyz, c.wo.xyz, c.p, c.wi.w, c.mode.x != 0.0, c.u);
  results[3 * i + 0] = vec4(s.wi, s.pdf);
  results[3 * i + 1] = vec4(s.weight, float(s.flags));
  results[3 * i + 2] = vec4(s.valid ? 1.0 : 0.0, s.delta ? 1.0 : 0.0, 0.0, 0.0);
}

#elif defined(PARITY_LIGHT)
// xyz the shaded point, w the light index into lights[].
layout(std430, binding = 3) readonly buffer Cases { vec4 cases[]; };
// Per case: (intensity rgb, distance), (wi, 0), (rangeWindow, spotFalloff, 0, 0).
layout(std430, binding = 4) writeonly buffer Results { vec4 results[]; };
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= uint(u_count)) return;
  vec4 c = cases[i];
  Light l = lights[int(c.w)];
  LightSample s = sampleLight(l, c.xyz);
  results[3 * i + 0] = vec4(s.intensity, s.dist);
  results[3 * i + 1] = vec4(s.wi, 0.0);
  results[3 * i + 2] = vec4(rangeWindow(s.dist, l.directionRange.w), spotFalloff(l, s.wi), 0.0, 0.0);
}

#elif defined(PARITY_MATERIAL)
// xy uv0, zw uv1 of one point on a mesh of material u_material, whose (constant) interpolated normal
// and tangent are u_normal and u_tangent.
uniform int u_material;
uniform int u_first;  // index of this dispatch's first case
uniform vec3 u_normal;
uniform vec4 u_tangent;
uniform int u_front;  // 0: the point is seen from the back of a double-sided surface
layout(std430, binding = 3) readonly buffer Cases { vec4 cases[]; };
layout(std430, binding = 4) writeonly buffer Results { MaterialParams results[]; };
layout(std430, binding = 5) writeonly buffer Normals { vec4 normals[]; };
layout(std430, binding = 6) writeonly buffer CoatNormals { vec4 coatNormals[]; };  // KHR_materials_clearcoat
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= uint(u_count)) return;
  uint k = uint(u_first) + i;
  vec4 c = cases[k];
  Material m = materials[u_material];
  SurfaceUv uv = surfaceUvPoint(c.xy, c.zw);
  results[k] = decodeMaterial(m, uv);
  normals[k] = vec4(decodeShadingNormal(m, normalize(u_normal), u_tangent, uv, u_front != 0), 0.0);
  coatNormals[k] = vec4(decodeCoatNormal(m, normalize(u_normal), u_tangent, uv, u_front != 0), 0.0);
}
#endif
