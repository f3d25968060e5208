// One pass of the edge-aware à-trous filter (renderer/shading/Denoiser.h has the method and weights).
// u_first: t_in is the noisy radiance, demodulated here by the base colour; u_last: the result is
// re-modulated. Between passes the images hold demodulated radiance.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D t_in;
layout(binding = 1) uniform sampler2D t_position;  // xyz world, w view depth (0: no geometry)
layout(binding = 2) uniform sampler2D t_normal;    // xyz shading normal
layout(binding = 3) uniform sampler2D t_albedo;    // rgb base colour
layout(binding = 4) uniform sampler2D t_noisy;     // the unfiltered radiance (the non-finite fallback)
layout(rgba32f, binding = 0) uniform writeonly image2D i_out;

uniform ivec2 u_size;
uniform int u_step;
uniform int u_first;
uniform int u_last;
uniform float u_pixelAngle;      // world size of a pixel at view depth 1 (perspective), else 0
uniform float u_orthoPixel;      // world size of a pixel (orthographic), else 0
uniform float u_sigmaLuminance;  // sigma_luminance x the relative noise
uniform float u_sigmaNormal;
uniform float u_sigmaPlane;
uniform float u_minAlbedo;

float lum(vec3 c) { return dot(c, vec3(0.2126, 0.7152, 0.0722)); }
bool finite3(vec3 v) { return !any(isnan(v)) && !any(isinf(v)); }
vec3 albedoAt(ivec2 p) { return max(texelFetch(t_albedo, p, 0).rgb, vec3(u_minAlbedo)); }
vec3 valueAt(ivec2 p) {
  vec3 v = texelFetch(t_in, p, 0).rgb;
  return u_first != 0 ? v / albedoAt(p) : v;
}

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(p, u_size))) return;
  vec4 xp = texelFetch(t_position, p, 0);
  vec3 cp = valueAt(p);
  if (xp.w <= 0.0 || !finite3(cp)) {  // no geometry (or a non-finite input): left as it is
    imageStore(i_out, p, vec4(texelFetch(t_noisy, p, 0).rgb, 1.0));
    return;
  }
  vec3 np = texelFetch(t_normal, p, 0).xyz;
  float lp = lum(cp);
  float pixel = u_orthoPixel > 0.0 ? u_orthoPixel : xp.w * u_pixelAngle;
  float planeScale = 1.0 / max(u_sigmaPlane * pixel * float(u_step), 1e-30);
  const float kernel[3] = float[](0.375, 0.25, 0.0625);  // B3 spline
  vec3 sum = vec3(0.0);
  float weights = 0.0;
  for (int dy = -2; dy <= 2; ++dy)
    for (int dx = -2; dx <= 2; ++dx) {
      ivec2 q = p + ivec2(dx, dy) * u_step;
      if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, u_size))) continue;
      vec4 xq = texelFetch(t_position, q, 0);
      if (xq.w <= 0.0) continue;
      vec3 cq = valueAt(q);
      if (!finite3(cq)) continue;
      // The three edge-stopping weights as one exponential: normal max(0, cos)^sigma_normal =
      // exp(sigma_normal ln cos), plane, luminance (one exp and one log per tap instead of pow and two
      // exp: 240 -> 225 ms of llvmpipe's filter at 256 px, k = 2; a lattice-tiled version with the
      // taps in shared memory ran 2.5x slower there).
      float cosN = dot(np, texelFetch(t_normal, q, 0).xyz);
      if (cosN <= 0.0) continue;  // weight 0
      float lq = lum(cq);
      float e = abs(dot(np, xq.xyz - xp.xyz)) * planeScale +
                abs(lp - lq) / (u_sigmaLuminance * 0.5 * (abs(lp) + abs(lq)) + 1e-20) - u_sigmaNormal * log(cosN);
      float w = kernel[abs(dx)] * kernel[abs(dy)] * exp(-e);
      sum += w * cq;
      weights += w;
    }
  // The centre tap has weight kernel[0]^2 (every factor 1 for itself), so weights > 0.
  vec3 result = sum / weights;
  if (u_last != 0) result *= albedoAt(p);
  if (!finite3(result)) result = texelFetch(t_noisy, p, 0).rgb;
  imageStore(i_out, p, vec4(result, 1.0));
}
