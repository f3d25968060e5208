// Vertex areas and irradiance (thesis 6.1.2 and 6.2): per vertex of the photon hit image,
// dA_v = k sum A_t over its drawn triangles and I_v = dPhi_v / dA_v. Also sums, per work group, the
// power of the valid photons and of those that belong to no drawn triangle (lost at the boundary).
layout(local_size_x = 8, local_size_y = 8) in;
#include "caustics/grid.glsl"

layout(rgba32f, binding = 0) writeonly uniform image2D o_vertex;  // rgb I_v, a sum A_t (0: no triangle)
layout(std430, binding = 5) writeonly buffer PowerSums { vec4 powerSums[]; };  // 2 per work group
uniform float u_areaWeight;

shared vec4 s_valid[64];
shared vec4 s_lost[64];

void main() {
  ivec2 v = ivec2(gl_GlobalInvocationID.xy);
  uint li = gl_LocalInvocationIndex;
  vec4 valid = vec4(0.0), lost = vec4(0.0);
  if (all(lessThan(v, ivec2(u_photonResolution)))) {
    vec4 outv = vec4(0.0);
    if (vertexValid(v)) {
      int count;
      float sumA = adjacentArea(v, count);
      vec3 phi = vertexPower(v);
      valid = vec4(phi, 1.0);
      if (count == 0) lost = vec4(phi, 1.0);
      // Zero-area neighbourhoods (a focus) get no finite I; the triangle pass deposits their power
      // over one texel instead (triangles.geom), so I = 0 here keeps every value finite.
      float dA = u_areaWeight * sumA;
      outv = vec4(dA > 0.0 ? phi / dA : vec3(0.0), sumA);
      if (any(isinf(outv.rgb)) || any(isnan(outv.rgb))) outv.rgb = vec3(0.0);
    }
    imageStore(o_vertex, v, outv);
  }
  s_valid[li] = valid;
  s_lost[li] = lost;
  barrier();
  for (uint s = 32u; s > 0u; s >>= 1u) {
    if (li < s) {
      s_valid[li] += s_valid[li + s];
      s_lost[li] += s_lost[li + s];
    }
    barrier();
  }
  if (li == 0u) {
    uint g = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
    powerSums[2u * g] = s_valid[0];
    powerSums[2u * g + 1u] = s_lost[0];
  }
}
