// Light slices (thesis 8.1.2): every block as a quad of its bounding square in the light's
// orthographic frame fitted to the whole system.
#include "common/shared.h"
#include "depth_impostors/frame.glsl"

uniform vec3 u_sliceCenter;
uniform vec3 u_sliceU;
uniform vec3 u_sliceV;
uniform float u_sliceHalf;

out vec2 v_offset;  // from the block centre in the slice plane (metres)
flat out int v_block;

void main() {
  const int i = gl_InstanceID;
  const ImpostorBlock B = blocks[i];
  const vec3 rel = B.centerRadius.xyz - u_sliceCenter;
  const int k = gl_VertexID;
  const vec2 corner = vec2((k == 1 || k == 2 || k == 4) ? 1.0 : -1.0, (k == 2 || k == 4 || k == 5) ? 1.0 : -1.0);
  v_offset = corner * B.centerRadius.w;
  v_block = i;
  gl_Position = vec4((vec2(dot(rel, u_sliceU), dot(rel, u_sliceV)) + v_offset) / u_sliceHalf, 0.5, 1.0);
}
