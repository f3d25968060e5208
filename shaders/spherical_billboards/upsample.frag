// Layer composition at a lower resolution (thesis 7.2.3): the particle layer rendered at ratio s is
// brought to full resolution. depth_aware (u_depthAware 1): bilinear weights times the similarity of
// each low-resolution sample's scene depth to this pixel's, so layers do not halo across depth edges;
// 0: plain bilinear. A low-resolution pixel's scene depth is the full-resolution depth its shader read.
in vec2 v_uv;
layout(binding = 0) uniform sampler2D t_low;       // RGB premultiplied radiance, A transmittance
layout(binding = 1) uniform sampler2D t_position;  // gbuffer_position (w view depth, 0 = none)
uniform int u_hasDepth;
uniform int u_depthAware;
uniform ivec2 u_lowSize;
uniform ivec2 u_fullSize;
layout(location = 0) out vec4 o_media;

float viewDepth(ivec2 full) {
  if (u_hasDepth == 0) return 1e30;
  const float w = texelFetch(t_position, clamp(full, ivec2(0), u_fullSize - 1), 0).w;
  return w > 0.0 ? w : 1e30;
}

void main() {
  const ivec2 p = ivec2(gl_FragCoord.xy);
  const vec2 scale = vec2(u_lowSize) / vec2(u_fullSize);
  const vec2 q = (vec2(p) + 0.5) * scale - 0.5;
  const ivec2 base = ivec2(floor(q));
  const vec2 f = q - vec2(base);
  const float z = viewDepth(p);
  vec4 sum = vec4(0.0);
  float wsum = 0.0;
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) {
      const ivec2 n = clamp(base + ivec2(i, j), ivec2(0), u_lowSize - 1);
      float w = (i == 0 ? 1.0 - f.x : f.x) * (j == 0 ? 1.0 - f.y : f.y);
      if (u_depthAware == 1) {
        const float zn = viewDepth(ivec2((vec2(n) + 0.5) / scale));
        const float rel = abs(zn - z) / max(min(z, zn), 1e-6);
        w *= 1.0 / (1e-3 + rel * rel * 1e4);
      }
      sum += w * texelFetch(t_low, n, 0);
      wsum += w;
    }
  o_media = wsum > 0.0 ? sum / wsum : vec4(0.0, 0.0, 0.0, 1.0);
}
