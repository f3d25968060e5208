// Photon splatting (Stürzlinger & Bastos 1997, §2.2, optimised mode §2.2.1), shared by the splat
// fragment shader and the per-pixel gather baseline so both compute exactly the same estimate:
//   L_o(x, wo) = sum_j phi_j f_r(x, wi_j, wo) k((x - x_j) / h_j) / h_j^2            (eq. 2 with 1/h^2)
// times |n_s . wi_j| / |n_j . wi_j| (the pixel's shading normal over the photon's geometric normal; 1 on
// a flat surface: photonContribution)
// with a kernel k of unit integral over the unit disk, evaluated in photon j's tangent plane. A photon
// contributes only to pixels whose G-buffer surface lies in its plane and faces the same way (the
// paper's per-surface stencil, here a surface test), so splats do not bleed across creases or onto
// other objects. The BRDF is the glTF one of the pixel's material (per pixel, not per splat: a
// textured surface then keeps its texture detail).
#ifndef RADIANT_PHOTON_GI_PHOTON
#define RADIANT_PHOTON_GI_PHOTON
#include "common/brdf.glsl"
#include "common/octahedral.glsl"

// std430 mirror of photon_gi::GpuSplat (renderer/techniques/photon_gi/Splatting.h).
struct GpuPhoton {
  vec4 positionRadius;  // xyz world position, w kernel radius h
  vec3 normal;          // unit normal on the side the photon arrived from
  uint wiFlags;         // photonWi (bits 0-29), bit 30: diffuse lobe only, bit 31: a copy (the grid's, splat.vert)
  vec4 power;           // rgb phi_j = flux / photons used; a > 0: a coverage point of weight A / n
};
// The unit direction towards where the photon came from: two 15-bit signed octahedral coordinates.
vec3 photonWi(GpuPhoton p) {
  int x = bitfieldExtract(int(p.wiFlags), 0, 15), y = bitfieldExtract(int(p.wiFlags), 15, 15);
  return octDecode(clamp(vec2(x, y) / 16383.0, -1.0, 1.0));
}
bool photonDiffuseOnly(GpuPhoton p) { return (p.wiFlags & 0x40000000u) != 0u; }
bool photonIsCopy(GpuPhoton p) { return (p.wiFlags & 0x80000000u) != 0u; }

layout(std430, binding = 5) readonly buffer Photons { GpuPhoton photons[]; };

const int KERNEL_BIWEIGHT = 0;      // Silverman's K2 = 3/pi (1 - r^2)^2
const int KERNEL_EPANECHNIKOV = 1;  // 2/pi (1 - r^2)

uniform int u_kernel;
uniform float u_planeTolerance;  // |distance to the photon's plane| < tolerance * h
uniform float u_normalCosine;    // minimum cosine between the pixel's and the photon's normals
uniform float u_minGlossyRoughness;  // below it only the diffuse lobe is splatted (see TECHNIQUES.md)

float kernel2d(float r2) {
  if (r2 >= 1.0) return 0.0;
  float s = 1.0 - r2;
  return u_kernel == KERNEL_EPANECHNIKOV ? 2.0 * INV_PI * s : 3.0 * INV_PI * s * s;
}

struct SplatSurface {
  vec3 x;      // world position
  vec3 n;      // shading normal
  vec3 ng;     // geometric normal facing the viewer
  vec3 nw;     // geometric normal on the front of the triangle's winding (coverage points' side)
  vec3 wo;     // towards the eye
  vec3 nc;     // the clear coat's normal (KHR_materials_clearcoat)
  MaterialParams p;  // the G-buffer's material with its layers (clear coat, sheen, specular)
};

// k((x - x_j) / h_j) / h_j^2 of photon j at a surface point x whose geometric normal ng faces the
// viewer: 0 when the point fails the surface test (not in the photon's plane, or facing elsewhere).
// Shared by the splats, the gather and the specular pass's distance maps (shaders/specular/map_indirect.comp).
float photonKernel(GpuPhoton p, vec3 x, vec3 ng) {
  float h = p.positionRadius.w;
  vec3 d = x - p.positionRadius.xyz;
  float planeDistance = dot(d, p.normal);
  if (abs(planeDistance) > u_planeTolerance * h) return 0.0;
  if (dot(ng, p.normal) < u_normalCosine) return 0.0;
  vec3 inPlane = d - planeDistance * p.normal;
  return kernel2d(dot(inPlane, inPlane) / (h * h)) / (h * h);
}

// phi_j f_r k / h^2 of photon j at the surface s (0 when it fails the surface test).
vec3 photonContribution(GpuPhoton p, SplatSurface s) {
  float k = photonKernel(p, s.x, s.ng);
  if (k <= 0.0) return vec3(0.0);
  vec3 wi = photonWi(p);
  // The photon's flux per area is irradiance on its own (geometric) plane, E = int L_i |n_j . wi| dw,
  // so each photon stands for L_i dw = (phi / A) / |n_j . wi|, and the receiver reflects
  // f |n_s . wi| L_i dw (the reference's integrand, with the pixel's shading normal):
  // phi f |n_s . wi| / |n_j . wi| k / h^2. Dividing by the receiver's own cosine instead (as until
  // 2026-12-05) is the same on a flat surface, not where the kernel spans a curve or a normal map
  // (MetalRoughSpheres' spheres are smaller than their kernels: -19.5 -> -19.7 dB under qwantani).
  float cosJ = dot(p.normal, wi);
  if (cosJ <= 0.0 || dot(s.n, wi) <= 0.0) return vec3(0.0);
  // The layered glTF BSDF (common/brdf.glsl gltfBsdfCos, the reference's rt::GltfBsdf): the base under
  // the sheen and the clear coat; gltfBsdfCos is f |n_s . wi|, divided by the photon's cosine. A lobe
  // too sharp to estimate from photons, or a glossy reflection another technique owns (photonDiffuseOnly), is
  // left out by making it a Dirac lobe, which carries nothing towards a photon's direction: the base's
  // specular (roughness 0 leaves the diffuse lobe with its Fresnel weight) and the coat's lobe (its
  // (1 - Fc) attenuation of the base stays).
  MaterialParams m = s.p;
  bool diffuseOnly = photonDiffuseOnly(p);
  if (diffuseOnly || m.surface.y < u_minGlossyRoughness) m.surface.y = 0.0;
  if (diffuseOnly || m.clearcoat.y < u_minGlossyRoughness) m.clearcoat.y = 0.0;
  return p.power.rgb * (gltfBsdfCos(s.n, s.nc, s.wo, wi, m, m.surface.w) / cosJ) * k;
}

// A coverage point (uniform by area over its surface, weight A / n, its normal the front of its
// triangle's winding): w k / h^2 at a point x whose winding front is nw. Summed over a surface's points
// this estimates the kernel mass that lies on the surface around x (1 in the interior), whichever side
// x is seen from: a photon on the side the viewer sees passes the photon test exactly where a coverage
// point of the same winding passes this one. The test compares winding fronts, not |cos|: a surface
// facing x's across a gap (the underside of a sphere resting on a plane) receives no photons on its
// hidden side, and counting its points there darkened the plane around the contact by half (0.53 of
// the reference; docs/TECHNIQUES.md, photon_gi, "Edge renormalisation").
float coverageKernel(GpuPhoton p, vec3 x, vec3 nw) {
  float h = p.positionRadius.w;
  vec3 d = x - p.positionRadius.xyz;
  float planeDistance = dot(d, p.normal);
  if (abs(planeDistance) > u_planeTolerance * h) return 0.0;
  if (dot(nw, p.normal) < u_normalCosine) return 0.0;
  vec3 inPlane = d - planeDistance * p.normal;
  return p.power.a * kernel2d(dot(inPlane, inPlane) / (h * h)) / (h * h);
}
float coverageContribution(GpuPhoton p, SplatSurface s) { return coverageKernel(p, s.x, s.nw); }
#endif
