// Caustics seen in mirrors and through glass (the light-path class LS+DS+E, issue 14): the specular
// objects rasterised from the camera as in the specular pass (only the fragment the G-buffer kept),
// their reflected and refracted rays traced through the layered distance maps (specular/trace.glsl,
// the specular pass's tree), and at every non-specular hit the caustic cubes looked up as in the camera
// pass (caustics/lookup.glsl), lit with the hit's diffuse albedo from the maps: L = albedo / pi E.
// The receivers are Lambertian here (their glossy lobe is left out at secondary hits). The footprint
// filter takes the pixel's area at the unfolded distance |p - eye| + |hit - p| (exact for one flat
// mirror). Additive into beauty only: the caustics AOV stays exactly LS+DE (the reference's class).
#define LDM_TRACING
#include "common/shared.h"
#include "common/constants.glsl"
#include "common/scene.glsl"
#include "specular/ldm.glsl"
#include "caustics/cube.glsl"
#include "caustics/lookup.glsl"
#include "common/frame.glsl"

in vec3 v_position;

layout(binding = kUnitGbufferPosition) uniform sampler2D t_position;
layout(binding = kUnitGbufferNormal) uniform sampler2D t_normal;
layout(binding = kUnitGbufferAlbedo) uniform sampler2D t_albedo;
layout(binding = kUnitGbufferMaterial) uniform sampler2D t_material;
layout(binding = kUnitGbufferEmission) uniform sampler2D t_emission;

uniform int u_object;  // index of the specular object being drawn
uniform float u_pixelArea;  // as camera.frag's

layout(location = 0) out vec4 o_beauty;

vec3 g_firstHit;        // p, the rasterised specular point
float g_eyeDistance;    // |p - eye| (perspective), 0 (orthographic)

vec3 missRadiance(vec3 dir, float cone) { return vec3(0.0); }

vec3 diffuseHitRadiance(vec3 hit, vec3 rayDir, vec3 dir, float cube, vec4 texel) {
  vec3 albedo = texture(t_ldmAlbedo, vec4(dir, cube)).rgb;
  if (!(max(albedo.r, max(albedo.g, albedo.b)) > 0.0)) return vec3(0.0);
  vec3 n = normalize(octDecode(texture(t_ldmGeometry, vec4(dir, cube)).xy));
  if (dot(n, rayDir) > 0.0) n = -n;  // facing the ray
  float cosView = max(-dot(n, rayDir), 0.2);
  float unfolded = g_eyeDistance + length(hit - g_firstHit);
  float pixelArea = u_pixelArea / cosView * (u_frame.flags.x != 0 ? 1.0 : unfolded * unfolded);
  vec3 E = vec3(0.0);
  for (int k = 0; k < u_generators; ++k) {
    vec3 wi;
    float NdotL;
    E += causticIrradiance(k, hit, n, pixelArea, wi, NdotL);
  }
  return albedo * INV_PI * E;
}

// The caustics on a mirror's diffuse lobe are not modelled (the maps keep no diffuse albedo for mirror
// texels): the lobe's direct light is the specular pass's, its caustic none.
vec3 mirrorDiffuseRadiance(vec4 texel) { return vec3(0.0); }

#include "specular/trace.glsl"

void main() {
  ivec2 px = ivec2(gl_FragCoord.xy);
  vec4 P = texelFetch(t_position, px, 0);
  float viewDepth = dot(v_position - u_frame.eye.xyz, u_frame.viewForward.xyz);
  // Only the fragment the G-buffer kept (same surface within rasterisation noise), as specular.frag.
  if (P.w <= 0.0 || abs(P.w - viewDepth) > 1e-3 * max(viewDepth, 1e-6) + 1e-6) discard;
  vec3 p = P.xyz;
  vec3 n = normalize(texelFetch(t_normal, px, 0).xyz);  // RGBA16F: unit only to ~5e-4 (direct.frag)
  vec4 mat = texelFetch(t_material, px, 0);  // metallic, roughness, occlusion, transmission
  vec3 albedo = texelFetch(t_albedo, px, 0).rgb;
  float ior = texelFetch(t_emission, px, 0).a;
  vec3 R = u_frame.flags.x != 0 ? u_frame.viewForward.xyz : normalize(p - u_frame.eye.xyz);
  g_firstHit = p;
  g_eyeDistance = u_frame.flags.x != 0 ? 0.0 : length(p - u_frame.eye.xyz);
  int traced;
  vec3 L = traceSpecularTree(p, R, n, specularTexel(albedo, mat.x, mat.w, ior), u_object, gl_FrontFacing, 0.0, 0.0, traced);
  if (any(isnan(L)) || any(isinf(L))) L = vec3(0.0);
  o_beauty = vec4(L, 0.0);
}
