// The second half of one iteration of the illumination network (thesis eq. 9.1, §9.1.2's array form,
// per link), with src from source.comp:
//   I'[p,i] = (1 - alpha) I[q,i] + alpha src[q,i]  (+ w(alpha) (src[p,i] - src[q,i]) when u_linearSource),
// q = V[p,i]; for a boundary link (q = -1) the sky instead of I[q,i] and p's own source. The linear
// term integrates a source varying linearly from q to p exactly, w = 1 - alpha / u with u the link's
// optical thickness (Network.cpp linearSourceWeight). The max-norm change of the iteration goes to
// residual[u_iteration] (atomicMax on the bits of a non-negative float, which order like the floats).
#include "illumination_network/network.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 7) readonly buffer Upstream { int upstream[]; };
layout(std430, binding = 8) readonly buffer Alpha { float alpha[]; };
layout(std430, binding = 10) readonly buffer RadianceIn { vec4 radianceIn[]; };
layout(std430, binding = 11) writeonly buffer RadianceOut { vec4 radianceOut[]; };
layout(std430, binding = 14) buffer Residual { uint residual[]; };
layout(std430, binding = 18) readonly buffer Source { vec4 source[]; };

uniform vec3 u_sky;
uniform int u_iteration;
uniform int u_linearSource;

float linearSourceWeight(float a) {
  if (!(a < 1.0)) return 1.0;
  const float u = -log(1.0 - a);
  return u > 1e-3 ? 1.0 - a / u : 0.5 * u;
}

void main() {
  const int link = int(gl_GlobalInvocationID.x);
  if (link >= u_nodes * u_directions) return;
  const int p = link / u_directions, i = link - p * u_directions;
  const int up = upstream[link];
  const int q = up >= 0 ? up : p;
  const vec3 incoming = up >= 0 ? radianceIn[q * u_directions + i].rgb : u_sky;
  const vec3 Sq = source[q * u_directions + i].rgb;
  const float a = alpha[link];
  vec3 I = (1.0 - a) * incoming + a * Sq;
  if (u_linearSource == 1) I += linearSourceWeight(a) * (source[link].rgb - Sq);
  radianceOut[link] = vec4(I, 0.0);
  const vec3 change = abs(I - radianceIn[link].rgb);
  atomicMax(residual[u_iteration], floatBitsToUint(max(change.r, max(change.g, change.b))));
}
