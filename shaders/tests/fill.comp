// Test fixture: writes values[i] = i * 3 + OFFSET and PI into SSBOs, to be read back exactly.
#include "tests/include_ok.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) buffer Values { uint values[]; };
layout(std430, binding = 1) buffer Constants { float constants[]; };
uniform int count;
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i < uint(count)) values[i] = i * 3u + uint(OFFSET);
  if (i == 0u) {
    constants[0] = PI;
    constants[1] = includeOk();
  }
}
