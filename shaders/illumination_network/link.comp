// Visibility network, step 4 of 4: V[p, i] = the node just before p along w_i in p's bin (the largest
// (depth, index) below p's: what a depth sort of the bin would put before it), or -1 when p is the
// first (the link then runs back to the bounding sphere). Link opacity alpha = 1 - exp(-tau_link
// length), tau_link the two nodes' mean extinction (p's own for the boundary link).
#include "illumination_network/network.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Nodes { NetworkNode nodes[]; };
layout(std430, binding = 1) readonly buffer Directions { NetworkDirection dirs[]; };
layout(std430, binding = 2) readonly buffer BinCount { uint binCount[]; };
layout(std430, binding = 3) readonly buffer BinStart { uint binStart[]; };
layout(std430, binding = 5) readonly buffer BinItems { int binItems[]; };
layout(std430, binding = 6) readonly buffer NodeBin { int nodeBin[]; };
layout(std430, binding = 7) writeonly buffer Upstream { int upstream[]; };
layout(std430, binding = 8) writeonly buffer Alpha { float alpha[]; };

void main() {
  const int p = int(gl_GlobalInvocationID.x), i = u_directionFirst + int(gl_GlobalInvocationID.y);
  if (p >= u_nodes || i >= u_directions) return;
  const vec3 w = dirs[i].w.xyz;
  const vec4 np = nodes[p].positionTau;
  const float zp = dot(np.xyz - u_center, w);
  const int at = i * u_window * u_window + nodeBin[i * u_nodes + p];
  const int start = int(binStart[at]), count = int(binCount[at]);
  int best = -1;
  float bestZ = 0.0;
  for (int k = 0; k < count; ++k) {
    const int q = binItems[i * u_nodes + start + k];
    const float zq = dot(nodes[q].positionTau.xyz - u_center, w);
    const bool before = zq < zp || (zq == zp && q < p);
    if (before && (best < 0 || zq > bestZ || (zq == bestZ && q > best))) best = q, bestZ = zq;
  }
  const int link = p * u_directions + i;
  upstream[link] = best;
  alpha[link] = best >= 0 ? 1.0 - exp(-0.5 * (np.w + nodes[best].positionTau.w) * (zp - bestZ))
                          : 1.0 - exp(-np.w * networkBoundaryDistance(w, np.xyz));
}
