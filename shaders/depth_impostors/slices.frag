// Light slices (thesis 8.1.2): slice k (channel k % 4 of texture k / 4, cleared to 1) receives the
// block's opacity when the block's group g <= k, else 0, blended dst (1 - src). Multiplication
// commutes, so the blocks need no sorting: slice k is the transmittance behind groups 0..k.
// Fourier opacity maps instead (u_fourierTerms M > 0; Jansen and Bavoil 2010; impostors::addFourierBox
// in Blocks.h is the C++ twin): the block's optical depth -ln T at the texel, spread uniformly over its
// light impostor's [front, back] there, as the closed-form Fourier coefficients a_0, a_k, b_k of that box
// over the normalised depth [0, 1] between the cloud's near and far planes; channel 0 a_0, 2k - 1 a_k,
// 2k b_k; added (blend ONE, ONE into targets cleared to 0): a sum commutes too.
#include "common/shared.h"
#include "depth_impostors/frame.glsl"

layout(binding = 0) uniform sampler2D t_lightTransmittance;  // the light impostors' atlas
layout(binding = 1) uniform sampler2D t_lightFront;          // Fourier only: their front and back depths
layout(binding = 2) uniform sampler2D t_lightBack;

uniform int u_axisMode;
uniform vec3 u_axis;
uniform vec3 u_sliceU;
uniform vec3 u_sliceV;
uniform int u_res;
uniform int u_tilesX;
uniform int u_slices;
uniform int u_fourierTerms;  // 0: slices
uniform vec3 u_sliceAxis;
uniform float u_zNear;       // the cloud's near and far planes along the light, from the slice centre
uniform float u_zFar;
uniform vec3 u_sliceCenter;

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
  const ivec2 texel = tileTexel(B.info.x, u_tilesX, u_res, l, R);
  const float alpha = 1.0 - texelFetch(t_lightTransmittance, texel, 0).r;
  if (!(alpha > 0.0)) discard;
  float s[kMaxImpostorSlices];
  if (u_fourierTerms > 0) {
    const float tau = -log(max(1.0 - alpha, 1e-30));
    const float zc = dot(B.centerRadius.xyz - u_sliceCenter, u_sliceAxis);
    const float span = max(u_zFar - u_zNear, 1e-30);
    const float d0 = clamp((zc + texelFetch(t_lightFront, texel, 0).r - u_zNear) / span, 0.0, 1.0);
    const float d1 = clamp((zc + texelFetch(t_lightBack, texel, 0).r - u_zNear) / span, d0, 1.0);
    const float w = d1 - d0, TWO_PI = 6.28318530717958648;
    for (int k = 0; k < kMaxImpostorSlices; ++k) s[k] = 0.0;
    s[0] = 2.0 * tau;
    for (int k = 1; k <= u_fourierTerms; ++k) {
      const float o = TWO_PI * float(k);
      if (w > 1e-5) {
        s[2 * k - 1] = 2.0 * tau * (sin(o * d1) - sin(o * d0)) / (o * w);
        s[2 * k] = 2.0 * tau * (cos(o * d0) - cos(o * d1)) / (o * w);
      } else {  // a delta at the middle
        const float m = 0.5 * (d0 + d1);
        s[2 * k - 1] = 2.0 * tau * cos(o * m);
        s[2 * k] = 2.0 * tau * sin(o * m);
      }
    }
  } else {
    for (int k = 0; k < kMaxImpostorSlices; ++k) s[k] = (B.info.z <= k && k < u_slices) ? alpha : 0.0;
  }
  o_slices0 = vec4(s[0], s[1], s[2], s[3]);
  o_slices1 = vec4(s[4], s[5], s[6], s[7]);
  o_slices2 = vec4(s[8], s[9], s[10], s[11]);
  o_slices3 = vec4(s[12], s[13], s[14], s[15]);
}
