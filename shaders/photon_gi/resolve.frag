// indirect = accumulated photon radiance, divided by the kernel mass that lies on the pixel's surface
// when renormalising (the coverage points' sum: 1 inside a surface, 1/2 at a straight edge, 1/4 at a
// right-angled corner); added to beauty by additive blending.
layout(binding = 0) uniform sampler2D t_accum;
uniform int u_renormalize;
uniform float u_minKernelMass;
layout(location = 0) out vec4 o_indirect;
layout(location = 1) out vec4 o_beauty;

void main() {
  vec4 a = texelFetch(t_accum, ivec2(gl_FragCoord.xy), 0);
  vec3 L = a.rgb;
  if (u_renormalize != 0 && a.a > 0.0) L /= max(a.a, u_minKernelMass);
  o_indirect = vec4(L, 1.0);
  o_beauty = vec4(L, 0.0);
}
