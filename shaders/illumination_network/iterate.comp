// One iteration of the illumination network (thesis eq. 9.1, §9.1.2's array form, per link):
//   I'[p,i] = (1 - alpha) I[q,i] + alpha (e_q(w_i) + a_q sum_d W[d,i] I[q,d]),  q = V[p,i],
// and for a boundary link (q = -1) the sky instead of I[q,i] and p's own source. W holds the
// normalised phase quadrature (columns sum to 1), e_q the emission plus the single-scattered
// directional lights at their exact directions, attenuated by T_l(q). The max-norm change of the
// iteration goes to residual[u_iteration] (atomicMax on the bits of a non-negative float, which
// order like the floats).
#include "illumination_network/network.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Nodes { NetworkNode nodes[]; };
layout(std430, binding = 1) readonly buffer Directions { NetworkDirection dirs[]; };
layout(std430, binding = 7) readonly buffer Upstream { int upstream[]; };
layout(std430, binding = 8) readonly buffer Alpha { float alpha[]; };
layout(std430, binding = 9) readonly buffer Weights { float weights[]; };
layout(std430, binding = 10) readonly buffer RadianceIn { vec4 radianceIn[]; };
layout(std430, binding = 11) writeonly buffer RadianceOut { vec4 radianceOut[]; };
layout(std430, binding = 12) readonly buffer Lights { NetworkLight lights[]; };
layout(std430, binding = 13) readonly buffer Transmittance { float transmittance[]; };
layout(std430, binding = 14) buffer Residual { uint residual[]; };

uniform int u_lightCount;
uniform int u_phaseModel;
uniform float u_phaseG;
uniform vec3 u_sky;
uniform int u_iteration;

// e_q(w): emission and the directional lights scattered once (Network.cpp nodeSource).
vec3 nodeSource(int q, vec3 w) {
  vec3 e = nodes[q].emission.rgb;
  for (int l = 0; l < u_lightCount; ++l)
    e += nodes[q].albedo.rgb * phaseValue(u_phaseModel, u_phaseG, dot(lights[l].direction.xyz, w)) *
         lights[l].irradiance.rgb * transmittance[q * u_lightCount + l];
  return e;
}

void main() {
  const int link = int(gl_GlobalInvocationID.x);
  if (link >= u_nodes * u_directions) return;
  const int p = link / u_directions, i = link - p * u_directions;
  const int up = upstream[link];
  const int q = up >= 0 ? up : p;
  vec3 S = vec3(0.0);
  for (int d = 0; d < u_directions; ++d) S += weights[d * u_directions + i] * radianceIn[q * u_directions + d].rgb;
  const vec3 incoming = up >= 0 ? radianceIn[q * u_directions + i].rgb : u_sky;
  const float a = alpha[link];
  const vec3 I = (1.0 - a) * incoming + a * (nodeSource(q, dirs[i].w.xyz) + nodes[q].albedo.rgb * S);
  radianceOut[link] = vec4(I, 0.0);
  const vec3 change = abs(I - radianceIn[link].rgb);
  atomicMax(residual[u_iteration], floatBitsToUint(max(change.r, max(change.g, change.b))));
}
