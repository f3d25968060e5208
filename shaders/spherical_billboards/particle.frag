// Spherical billboards (thesis Algorithm 5, eqs. 7.1-7.4) and the two baselines, per fragment:
// the length the pixel's ray travels inside the particle sphere, clamped to the near plane and the
// scene depth, becomes the opacity alpha = 1 - exp(-optical depth); the particle's source radiance is
// blended premultiplied, C = alpha L + (1 - alpha) C, and the target's alpha keeps the product of
// (1 - alpha): the transmittance (independent of the draw order).
//   method 0 spherical, chord 0 exact: the ray-sphere chord along the actual ray (distances along the
//            ray, scene depth as the ray distance to the surface); profiles constant, linear_exact
//            (closed form, renderer/raytracing/Media.h) or thesis (eq. 7.4's tau (1 - d/r) ds).
//   method 0 spherical, chord 1 screen_parallel: eqs. 7.1-7.3 as printed: rays parallel to the view
//            axis, |F| = z_p - w, |B| = z_p + w, ds = min(Z_s, |B|) - max(f, |F|) in view depth.
//   method 1 planar: a classic billboard through the centre: the full chord's opacity where the
//            billboard plane lies between the near plane and the scene (clipping and popping).
//   method 2 soft: planar times saturate((Z_s - z_p) / D) saturate((z_p - f) / D), D = soft_scale r
//            (soft particles, Lorach 2007).
//   Colour: the particle's direction-independent source plus albedo x the punctual lights' light
//   (unshadowed, thesis 7.2.1) scattered by the phase function at the middle of the ray's segment in
//   the particle (the closest point to the centre for the screen-parallel and planar chords).
#include "common/shared.h"
#include "common/lights.glsl"
#include "common/particle_density.glsl"
#include "common/phase.glsl"
#include "common/frame.glsl"

layout(std430, binding = kBindingMediaParticles) readonly buffer Particles { MediaParticle particles[]; };
layout(binding = kUnitGbufferPosition) uniform sampler2D t_position;  // gbuffer_position: xyz world, w view depth (0 = none)

uniform int u_hasDepth;
uniform vec2 u_targetSize;
uniform ivec2 u_fullSize;
uniform float u_znear;
uniform int u_method;
uniform int u_chord;
uniform float u_softScale;
uniform int u_lightCount;

flat in int v_particle;
layout(location = 0) out vec4 o_color;

// The particle's radiance towards the camera at x for a ray along dir.
vec3 source(MediaParticle q, vec3 x, vec3 dir) {
  vec3 L = q.sourceTau.rgb;
  if (max(q.albedoG.r, max(q.albedoG.g, q.albedoG.b)) <= 0.0) return L;
  vec3 in_ = vec3(0.0);
  for (int i = 0; i < u_lightCount; ++i) {
    const LightSample s = sampleLight(lights[i], x);
    in_ += phaseValue(q.models.y, q.albedoG.w, dot(s.wi, dir)) * s.intensity;  // mu = dot(-wi, -dir)
  }
  return L + q.albedoG.rgb * in_;
}

vec3 unproject(vec2 ndc, float depth) {
  const vec4 p = u_frame.invViewProj * vec4(ndc, depth, 1.0);
  return p.xyz / p.w;
}

void main() {
  const MediaParticle q = particles[v_particle];
  const vec3 c = q.centerRadius.xyz;
  const float r = q.centerRadius.w, tau = q.sourceTau.w;
  const int profile = q.models.x;

  const vec2 uv = gl_FragCoord.xy / u_targetSize;
  const vec2 ndc = uv * 2.0 - 1.0;
  // The ray from the near plane (reversed-Z depth 1) through depth 0.5 (twice as far).
  const vec3 o = unproject(ndc, 1.0);
  const vec3 dir = normalize(unproject(ndc, 0.5) - o);
  float tScene = 1e30, zScene = 1e30;
  if (u_hasDepth == 1) {
    const vec4 s = texelFetch(t_position, clamp(ivec2(uv * vec2(u_fullSize)), ivec2(0), u_fullSize - 1), 0);
    if (s.w > 0.0) tScene = dot(s.xyz - o, dir), zScene = s.w;
  }

  float depth = 0.0;
  float tMid;  // where along the ray the particle's colour is evaluated
  if (u_method == 0 && u_chord == 0) {
    const vec3 oc = c - o;
    const float tc = dot(oc, dir);
    // |oc - tc dir|^2 rather than |oc|^2 - tc^2, which cancels catastrophically far from the camera.
    const vec3 perp = oc - tc * dir;
    const float d2 = dot(perp, perp);
    if (d2 >= r * r) discard;
    const float w = sqrt(r * r - d2), d = sqrt(max(d2, 0.0));
    const float t0 = max(0.0, tc - w), t1 = min(tScene, tc + w);
    depth = segmentDepth(profile, tau, r, d, t0 - tc, t1 - tc);
    tMid = 0.5 * (t0 + t1);
  } else {
    // View space: the ray meets the billboard plane z = z_p at Q (eq. 7.1's assumption z_q = z_p).
    const vec3 P = (u_frame.view * vec4(c, 1.0)).xyz;
    const vec3 oV = (u_frame.view * vec4(o, 1.0)).xyz, dV = mat3(u_frame.view) * dir;
    const float zp = -P.z;
    const vec3 Q = oV + dV * ((P.z - oV.z) / dV.z);
    const float d = length(Q.xy - P.xy);
    if (d >= r) discard;
    tMid = dot(c - o, dir);
    const float w = sqrt(r * r - d * d);  // eq. 7.2
    if (u_method == 0) {
      const float front = max(u_znear, zp - w), back = min(zScene, zp + w);  // eqs. 7.1, 7.3
      depth = segmentDepth(profile, tau, r, d, front - zp, back - zp);
    } else {
      const float chord = segmentDepth(profile, tau, r, d, -w, w);
      if (u_method == 1) {
        depth = zp > u_znear && zp < zScene ? chord : 0.0;
      } else {
        const float D = u_softScale * r;
        depth = chord;  // alpha is faded below, not the depth
        const float fade = clamp((zScene - zp) / D, 0.0, 1.0) * clamp((zp - u_znear) / D, 0.0, 1.0);
        const float alpha = (1.0 - exp(-chord)) * fade;
        if (!(alpha > 0.0)) discard;
        o_color = vec4(source(q, o + tMid * dir, dir) * alpha, alpha);
        return;
      }
    }
  }
  const float alpha = 1.0 - exp(-depth);
  if (!(alpha > 0.0)) discard;
  o_color = vec4(source(q, o + tMid * dir, dir) * alpha, alpha);
}
