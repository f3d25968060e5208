// Camera pass (thesis 6.1.3): every visible non-specular receiver x looks up, per generator, the
// caustic cube map in the direction v = x - c_G. Visibility: x receives the caustic only when |v|
// matches the mean distance of the receivers the photons were deposited on in that direction
// (deposit.frag's alpha, within visibility_tolerance texels of the caustic cube). The thesis tests
// |v| against the distance map's environment layer instead (the distance map as a shadow map); that
// fails when another primitive of the same glass object, or a second generator, lies between c_G and
// the receiver (it is the nearest surface in the environment layer), and it lets a caustic deposited
// on a receiver hidden from c_G leak onto the surface that hides it. The cube holds irradiance per
// receiver area, so the radiance added is f_r(wi, wo) E with no further cosine; wi points from x
// towards c_G (so glossy receivers get a direction).
#define LDM_TRACING
#include "common/brdf.glsl"
#include "specular/ldm.glsl"
#include "caustics/cube.glsl"

layout(binding = 0) uniform sampler2D t_position;
layout(binding = 1) uniform sampler2D t_normal;
layout(binding = 2) uniform sampler2D t_albedo;
layout(binding = 3) uniform sampler2D t_material;
layout(binding = 4) uniform sampler2D t_emission;
layout(binding = 5) uniform sampler2D t_geoNormal;
layout(binding = kUnitCausticCube) uniform samplerCubeArray t_caustics;

uniform int u_generators;
uniform float u_visibilityTolerance;  // texels of the caustic cube
uniform vec3 u_eye;
uniform vec3 u_viewForward;
uniform int u_orthographic;
uniform float u_pixelArea;  // a pixel's area at unit view depth (perspective) or its area (orthographic)
uniform float u_maxLod;     // 0: point samples of the finest level (footprint_filter false)

layout(location = 0) out vec4 o_caustics;
layout(location = 1) out vec4 o_beauty;

void main() {
  ivec2 px = ivec2(gl_FragCoord.xy);
  o_caustics = vec4(0.0);
  o_beauty = vec4(0.0);
  vec4 P = texelFetch(t_position, px, 0);
  vec4 N = texelFetch(t_normal, px, 0);
  if (P.w <= 0.0 || N.w == 0.0) return;               // background, or unlit
  if (texelFetch(t_geoNormal, px, 0).w > 0.5) return;  // a specular surface: the specular pass's
  vec3 x = P.xyz;
  vec3 n = normalize(N.xyz);
  vec3 wo = u_orthographic != 0 ? -u_viewForward : normalize(u_eye - x);
  vec4 mat = texelFetch(t_material, px, 0);
  MaterialParams mp = materialParams(texelFetch(t_albedo, px, 0).rgb, mat.x, mat.y, mat.w,
                                     texelFetch(t_emission, px, 0).a);
  // The pixel's area on the receiver: Omega_pixel d^2 / cos_n = u_pixelArea z^2 cos(theta) / cos_n for
  // a perspective camera (Omega_pixel = u_pixelArea cos^3(theta), z the view depth), u_pixelArea / cos_n
  // for an orthographic one. The cosines are floored at 0.2 like the visibility tolerance's.
  float cosView = max(abs(dot(n, wo)), 0.2);
  float pixelArea = u_pixelArea / cosView;
  if (u_orthographic == 0) {
    float z = max(dot(x - u_eye, u_viewForward), 1e-30);
    pixelArea *= z * z * z / max(length(x - u_eye), 1e-30);
  }
  vec3 L = vec3(0.0);
  for (int k = 0; k < u_generators; ++k) {
    vec3 v = x - objects[k].referenceRadius.xyz;
    float dist = length(v);
    if (!(dist > 0.0)) continue;
    vec3 wi = -v / dist;
    float NdotL = dot(n, wi);
    if (NdotL <= 0.0) continue;
    // Footprint filter: the mip level whose texels cover the pixel's receiver area. A level-0 texel
    // covers Omega_texel |v|^2 / cos_r with Omega_texel = (2 / C)^2 (m / |v|)^3 (m = |v|'s major axis
    // component). At that level neighbouring pixels lie about a texel apart, and bilinear tents of half
    // width one texel sampled one texel apart sum to one (a partition of unity): the pixels integrate
    // the cube's power whatever the phase of the focus against the pixel grid. At finer levels a spike
    // narrower than the pixel spacing is hit (too bright) or missed.
    vec3 va = abs(v);
    float major = max(va.x, max(va.y, va.z));
    float texelArea = 4.0 / (u_causticResolution * u_causticResolution) * pow(major / dist, 3.0) * dist * dist /
                      max(NdotL, 0.2);
    float lod = clamp(0.5 * log2(pixelArea / texelArea), 0.0, u_maxLod);
    vec4 deposit = textureLod(t_caustics, vec4(v, float(k)), lod);
    float deposited = depositDistance(deposit);
    if (!(deposited > 0.0)) continue;
    // The deposit depth is a mean over the level's texel: the tolerance grows with it.
    float tol = u_visibilityTolerance * 2.0 * dist * exp2(lod) / u_causticResolution / max(NdotL, 0.2);
    if (abs(dist - deposited) > tol) continue;
    L += gltfBrdfCos(n, wo, wi, mp) / NdotL * deposit.rgb;
  }
  if (any(isnan(L)) || any(isinf(L))) L = vec3(0.0);
  o_caustics = vec4(L, 1.0);
  o_beauty = vec4(L, 0.0);
}
