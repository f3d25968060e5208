// The specular pass proper: rasterises each specular object (the first hit, thesis ch. 5: "the first
// point is identified by rasterization"), keeps the fragment the G-buffer sees, and traces the
// reflected and refracted rays through the layered distance maps (Algorithm 3, specular/trace.glsl).
// Writes the radiance arriving through the traced paths, already weighted by Fresnel and colour:
// the `specular` AOV, which compose.frag adds to beauty.
#define LDM_TRACING
#include "common/shared.h"
#include "common/scene.glsl"
#include "specular/ldm.glsl"
#include "common/environment.glsl"
#include "common/frame.glsl"

in vec3 v_position;

layout(binding = kUnitGbufferPosition) uniform sampler2D t_position;
layout(binding = kUnitGbufferNormal) uniform sampler2D t_normal;
layout(binding = kUnitGbufferAlbedo) uniform sampler2D t_albedo;
layout(binding = kUnitGbufferMaterial) uniform sampler2D t_material;
layout(binding = kUnitGbufferEmission) uniform sampler2D t_emission;

uniform int u_object;  // index of the specular object being drawn
// 1: a ray leaving the scene sees the environment map (when direct uploaded it), else the uniform sky
uniform int u_hasEnvironment;
layout(binding = kUnitEnvironment) uniform sampler2D t_environment;

layout(location = 0) out vec4 o_specular;

// A ray that leaves the scene sees the sky in its direction, averaged over its cone (the sample's
// footprintCone below, widened by the convex mirrors on its path: specular/trace.glsl); a diffuse hit
// its stored radiance.
vec3 missRadiance(vec3 dir, float cone) {
  return u_hasEnvironment != 0 ? environmentRadianceCone(t_environment, dir, cone) : u_frame.background.rgb;
}

// The reflected direction at G-buffer sample q, or vec3(0) when q is not a surface that continues the
// one at p with normal n (the background, or a surface more than 60 degrees off: another object);
// its surface point in `at`.
vec3 neighbourReflection(ivec2 q, vec3 n, out vec3 at) {
  at = vec3(0.0);
  if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, textureSize(t_position, 0)))) return vec3(0.0);
  vec4 Q = texelFetch(t_position, q, 0);
  if (Q.w <= 0.0) return vec3(0.0);
  vec3 nq = normalize(texelFetch(t_normal, q, 0).xyz);
  if (dot(nq, n) < 0.5) return vec3(0.0);
  at = Q.xyz;
  vec3 v = u_frame.flags.x != 0 ? u_frame.viewForward.xyz : normalize(Q.xyz - u_frame.eye.xyz);
  return reflect(v, nq);
}

// The cone of directions a sample's reflected ray stands for: its footprint (one sample spacing, the
// chord between its reflected direction r and the neighbours', the nearer side per axis, the wider
// axis) widened by the glossy lobe of a surface the pass traces as a mirror (roughness below 0.2, GGX's
// D falls to half at tan(theta_h) = 0.64 alpha: a reflected full width at half maximum of 2.56 alpha;
// a glint's half-energy radius is then 0.82 of the reference's, and 1.65 with the half-mass cone of
// 4 alpha: Environment.AGlossyMirrorSpreadsTheSunOverItsLobeAsTheReference).
// Without it each sample read one texel: on a mirror sphere a few pixels wide a sample sees about
// 3-4 degrees of sky and a sun of half a degree was all or nothing in the pixel (MetalRoughSpheres'
// worst pixels in the fidelity benchmark, where the reference integrates the pixel).
// width: the beam's width at p, the same way: the distance to the neighbours' surface points across
// the incident direction R (a sample spacing; the ray cone's start, specular/trace.glsl).
float footprintCone(ivec2 px, vec3 p, vec3 R, vec3 n, vec3 r, float roughness, out float width) {
  float axis[2], across[2];
  for (int a = 0; a < 2; ++a) {
    ivec2 step = a == 0 ? ivec2(1, 0) : ivec2(0, 1);
    float best = 1e30, nearest = 1e30;
    for (int side = -1; side <= 1; side += 2) {
      vec3 q;
      vec3 rq = neighbourReflection(px + side * step, n, q);
      if (!(dot(rq, rq) > 0.0)) continue;
      best = min(best, length(rq - r));
      vec3 dq = q - p;
      nearest = min(nearest, length(dq - dot(dq, R) * R));
    }
    axis[a] = best < 1e30 ? best : 0.0;
    across[a] = nearest < 1e30 ? nearest : 0.0;
  }
  width = max(across[0], across[1]);
  float alpha = roughness * roughness;
  float lobe = 2.56 * alpha;
  return sqrt(max(axis[0], axis[1]) * max(axis[0], axis[1]) + lobe * lobe);
}
vec3 diffuseHitRadiance(vec3 hit, vec3 rayDir, vec3 dir, float cube, vec4 texel) { return texel.rgb; }
vec3 mirrorDiffuseRadiance(vec4 texel) { return texel.rgb; }

#include "specular/trace.glsl"

void main() {
  ivec2 px = ivec2(gl_FragCoord.xy);
  vec4 P = texelFetch(t_position, px, 0);
  float viewDepth = dot(v_position - u_frame.eye.xyz, u_frame.viewForward.xyz);
  // Only the fragment the G-buffer kept (same surface within rasterisation noise) is shaded.
  if (P.w <= 0.0 || abs(P.w - viewDepth) > 1e-3 * max(viewDepth, 1e-6) + 1e-6) discard;

  vec3 p = P.xyz;
  vec3 n = normalize(texelFetch(t_normal, px, 0).xyz);  // RGBA16F: unit only to ~5e-4 (direct.frag)
  vec4 mat = texelFetch(t_material, px, 0);  // metallic, roughness, occlusion, transmission
  vec3 albedo = texelFetch(t_albedo, px, 0).rgb;
  float ior = texelFetch(t_emission, px, 0).a;
  vec3 R = u_frame.flags.x != 0 ? u_frame.viewForward.xyz : normalize(p - u_frame.eye.xyz);
  float cone = 0.0, width = 0.0;
  if (u_hasEnvironment != 0) cone = footprintCone(px, p, R, n, reflect(R, n), mat.y, width);

  // The G-buffer normal faces the viewer; whether the ray enters or leaves the object is the face's
  // orientation (a camera inside a glass object sees its back faces).
  int traced;
  vec3 L = traceSpecularTree(p, R, n, specularTexel(albedo, mat.x, mat.w, ior), u_object, gl_FrontFacing, cone, width,
                             traced);
  o_specular = vec4(L, float(traced));
}
