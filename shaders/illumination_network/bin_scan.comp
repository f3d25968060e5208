// Visibility network, step 2 of 4: each direction's bins' start offsets (an exclusive prefix sum; one
// invocation per direction, M^2 bins each), and the fill counters reset for the scatter.
#include "illumination_network/network.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 2) readonly buffer BinCount { uint binCount[]; };
layout(std430, binding = 3) writeonly buffer BinStart { uint binStart[]; };
layout(std430, binding = 4) writeonly buffer BinFill { uint binFill[]; };

void main() {
  const int i = u_directionFirst + int(gl_GlobalInvocationID.x);
  if (i >= u_directions) return;
  const int bins = u_window * u_window;
  uint sum = 0u;
  for (int b = 0; b < bins; ++b) {
    binStart[i * bins + b] = sum;
    binFill[i * bins + b] = 0u;
    sum += binCount[i * bins + b];
  }
}
