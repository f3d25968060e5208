// Final render by marching the view ray (`final_render: march`), one fragment per pixel: the volume
// rendering integral L = sum_k T_k (1 - e^(-dtau_k)) J(x_k, w_c), T_{k+1} = T_k e^(-dtau_k), over
// u_steps equal pieces of the ray's chord through the medium's bounding sphere (clipped by the near
// plane and the scene depth), with
//   dtau_k   the exact optical depth of the piece through the medium's own particles (closed-form
//            chords, common/particle_density.glsl), so the silhouette and the transmittance are the
//            medium's and not the splats' (no blur, no lumps);
//   J        = a(x) sum_l P(w_l . w_c) E_l T_l(x)   the single-scattered directional lights, evaluated
//            exactly at the piece's midpoint x (T_l: the exact optical depth along -w_l through every
//            particle): the thin lit skin (1/tau deep) that N nodes cannot resolve;
//            + J_ms(x)   what the network adds: every node's e_p(emission) + a_p sum_d W_d(w_c) I[p,d]
//            (camera.comp without the lights: the sun scattered twice and more, the sky scattered once
//            and more), interpolated at x by normalised Gaussian weights of width u_kernel (Shepard).
// a(x) is the extinction-weighted albedo of the particles over the piece. One draw marches the pieces
// [u_stepBegin, u_stepEnd) and outputs (L, 1 - T) of that stretch for the media layer's premultiplied
// blending; the pass draws the stretches back to front, so the blending composes them exactly
// (C = L_k + T_k C). The stretches exist because llvmpipe ends every loop of a shader invocation after
// 65535 iterations in all (gallivm's LP_MAX_TGSI_LOOP_ITERATIONS, shared between the loops): the pass
// sizes them to stay below it (IlluminationNetwork.cpp marchStretch).
#include "common/shared.h"
#include "illumination_network/network.glsl"
#include "common/particle_density.glsl"
#include "common/frame.glsl"

layout(std430, binding = kBindingMediaParticles) readonly buffer Particles { MediaParticle particles[]; };
layout(std430, binding = 15) readonly buffer Splats { MediaParticle splats[]; };  // xyz node, rgb J_ms
layout(std430, binding = 12) readonly buffer Lights { NetworkLight lights[]; };
layout(std430, binding = 1) readonly buffer Directions { NetworkDirection dirs[]; };
layout(binding = kUnitGbufferPosition) uniform sampler2D t_position;  // gbuffer_position: xyz world, w view depth (0 = none)

uniform int u_hasDepth;
uniform vec2 u_targetSize;
uniform ivec2 u_fullSize;
uniform int u_particleCount;
uniform int u_steps;
uniform int u_stepBegin, u_stepEnd;  // this draw's stretch of pieces
uniform float u_kernel;  // Gaussian width of the node interpolation (world units)
uniform int u_lightCount;
uniform int u_phaseModel;
uniform float u_phaseG;
uniform int u_skyExact;  // the sky scattered once exactly (over the network's D directions)
uniform vec3 u_sky;

out vec4 o_color;

const int kMaxHits = 128;  // particles met by one pixel's ray, kept for the per-piece sums

vec3 unproject(vec2 ndc, float depth) {
  const vec4 p = u_frame.invViewProj * vec4(ndc, depth, 1.0);
  return p.xyz / p.w;
}

// Optical depth of particle q along o + t dir for t in [a, b].
float particleDepth(MediaParticle q, vec3 o, vec3 dir, float a, float b) {
  const vec3 oc = q.centerRadius.xyz - o;
  const float r = q.centerRadius.w, tc = dot(oc, dir);
  const vec3 perp = oc - tc * dir;
  const float d2 = dot(perp, perp);
  if (d2 >= r * r) return 0.0;
  const float w = sqrt(r * r - d2);
  return segmentDepth(q.models.x, q.sourceTau.w, r, sqrt(d2), max(a, tc - w) - tc, min(b, tc + w) - tc);
}

// Transmittance from x towards the light (against its propagation direction w) out of the medium.
float lightTransmittance(vec3 x, vec3 w) {
  float depth = 0.0;
  for (int k = 0; k < u_particleCount; ++k) depth += particleDepth(particles[k], x, -w, 0.0, 1e30);
  return exp(-depth);
}

// J_ms at x: the nodes' multiple-scatter sources, normalised Gaussian weights.
vec3 networkSource(vec3 x) {
  vec3 sum = vec3(0.0);
  float weight = 0.0;
  const float inv = 1.0 / (2.0 * u_kernel * u_kernel);
  for (int p = 0; p < u_nodes; ++p) {
    const vec3 d = splats[p].centerRadius.xyz - x;
    const float w = exp(-dot(d, d) * inv);
    sum += w * splats[p].sourceTau.rgb, weight += w;
  }
  return weight > 0.0 ? sum / weight : vec3(0.0);
}

void main() {
  const vec2 uv = gl_FragCoord.xy / u_targetSize;
  const vec2 ndc = uv * 2.0 - 1.0;
  const vec3 o = unproject(ndc, 1.0);  // reversed Z: the near plane
  const vec3 dir = normalize(unproject(ndc, 0.5) - o);
  float tScene = 1e30;
  if (u_hasDepth == 1) {
    const vec4 s = texelFetch(t_position, clamp(ivec2(uv * vec2(u_fullSize)), ivec2(0), u_fullSize - 1), 0);
    if (s.w > 0.0) tScene = dot(s.xyz - o, dir);
  }
  // The chord through the bounding sphere.
  const vec3 oc = u_center - o;
  const float tc = dot(oc, dir);
  const vec3 perp = oc - tc * dir;
  const float h2 = u_radius * u_radius - dot(perp, perp);
  if (!(h2 > 0.0)) discard;
  const float t0 = max(0.0, tc - sqrt(h2)), t1 = min(tScene, tc + sqrt(h2));
  if (!(t1 > t0)) discard;

  // The particles this ray meets (all of them when there are more than kMaxHits).
  int hits[kMaxHits];
  int hitCount = 0;
  bool overflow = false;
  for (int k = 0; k < u_particleCount && !overflow; ++k) {
    if (particleDepth(particles[k], o, dir, t0, t1) > 0.0) {
      if (hitCount == kMaxHits) overflow = true;
      else hits[hitCount++] = k;
    }
  }
  if (hitCount == 0) discard;
  const int count = overflow ? u_particleCount : hitCount;

  const vec3 toCamera = -dir;
  const float dt = (t1 - t0) / float(u_steps);
  vec3 L = vec3(0.0);
  float T = 1.0;
  for (int s = u_stepBegin; s < u_stepEnd; ++s) {
    const float a = t0 + float(s) * dt, b = a + dt;
    float dtau = 0.0;
    vec3 albedo = vec3(0.0);
    for (int h = 0; h < count; ++h) {
      const MediaParticle q = particles[overflow ? h : hits[h]];
      const float part = particleDepth(q, o, dir, a, b);
      dtau += part, albedo += part * q.albedoG.rgb;
    }
    if (!(dtau > 0.0)) continue;
    albedo /= dtau;
    const vec3 x = o + (0.5 * (a + b)) * dir;
    vec3 J = networkSource(x);
    if (u_skyExact == 1) {
      // a sky sum_d W_d(w_c) T(x, -w_d): the normalised phase column of the network (camera.comp).
      float sky = 0.0, sum = 0.0;
      for (int d = 0; d < u_directions; ++d) {
        const float P = phaseValue(u_phaseModel, u_phaseG, dot(dirs[d].w.xyz, toCamera));
        sky += P * lightTransmittance(x, dirs[d].w.xyz), sum += P;
      }
      J += albedo * u_sky * (sum > 0.0 ? sky / sum : 0.0);
    }
    for (int l = 0; l < u_lightCount; ++l) {
      const vec3 w = lights[l].direction.xyz;
      J += albedo * phaseValue(u_phaseModel, u_phaseG, dot(w, toCamera)) * lights[l].irradiance.rgb *
           lightTransmittance(x, w);
    }
    const float piece = exp(-dtau);
    L += T * (1.0 - piece) * J;
    T *= piece;
  }
  o_color = vec4(L, 1.0 - T);
}
