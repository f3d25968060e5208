// Diagnostics (caustics.energy_check): the power the caustic cube map of one generator deposits on
// its receivers, sum over texels of E Omega_texel d^2 / cos (thesis oracle: with area weight 1/3 it
// equals the photons' power, with 1/2 two thirds of it). d is the texel's deposit distance
// (deposit.frag), the receiver normal comes from the environment layer (exact for receivers that
// c_G sees); per work group partial sums.
layout(local_size_x = 8, local_size_y = 8) in;
#define LDM_TRACING
#include "specular/ldm.glsl"
#include "caustics/cube.glsl"

layout(rgba32f, binding = 1) readonly uniform imageCubeArray i_caustics;
layout(std430, binding = 5) writeonly buffer DepositSums { vec4 depositSums[]; };
uniform int u_generator;

shared vec4 s_sum[64];

void main() {
  ivec3 id = ivec3(gl_GlobalInvocationID);  // x, y, face
  uint li = gl_LocalInvocationIndex;
  int C = int(u_causticResolution);
  vec4 sum = vec4(0.0);
  if (id.x < C && id.y < C) {
    vec3 E = imageLoad(i_caustics, ivec3(id.xy, 6 * u_generator + id.z)).rgb;
    if (any(greaterThan(E, vec3(0.0)))) {
      vec2 st = (vec2(id.xy) + 0.5) / float(C) * 2.0 - 1.0;
      vec3 dir = normalize(faceDirection(id.z, st));
      vec4 geo = texture(t_ldmGeometry, vec4(dir, float(u_generator * u_layers + 2)));
      float d = depositDistance(imageLoad(i_caustics, ivec3(id.xy, 6 * u_generator + id.z)));
      if (geo.z > 0.0 && d > 0.0) {
        float cosR = max(abs(dot(octDecode(geo.xy), dir)), 1e-3);
        sum = vec4(E * texelSolidAngle(st) * d * d / cosR, 1.0);
      }
    }
  }
  s_sum[li] = sum;
  barrier();
  for (uint s = 32u; s > 0u; s >>= 1u) {
    if (li < s) s_sum[li] += s_sum[li + s];
    barrier();
  }
  if (li == 0u) {
    uint g = (gl_WorkGroupID.z * gl_NumWorkGroups.y + gl_WorkGroupID.y) * gl_NumWorkGroups.x + gl_WorkGroupID.x;
    depositSums[g] = s_sum[0];
  }
}
