// Light slices (thesis 8.1.2): slice k (channel k % 4 of texture k / 4, cleared to 1) receives the
// block's opacity when the block's group g <= k, else 0, blended dst (1 - src). Multiplication
// commutes, so the blocks need no sorting: slice k is the transmittance behind groups 0..k.
#include "common/shared.h"
#include "depth_impostors/frame.glsl"

layout(binding = 0) uniform sampler2D t_lightTransmittance;  // the light impostors' atlas

uniform int u_axisMode;
uniform vec3 u_axis;
uniform vec3 u_sliceU;
uniform vec3 u_sliceV;
uniform int u_res;
uniform int u_tilesX;
uniform int u_slices;

in vec2 v_offset;
flat in int v_block;
layout(location = 0) out vec4 o_slices0;
layout(location = 1) out vec4 o_slices1;
layout(location = 2) out vec4 o_slices2;
layout(location = 3) out vec4 o_slices3;

void main() {
  const ImpostorBlock B = blocks[v_block];
  const float R = B.centerRadius.w;
  // The block's own impostor frame (the same as the slices' for a directional light).
  vec3 u, v;
  impostorBasis(impostorAxis(u_axisMode, u_axis, B.centerRadius.xyz), u, v);
  const vec3 off = v_offset.x * u_sliceU + v_offset.y * u_sliceV;
  const vec2 l = vec2(dot(off, u), dot(off, v));
  if (any(greaterThanEqual(abs(l), vec2(R)))) discard;
  const float alpha = 1.0 - texelFetch(t_lightTransmittance, tileTexel(B.info.x, u_tilesX, u_res, l, R), 0).r;
  if (!(alpha > 0.0)) discard;
  float s[kMaxImpostorSlices];
  for (int k = 0; k < kMaxImpostorSlices; ++k) s[k] = (B.info.z <= k && k < u_slices) ? alpha : 0.0;
  o_slices0 = vec4(s[0], s[1], s[2], s[3]);
  o_slices1 = vec4(s[4], s[5], s[6], s[7]);
  o_slices2 = vec4(s[8], s[9], s[10], s[11]);
  o_slices3 = vec4(s[12], s[13], s[14], s[15]);
}
