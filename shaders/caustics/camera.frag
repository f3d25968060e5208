// Camera pass (thesis 6.1.3): every visible non-specular receiver x looks up, per generator, the
// caustic cube map in the direction x - c_G (caustics/lookup.glsl: visibility by the cube's deposit
// depth, footprint filter). The cube holds irradiance per receiver area, so the radiance added is
// f_r(wi, wo) E with no further cosine; wi points from x towards c_G (so glossy receivers get a
// direction).
#define LDM_TRACING
#include "common/shared.h"
#include "common/brdf.glsl"
#include "common/gbuffer_geometry.glsl"
#include "specular/ldm.glsl"
#include "caustics/cube.glsl"
#include "caustics/lookup.glsl"
#include "common/frame.glsl"

layout(binding = kUnitGbufferPosition) uniform sampler2D t_position;
layout(binding = kUnitGbufferNormal) uniform sampler2D t_normal;
layout(binding = kUnitGbufferAlbedo) uniform sampler2D t_albedo;
layout(binding = kUnitGbufferMaterial) uniform sampler2D t_material;
layout(binding = kUnitGbufferEmission) uniform sampler2D t_emission;
layout(binding = kUnitGbufferGeometricNormal) uniform sampler2D t_geoNormal;
uniform float u_pixelArea;  // a pixel's area at unit view depth (perspective) or its area (orthographic)

layout(location = 0) out vec4 o_caustics;
layout(location = 1) out vec4 o_beauty;

void main() {
  ivec2 px = ivec2(gl_FragCoord.xy);
  o_caustics = vec4(0.0);
  o_beauty = vec4(0.0);
  vec4 P = texelFetch(t_position, px, 0);
  vec4 N = texelFetch(t_normal, px, 0);
  if (P.w <= 0.0 || N.w == 0.0) return;               // background, or unlit
  if (gbufferSpecularOwned(texelFetch(t_geoNormal, px, 0))) return;  // a specular surface: the specular pass's
  vec3 x = P.xyz;
  vec3 n = normalize(N.xyz);
  vec3 wo = u_frame.flags.x != 0 ? -u_frame.viewForward.xyz : normalize(u_frame.eye.xyz - x);
  vec4 mat = texelFetch(t_material, px, 0);
  MaterialParams mp = materialParams(texelFetch(t_albedo, px, 0).rgb, mat.x, mat.y, mat.w,
                                     texelFetch(t_emission, px, 0).a);
  // The pixel's area on the receiver: Omega_pixel d^2 / cos_n = u_pixelArea z^2 cos(theta) / cos_n for
  // a perspective camera (Omega_pixel = u_pixelArea cos^3(theta), z the view depth), u_pixelArea / cos_n
  // for an orthographic one. The cosines are floored at 0.2 like the visibility tolerance's.
  float cosView = max(abs(dot(n, wo)), 0.2);
  float pixelArea = u_pixelArea / cosView;
  if (u_frame.flags.x == 0) {
    float z = max(dot(x - u_frame.eye.xyz, u_frame.viewForward.xyz), 1e-30);
    pixelArea *= z * z * z / max(length(x - u_frame.eye.xyz), 1e-30);
  }
  vec3 L = vec3(0.0);
  for (int k = 0; k < u_generators; ++k) {
    vec3 wi;
    float NdotL;
    vec3 E = causticIrradiance(k, x, n, pixelArea, wi, NdotL);
    if (NdotL > 0.0 && any(greaterThan(E, vec3(0.0)))) L += gltfBrdfCos(n, wo, wi, mp) / NdotL * E;
  }
  if (any(isnan(L)) || any(isinf(L))) L = vec3(0.0);
  o_caustics = vec4(L, 1.0);
  o_beauty = vec4(L, 0.0);
}
