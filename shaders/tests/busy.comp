// Test fixture: enough arithmetic per invocation that a GL_TIME_ELAPSED query around the dispatch
// measures a non-zero time even on a software rasteriser.
layout(local_size_x = 64) in;
layout(std430, binding = 0) buffer Result { float result[]; };
uniform int iterations;
void main() {
  uint i = gl_GlobalInvocationID.x;
  float x = float(i) * 1e-3;
  for (int k = 0; k < iterations; ++k) x = fract(sin(x) * 43758.5453 + 0.1);
  result[i] = x;
}
