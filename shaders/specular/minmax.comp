// Min-max distance of every layer (thesis 5.1.2, "Acceleration with min-max distance values"): one
// invocation per texel of one cube (6 faces), atomics on the float bits (positive floats order like
// their unsigned bit patterns). Empty texels (distance 0) are skipped.
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
layout(binding = 0, rgba32f) readonly uniform imageCubeArray i_geometry;
layout(std430, binding = 4) buffer LayerMinMax { uint layerMinMax[]; };
uniform int u_cube;  // cube index (object * layers + layer)
uniform int u_size;

void main() {
  ivec3 g = ivec3(gl_GlobalInvocationID);
  if (g.x >= u_size || g.y >= u_size || g.z >= 6) return;
  float d = imageLoad(i_geometry, ivec3(g.xy, u_cube * 6 + g.z)).z;
  if (!(d > 0.0) || isinf(d)) return;
  atomicMin(layerMinMax[2 * u_cube], floatBitsToUint(d));
  atomicMax(layerMinMax[2 * u_cube + 1], floatBitsToUint(d));
}
