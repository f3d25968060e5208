// Final gathering (thesis 8.1.3): blocks back to front, each as a screen quad covering its bounding
// sphere (common/sphere_quad.glsl); u_order maps the draw index to the block.
#include "common/shared.h"
#include "common/sphere_quad.glsl"
#include "depth_impostors/frame.glsl"
#include "common/frame.glsl"

layout(std430, binding = kBindingImpostorOrder) readonly buffer Order { int order[]; };

uniform float u_znear;
uniform int u_firstInstance;  // drawn in stretches (renderer/shading/Stretches.h)

flat out int v_block;

void main() {
  v_block = order[u_firstInstance + gl_InstanceID];
  const vec4 cr = blocks[v_block].centerRadius;
  gl_Position = sphereQuadVertex(cr.xyz, cr.w, gl_VertexID, u_frame.view, u_frame.proj, u_znear, u_frame.flags.x == 1);
}
