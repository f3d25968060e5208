// Final gathering of one block (thesis 8.1.3-8.1.4, Algorithm 6) at a pixel:
//   the pixel's ray meets the block plane (through its centre, normal to its view axis) in a texel of
//   its view impostor: transmittance T, front and back depth; along the ray Z_f = t_plane + front /
//   cos, Z_b = t_plane + back / cos;
//   objects in clouds: the part of [Z_f, Z_b] in front of the scene depth and behind the near plane,
//   the fraction f of it, scales the opacity: linear alpha' = (1 - T) f (the thesis), or
//   exponential alpha' = 1 - T^f (exact when the density is uniform along the interval);
//   light: the shadowed light's transmittance interpolated between the enclosing light slices, or
//   reconstructed from the Fourier opacity maps (light_transmittance: fourier),
//   (optionally the forward-scatter heuristic) at both ends of the visible interval, integrated over
//   it with the in-scattering's weight (shadowOverInterval); the lights' direction and intensity at
//   its middle; the other lights unshadowed;
//   colour L = source + albedo sum_lights phase(mu) I_light T_light, blended C = alpha' L + (1 - alpha') C.
#include "common/shared.h"
#include "common/lights.glsl"
#include "common/phase.glsl"
#include "depth_impostors/frame.glsl"
#include "common/frame.glsl"

layout(binding = kUnitGbufferPosition) uniform sampler2D t_position;  // gbuffer_position: xyz world, w view depth (0 = none)
layout(binding = 1) uniform sampler2D t_front;
layout(binding = 2) uniform sampler2D t_back;
layout(binding = 3) uniform sampler2D t_transmittance;
layout(binding = 4) uniform sampler2D t_slices0;
layout(binding = 5) uniform sampler2D t_slices1;
layout(binding = kUnitImpostorSlices2) uniform sampler2D t_slices2;
layout(binding = kUnitImpostorSlices3) uniform sampler2D t_slices3;

uniform int u_hasDepth;
uniform vec2 u_targetSize;
uniform ivec2 u_fullSize;
uniform int u_axisMode;
uniform vec3 u_axis;
uniform int u_res;
uniform int u_tilesX;
uniform int u_clipScaling;  // 0 linear, 1 exponential
uniform int u_lightCount;
uniform int u_shadowedLight;  // -1: none
uniform int u_slices;
uniform vec3 u_sliceCenter;
uniform vec3 u_sliceAxis;
uniform vec3 u_sliceU;
uniform vec3 u_sliceV;
uniform float u_sliceHalf;
uniform float u_sliceDmin;
uniform float u_sliceDmax;
uniform int u_forwardScatter;
uniform float u_sliceTexel;  // one slice texel in uv
uniform int u_fourierTerms;  // M > 0: Fourier opacity maps in the slice textures instead of slices
uniform float u_fourierNear;  // the cloud's near and far planes along the light (normalised depth 0, 1)
uniform float u_fourierFar;
uniform float u_fourierDamping[8];  // g_k, k = 1..M (Jackson kernel; impostors::fourierDamping)

flat in int v_block;
layout(location = 0) out vec4 o_color;

vec3 unproject(vec2 ndc, float depth) {
  const vec4 p = u_frame.invViewProj * vec4(ndc, depth, 1.0);
  return p.xyz / p.w;
}

float sliceValue(int k, vec2 uv) {
  const int t = k / 4, c = k % 4;
  vec4 v = t == 0 ? texture(t_slices0, uv) : t == 1 ? texture(t_slices1, uv) : t == 2 ? texture(t_slices2, uv)
                                                                               : texture(t_slices3, uv);
  return v[c];
}

// Knot j of the depth interpolation: 1 in front of the system, slice j - 1 behind group j - 1.
float knotValue(int j, vec2 uv) { return j == 0 ? 1.0 : sliceValue(j - 1, uv); }

float knotValueFiltered(int j, vec2 uv, int model, float g, vec3 dir) {
  if (u_forwardScatter == 0 || j == 0) return knotValue(j, uv);
  // Forward-scatter heuristic (thesis 8.1.3, "the pixels of both enclosing slices for which the phase
  // function is not negligible"): the 3 x 3 neighbourhood of the slice texel, each weighted by the
  // phase function towards the light direction from the neighbour one slice thickness away.
  const float thickness = (u_sliceDmax - u_sliceDmin) / float(u_slices);
  float sum = 0.0, wsum = 0.0;
  for (int y = -1; y <= 1; ++y)
    for (int x = -1; x <= 1; ++x) {
      const vec2 offset = vec2(x, y) * u_sliceTexel;
      const vec3 lateral = (offset.x * u_sliceU + offset.y * u_sliceV) * (2.0 * u_sliceHalf);
      const float mu = dot(normalize(u_sliceAxis * thickness - lateral), u_sliceAxis);
      const float w = phaseValue(model, g, mu);
      sum += w * knotValue(j, uv + offset);
      wsum += w;
    }
  return sum / wsum;
}

// Fourier opacity maps (Jansen and Bavoil 2010; impostors::fourierTransmittance in Blocks.h is the C++
// twin): the optical depth to normalised depth d is the truncated series' integral,
//   D(d) = a_0 d / 2 + sum_k g_k (a_k sin(2 pi k d) + b_k (1 - cos(2 pi k d))) / (2 pi k),
// with the Jackson damping g_k, whose kernel is non-negative: D is non-decreasing in d, in [0, a_0 / 2],
// and the transmittance exp(-D) non-increasing along the light (clamped too, against rounding).
float fourierTransmittanceAt(vec2 uv, float d) {
  const float TWO_PI = 6.28318530717958648;
  float c[16];  // the 2M + 1 coefficients, one fetch per RGBA texture in use
  const vec4 c0 = texture(t_slices0, uv);
  c[0] = c0.x, c[1] = c0.y, c[2] = c0.z, c[3] = c0.w;
  const vec4 c1 = u_fourierTerms >= 2 ? texture(t_slices1, uv) : vec4(0.0);
  c[4] = c1.x, c[5] = c1.y, c[6] = c1.z, c[7] = c1.w;
  const vec4 c2 = u_fourierTerms >= 4 ? texture(t_slices2, uv) : vec4(0.0);
  c[8] = c2.x, c[9] = c2.y, c[10] = c2.z, c[11] = c2.w;
  const vec4 c3 = u_fourierTerms >= 6 ? texture(t_slices3, uv) : vec4(0.0);
  c[12] = c3.x, c[13] = c3.y, c[14] = c3.z, c[15] = c3.w;
  const float a0 = c[0];
  float D = 0.5 * a0 * d;
  for (int k = 1; k <= u_fourierTerms; ++k) {
    const float o = TWO_PI * float(k);
    D += u_fourierDamping[k - 1] * (c[2 * k - 1] * sin(o * d) + c[2 * k] * (1.0 - cos(o * d))) / o;
  }
  return clamp(exp(-clamp(D, 0.0, max(0.5 * a0, 0.0))), 0.0, 1.0);
}

float fourierTransmittance(vec3 x, int model, float g) {
  const vec3 rel = x - u_sliceCenter;
  const vec2 uv = vec2(dot(rel, u_sliceU), dot(rel, u_sliceV)) / u_sliceHalf * 0.5 + 0.5;
  const float d = clamp((dot(rel, u_sliceAxis) - u_fourierNear) / max(u_fourierFar - u_fourierNear, 1e-30), 0.0, 1.0);
  if (u_forwardScatter == 0) return fourierTransmittanceAt(uv, d);
  // The forward-scatter heuristic as for the slices (knotValueFiltered): the 3 x 3 slice texels' values,
  // each weighted by the phase function towards the light from one slice thickness away (here the
  // thickness of the K = 4 ceil((2M + 1) / 4) slices of equal memory).
  const float thickness = (u_sliceDmax - u_sliceDmin) / float(4 * ((2 * u_fourierTerms + 4) / 4));
  float sum = 0.0, wsum = 0.0;
  for (int y = -1; y <= 1; ++y)
    for (int x = -1; x <= 1; ++x) {
      const vec2 offset = vec2(x, y) * u_sliceTexel;
      const vec3 lateral = (offset.x * u_sliceU + offset.y * u_sliceV) * (2.0 * u_sliceHalf);
      const float w = phaseValue(model, g, dot(normalize(u_sliceAxis * thickness - lateral), u_sliceAxis));
      sum += w * fourierTransmittanceAt(uv + offset, d);
      wsum += w;
    }
  return sum / wsum;
}

float lightTransmittance(vec3 x, int model, float g, vec3 dir) {
  if (u_fourierTerms > 0) return fourierTransmittance(x, model, g);
  const vec3 rel = x - u_sliceCenter;
  const vec2 uv = vec2(dot(rel, u_sliceU), dot(rel, u_sliceV)) / u_sliceHalf * 0.5 + 0.5;
  const float s = clamp((dot(rel, u_sliceAxis) - u_sliceDmin) / max(u_sliceDmax - u_sliceDmin, 1e-30) * float(u_slices),
                        0.0, float(u_slices));
  const int i = min(int(floor(s)), u_slices - 1);
  return mix(knotValueFiltered(i, uv, model, g, dir), knotValueFiltered(i + 1, uv, model, g, dir), s - float(i));
}

// The light's transmittance averaged over the visible interval with the weight of its in-scattering
// towards the eye: the interval's density is uniform (its optical depth D = -ln(1 - alpha), the
// assumption of the exponential clip scaling) and the light's transmittance is log-linear between its
// values at the near end, Tn, and the far end, Tf (exact for a homogeneous slab). With
// g = ln(Tf / Tn):
//   int_0^D e^-s Tn e^(g s / D) ds / (1 - e^-D) = (Tn - Tf e^-D) / (D - g) / ((1 - e^-D) / D).
// One value at the middle (Tn^(1/2) Tf^(1/2)) instead over-estimates by (1 - e^-D) e^(D/2) / D when
// the light comes from behind (Tn << Tf: 1.8x at D = 4) and under-estimates when it comes from the
// eye's side (e^-D/2 against (1 - e^-2D) / 2 / (1 - e^-D)).
float shadowOverInterval(float Tn, float Tf, float alpha) {
  const float D = -log(max(1.0 - alpha, 1e-30));
  Tn = max(Tn, 1e-30), Tf = max(Tf, 1e-30);
  const float kD = D - log(Tf / Tn);
  const float viewT = 1.0 - alpha;
  // (Tn - Tf e^-D) / (D - g), and its limit Tn (1 - kD / 2) where the two exponents cancel.
  const float integral = abs(kD) > 1e-3 ? (Tn - Tf * viewT) / kD : Tn * (1.0 - 0.5 * kD);
  const float norm = D > 1e-4 ? alpha / D : 1.0 - 0.5 * D;  // (1 - e^-D) / D
  return clamp(integral / norm, 0.0, max(Tn, Tf));
}

void main() {
  const ImpostorBlock B = blocks[v_block];
  const vec3 c = B.centerRadius.xyz;
  const float R = B.centerRadius.w;

  const vec2 uvScreen = gl_FragCoord.xy / u_targetSize;
  const vec2 ndc = uvScreen * 2.0 - 1.0;
  const vec3 o = unproject(ndc, 1.0);
  const vec3 dir = normalize(unproject(ndc, 0.5) - o);
  float tScene = 1e30;
  if (u_hasDepth == 1) {
    const vec4 s = texelFetch(t_position, clamp(ivec2(uvScreen * vec2(u_fullSize)), ivec2(0), u_fullSize - 1), 0);
    if (s.w > 0.0) tScene = dot(s.xyz - o, dir);
  }

  const vec3 a = impostorAxis(u_axisMode, u_axis, c);
  vec3 u, v;
  impostorBasis(a, u, v);
  const float cosA = dot(dir, a);
  if (!(cosA > 1e-4)) discard;
  const float tPlane = dot(c - o, a) / cosA;
  const vec3 q = o + tPlane * dir - c;
  const vec2 l = vec2(dot(q, u), dot(q, v));
  if (any(greaterThanEqual(abs(l), vec2(R)))) discard;
  const ivec2 texel = tileTexel(B.info.x, u_tilesX, u_res, l, R);
  const float T = texelFetch(t_transmittance, texel, 0).r;
  if (!(T < 1.0)) discard;
  const float zf = tPlane + texelFetch(t_front, texel, 0).r / cosA;
  const float zb = tPlane + texelFetch(t_back, texel, 0).r / cosA;
  const float t0 = max(zf, 0.0), t1 = min(zb, tScene);
  if (!(t1 > t0)) discard;
  const float f = clamp((t1 - t0) / max(zb - zf, 1e-30), 0.0, 1.0);
  const float alpha = u_clipScaling == 0 ? (1.0 - T) * f : 1.0 - pow(max(T, 0.0), f);
  if (!(alpha > 0.0)) discard;

  const vec3 x = o + 0.5 * (t0 + t1) * dir;  // the middle of the visible interval (notes §3)
  vec3 L = B.source.rgb;
  if (max(B.albedoG.r, max(B.albedoG.g, B.albedoG.b)) > 0.0) {
    vec3 in_ = vec3(0.0);
    for (int i = 0; i < u_lightCount; ++i) {
      const LightSample s = sampleLight(lights[i], x);
      float shadow = 1.0;
      if (i == u_shadowedLight)
        shadow = shadowOverInterval(lightTransmittance(o + t0 * dir, B.info.y, B.albedoG.w, dir),
                                    lightTransmittance(o + t1 * dir, B.info.y, B.albedoG.w, dir), alpha);
      in_ += phaseValue(B.info.y, B.albedoG.w, dot(s.wi, dir)) * s.intensity * shadow;  // mu = dot(-wi, -dir)
    }
    L += B.albedoG.rgb * in_;
  }
  o_color = vec4(L * alpha, alpha);
}
