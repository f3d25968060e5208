// Visibility network, step 3 of 4: the nodes listed bin by bin per direction (unordered within a bin).
#include "illumination_network/network.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 3) readonly buffer BinStart { uint binStart[]; };
layout(std430, binding = 4) buffer BinFill { uint binFill[]; };
layout(std430, binding = 5) writeonly buffer BinItems { int binItems[]; };
layout(std430, binding = 6) readonly buffer NodeBin { int nodeBin[]; };

void main() {
  const int p = int(gl_GlobalInvocationID.x), i = u_directionFirst + int(gl_GlobalInvocationID.y);
  if (p >= u_nodes || i >= u_directions) return;
  const int at = i * u_window * u_window + nodeBin[i * u_nodes + p];
  const uint slot = binStart[at] + atomicAdd(binFill[at], 1u);
  binItems[i * u_nodes + int(slot)] = p;
}
