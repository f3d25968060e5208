// The caustic cube lookup at a receiver point (thesis 6.1.3), shared by the camera pass (camera.frag)
// and the lookup at the specular pass's secondary hits (secondary.frag). Needs LDM_TRACING's
// specular/ldm.glsl (the generators' reference points) and caustics/cube.glsl.
#ifndef RADIANT_CAUSTICS_LOOKUP
#define RADIANT_CAUSTICS_LOOKUP
#include "common/shared.h"
#include "caustics/shared.h"
layout(binding = kUnitCausticCube) uniform samplerCubeArray t_caustics;
uniform int u_generators;
uniform float u_visibilityTolerance;  // texels of the caustic cube
uniform float u_maxLod;               // 0: point samples of the finest level (footprint_filter false)

// Irradiance per receiver area at x (normal n, facing the viewer) from generator k's cube; 0 unless
// c_G lies in front of x and x lies at the depth the photons were deposited at. wi points towards c_G.
// Visibility: |x - c_G| must match the mean distance of the receivers the photons were deposited on in
// that direction (deposit.frag's alpha, within visibility_tolerance texels). The thesis tests it
// against the distance map's environment layer instead (the distance map as a shadow map); that fails
// when another primitive of the same glass object, or a second generator, lies between c_G and the
// receiver (it is the nearest surface in the environment layer), and it lets a caustic deposited on a
// receiver hidden from c_G leak onto the surface that hides it.
// Footprint filter: `pixelArea` is the pixel's area on the receiver; the cube is read at the mip level
// whose texels cover it. A level-0 texel covers Omega_texel |v|^2 / cos_r with Omega_texel =
// (2 / C)^2 (m / |v|)^3 (m = |v|'s major axis component). At that level neighbouring pixels lie about
// a texel apart, and bilinear tents of half width one texel sampled one texel apart sum to one (a
// partition of unity): the pixels integrate the cube's power whatever the phase of a focus against the
// pixel grid. At finer levels a spike narrower than the pixel spacing is hit (too bright) or missed.
vec3 causticIrradiance(int k, vec3 x, vec3 n, float pixelArea, out vec3 wi, out float NdotL) {
  vec3 v = x - objects[k].referenceRadius.xyz;
  float dist = length(v);
  wi = vec3(0.0);
  NdotL = 0.0;
  if (!(dist > 0.0)) return vec3(0.0);
  wi = -v / dist;
  NdotL = dot(n, wi);
  if (NdotL <= 0.0) return vec3(0.0);
  vec3 va = abs(v);
  float major = max(va.x, max(va.y, va.z));
  float texelArea = 4.0 / (u_causticResolution * u_causticResolution) * pow(major / dist, 3.0) * dist * dist /
                    max(NdotL, 0.2);
  float lod = clamp(0.5 * log2(pixelArea / texelArea), 0.0, u_maxLod);
  vec4 deposit = textureLod(t_caustics, vec4(v, float(k)), lod);
  float deposited = depositDistance(deposit);
  if (!(deposited > 0.0)) return vec3(0.0);
  // The deposit depth is a mean over the level's texel: the tolerance grows with it.
  float tol = u_visibilityTolerance * 2.0 * dist * exp2(lod) / u_causticResolution / max(NdotL, 0.2);
  if (abs(dist - deposited) > tol) return vec3(0.0);
  return deposit.rgb;
}
#endif
