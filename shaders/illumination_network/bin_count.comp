// Visibility network, step 1 of 4: every node's bin per direction, and the bins' sizes (a counting
// sort per direction, thesis §9.1's depth peeling replaced by binning on the GPU).
#include "illumination_network/network.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Nodes { NetworkNode nodes[]; };
layout(std430, binding = 1) readonly buffer Directions { NetworkDirection dirs[]; };
layout(std430, binding = 2) buffer BinCount { uint binCount[]; };
layout(std430, binding = 6) writeonly buffer NodeBin { int nodeBin[]; };

void main() {
  const int p = int(gl_GlobalInvocationID.x), i = u_directionFirst + int(gl_GlobalInvocationID.y);
  if (p >= u_nodes || i >= u_directions) return;
  const int b = networkBin(dirs[i], nodes[p].positionTau.xyz);
  nodeBin[i * u_nodes + p] = b;
  atomicAdd(binCount[i * u_window * u_window + b], 1u);
}
