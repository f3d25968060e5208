#pragma once
// The glTF 2.0 metallic-roughness BSDF of the CPU ray-tracing core, with its sampling routines. The
// reference path tracer (radiance) and the photon tracer (importance) share it.
//
// Everything here works in a local shading frame where +z is the shading normal and wo (the direction
// towards the viewer) lies in the upper hemisphere (wo.z > 0). Directions point away from the surface.
//
// The BRDF is the one of the glTF 2.0 specification, Appendix B ("BRDF Implementation"):
//   material        = mix(dielectric_brdf, metal_brdf, metallic)
//   metal_brdf      = conductor_fresnel(f0 = baseColor, specular_brdf(alpha = roughness^2))
//   dielectric_brdf = fresnel_mix(ior, base = diffuse_brdf(baseColor), layer = specular_brdf(alpha))
//   specular_brdf   = D(h) * V(l, v)                       (V = G / (4 |n.l| |n.v|), height-correlated Smith)
//   conductor_fresnel = bsdf * (f0 + (1 - f0) (1 - |v.h|)^5)
//   fresnel_mix     = mix(base, layer, f0_ior + (1 - f0_ior) (1 - |v.h|)^5), f0_ior = ((1 - ior) / (1 + ior))^2
// We use the mix form literally (so the diffuse lobe is weighted by (1 - metallic)(1 - F_dielectric), not
// by the "implementation" shortcut (1 - F_mixed) c_diff of the spec, which is an approximation of it).
//
// KHR_materials_transmission replaces the diffuse base of the dielectric by
// mix(diffuse_brdf, specular_btdf, transmission); specular_btdf is tinted by baseColor. DECISION: the
// reference treats a transmissive surface as a refracting interface between air and a solid of index
// `ior` (the brief asks for refraction, slabs and total internal reflection), not as glTF's thin-walled
// default; the dielectric reflection/refraction split of a transmissive material uses the exact
// unpolarised Fresnel equations (Schlick cannot express total internal reflection and does not balance
// reflection and refraction exactly). Rough transmission is Walter et al. 2007's microfacet BTDF.
//
// The layered extensions, as the KHR texts write them (glTF's layering by "mix" weights, not a
// physical multiple-scattering model):
//   KHR_materials_specular:  fresnel_mix gets f0 = min(f0_ior specularColor, 1) (rgb), F90 = 1, and the
//                            layer weight w = specularFactor: the dielectric is
//                            (1 - w max3(F)) diffuse + w F specular_brdf.
//   KHR_materials_sheen:     sheen_material = sheen_brdf + base * min(1 - max3(c) E(n.v), 1 - max3(c) E(n.l)),
//                            sheen_brdf = c D_charlie(alpha = r^2) V_ashikhmin (Estevez and Kulla 2017;
//                            Neubelt and Pettineo 2013), E the sheen's directional albedo (a table).
//   KHR_materials_clearcoat: coated = mix(sheen_material, coat_brdf, clearcoat Fc(|n_c.v|)),
//                            Fc the Schlick Fresnel of index 1.5 (F0 0.04), coat_brdf = D V of
//                            alpha = clearcoatRoughness^2 around the coat normal n_c.
// The coat's mix weight depends on v alone, so a coated BSDF is not reciprocal: f(wo, wi) / f(wi, wo)
// = (1 - Fc(wo) c) / (1 - Fc(wi) c) for its base, Fc(wo) / Fc(wi) for the coat (the unit tests state it).
// Without the layers (clearcoat 0, sheen colour 0, specular (1, 1)) every formula reduces to the one
// above. The transmissive part keeps its exact Fresnel (KHR_materials_specular does not tint it).
//
// Roughness: roughness == 0 makes the specular lobes Dirac deltas (perfect mirror / smooth dielectric,
// the alpha -> 0 limit of the microfacet lobes, whose albedo tends to F(n.v)). Any roughness > 0 uses
// alpha = max(roughness^2, kMinAlpha) with kMinAlpha = 1e-3, so D stays finite in float
// (D_max = 1 / (pi alpha^2) ~ 3e5) and nothing produces NaN. kMinAlpha is gpu::kMinGgxAlpha, the one
// constant GLSL's brdf.glsl reads too (shaders/common/shared.h).
#include <algorithm>
#include <cmath>

#include <glm/glm.hpp>

#include "renderer/frame/GpuTypes.h"

namespace radiant::rt {

inline constexpr float kPi = 3.14159265358979323846f;
inline constexpr float kInvPi = 1.f / kPi;
inline constexpr float kMinAlpha = gpu::kMinGgxAlpha;

inline float luminance(const glm::vec3& c) { return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b; }
inline float maxComponent(const glm::vec3& c) { return std::max(c.r, std::max(c.g, c.b)); }
inline float safeSqrt(float x) { return std::sqrt(std::max(0.f, x)); }
inline float sqr(float x) { return x * x; }

// Orthonormal basis around n (Duff et al. 2017, "Building an Orthonormal Basis, Revisited").
struct ShadingFrame {
  glm::vec3 t, b, n;
  static ShadingFrame fromNormal(const glm::vec3& n) {
    const float sign = std::copysign(1.f, n.z);
    const float a = -1.f / (sign + n.z);
    const float bb = n.x * n.y * a;
    ShadingFrame f;
    f.t = glm::vec3(1.f + sign * n.x * n.x * a, sign * bb, -sign * n.x);
    f.b = glm::vec3(bb, sign + n.y * n.y * a, -n.y);
    f.n = n;
    return f;
  }
  glm::vec3 toLocal(const glm::vec3& v) const { return {glm::dot(v, t), glm::dot(v, b), glm::dot(v, n)}; }
  glm::vec3 toWorld(const glm::vec3& v) const { return v.x * t + v.y * b + v.z * n; }
};

// ---------------------------------------------------------------------------------------------------
// Sampling routines, each next to its pdf (solid-angle measure).

// Concentric square-to-disk map (Shirley and Chiu 1997).
inline glm::vec2 sampleConcentricDisk(glm::vec2 u) {
  const glm::vec2 o = 2.f * u - 1.f;
  if (o.x == 0.f && o.y == 0.f) return glm::vec2(0.f);
  float r, theta;
  if (std::abs(o.x) > std::abs(o.y)) { r = o.x; theta = (kPi / 4.f) * (o.y / o.x); }
  else { r = o.y; theta = kPi / 2.f - (kPi / 4.f) * (o.x / o.y); }
  return r * glm::vec2(std::cos(theta), std::sin(theta));
}

// Malley's method: p(w) = cos(theta) / pi.
inline glm::vec3 sampleCosineHemisphere(glm::vec2 u) {
  const glm::vec2 d = sampleConcentricDisk(u);
  return {d.x, d.y, safeSqrt(1.f - d.x * d.x - d.y * d.y)};
}
inline float cosineHemispherePdf(float cosTheta) { return std::max(cosTheta, 0.f) * kInvPi; }

// p(w) = (n + 1) cos^n(theta) / (2 pi); cos(theta) = u^(1/(n+1)). Used with n = 3 by volumetric AO.
inline glm::vec3 sampleCosinePowerHemisphere(glm::vec2 u, float n) {
  const float cosTheta = std::pow(u.x, 1.f / (n + 1.f));
  const float sinTheta = safeSqrt(1.f - cosTheta * cosTheta);
  const float phi = 2.f * kPi * u.y;
  return {sinTheta * std::cos(phi), sinTheta * std::sin(phi), cosTheta};
}
inline float cosinePowerHemispherePdf(float cosTheta, float n) {
  return cosTheta > 0.f ? (n + 1.f) * std::pow(cosTheta, n) / (2.f * kPi) : 0.f;
}

// p(w) = 1 / (4 pi).
inline glm::vec3 sampleUniformSphere(glm::vec2 u) {
  const float z = 1.f - 2.f * u.x;
  const float r = safeSqrt(1.f - z * z);
  const float phi = 2.f * kPi * u.y;
  return {r * std::cos(phi), r * std::sin(phi), z};
}
inline float uniformSpherePdf() { return 1.f / (4.f * kPi); }

// Uniform barycentrics on a triangle (area measure pdf = 1 / area).
inline glm::vec2 sampleUniformTriangle(glm::vec2 u) {
  const float su = std::sqrt(u.x);
  return {1.f - su, u.y * su};  // (b0, b1); b2 = 1 - b0 - b1
}

// Veach's power heuristic (beta = 2) for two strategies with one sample each.
inline float powerHeuristic(float pdfA, float pdfB) {
  const float a = pdfA * pdfA, b = pdfB * pdfB;
  return a > 0.f ? a / (a + b) : 0.f;
}

// ---------------------------------------------------------------------------------------------------
// GGX (Trowbridge-Reitz) microfacet distribution, isotropic, alpha = roughness^2.

inline float alphaFromRoughness(float roughness) { return std::max(roughness * roughness, kMinAlpha); }

// glTF Appendix B: D = alpha^2 chi+(n.h) / (pi ((n.h)^2 (alpha^2 - 1) + 1)^2).
inline float ggxD(float cosThetaH, float alpha) {
  if (cosThetaH <= 0.f) return 0.f;
  const float a2 = alpha * alpha;
  const float d = cosThetaH * cosThetaH * (a2 - 1.f) + 1.f;
  return a2 / (kPi * d * d);
}

// Smith Lambda for GGX: Lambda(w) = (-1 + sqrt(1 + alpha^2 tan^2 theta)) / 2 (Heitz 2014, eq. 72).
inline float ggxLambda(float cosTheta, float alpha) {
  const float c2 = cosTheta * cosTheta;
  if (c2 <= 0.f) return 1e30f;
  const float tan2 = std::max(0.f, 1.f - c2) / c2;
  return 0.5f * (-1.f + std::sqrt(1.f + alpha * alpha * tan2));
}
inline float smithG1(float cosTheta, float alpha) { return 1.f / (1.f + ggxLambda(cosTheta, alpha)); }
// Height-correlated masking-shadowing G2 = 1 / (1 + Lambda(wo) + Lambda(wi)) (Heitz 2014, eq. 99).
inline float smithG2HeightCorrelated(float cosO, float cosI, float alpha) {
  return 1.f / (1.f + ggxLambda(std::abs(cosO), alpha) + ggxLambda(std::abs(cosI), alpha));
}

// glTF Appendix B, "Specular BRDF": V = G2 / (4 |n.l| |n.v|)
//   = 0.5 / (n.l sqrt((n.v)^2 (1 - a2) + a2) + n.v sqrt((n.l)^2 (1 - a2) + a2)).
inline float ggxVisibility(float NdotL, float NdotV, float alpha) {
  if (NdotL <= 0.f || NdotV <= 0.f) return 0.f;
  const float a2 = alpha * alpha;
  const float gv = NdotL * std::sqrt(NdotV * NdotV * (1.f - a2) + a2);
  const float gl = NdotV * std::sqrt(NdotL * NdotL * (1.f - a2) + a2);
  const float s = gv + gl;
  return s > 0.f ? 0.5f / s : 0.f;
}

// Heitz 2018, "Sampling the GGX Distribution of Visible Normals", listing 1 (isotropic alpha).
// Returns a microfacet normal h distributed as D_wo(h) = G1(wo) max(0, wo.h) D(h) / wo.z.
inline glm::vec3 sampleGgxVndf(const glm::vec3& wo, float alpha, glm::vec2 u) {
  const glm::vec3 vh = glm::normalize(glm::vec3(alpha * wo.x, alpha * wo.y, wo.z));
  const float lensq = vh.x * vh.x + vh.y * vh.y;
  const glm::vec3 t1 = lensq > 0.f ? glm::vec3(-vh.y, vh.x, 0.f) / std::sqrt(lensq) : glm::vec3(1.f, 0.f, 0.f);
  const glm::vec3 t2 = glm::cross(vh, t1);
  const float r = std::sqrt(u.x);
  const float phi = 2.f * kPi * u.y;
  const float p1 = r * std::cos(phi);
  float p2 = r * std::sin(phi);
  const float s = 0.5f * (1.f + vh.z);
  p2 = (1.f - s) * safeSqrt(1.f - p1 * p1) + s * p2;
  const glm::vec3 nh = p1 * t1 + p2 * t2 + safeSqrt(1.f - p1 * p1 - p2 * p2) * vh;
  return glm::normalize(glm::vec3(alpha * nh.x, alpha * nh.y, std::max(1e-7f, nh.z)));
}
// Density of sampleGgxVndf's h (Heitz 2018, eq. 3).
inline float ggxVndfPdf(const glm::vec3& wo, const glm::vec3& h, float alpha) {
  if (wo.z <= 0.f) return 0.f;
  return smithG1(wo.z, alpha) * std::max(0.f, glm::dot(wo, h)) * ggxD(h.z, alpha) / wo.z;
}
// Density of wi = reflect(-wo, h) in solid angle: D_wo(h) / (4 |wo.h|) (Jacobian of the reflection).
inline float ggxReflectionPdf(const glm::vec3& wo, const glm::vec3& wi, float alpha) {
  if (wo.z <= 0.f || wi.z <= 0.f) return 0.f;
  const glm::vec3 h = glm::normalize(wo + wi);
  const float voh = glm::dot(wo, h);
  return voh > 0.f ? ggxVndfPdf(wo, h, alpha) / (4.f * voh) : 0.f;
}

// ---------------------------------------------------------------------------------------------------
// Fresnel.

inline float schlickWeight(float cosTheta) {
  const float m = std::clamp(1.f - std::abs(cosTheta), 0.f, 1.f);
  return (m * m) * (m * m) * m;
}
inline glm::vec3 schlickFresnel(const glm::vec3& f0, float cosTheta) {
  return f0 + (glm::vec3(1.f) - f0) * schlickWeight(cosTheta);
}
inline float schlickFresnel(float f0, float cosTheta) { return f0 + (1.f - f0) * schlickWeight(cosTheta); }
inline float f0FromIor(float ior) { return sqr((ior - 1.f) / (ior + 1.f)); }

// Exact unpolarised Fresnel reflectance of a dielectric interface, R = (Rs + Rp) / 2 with
// rs = (cos_i - eta cos_t) / (cos_i + eta cos_t), rp = (eta cos_i - cos_t) / (eta cos_i + cos_t),
// where eta = n_t / n_i (index on the far side over index on the incident side) and cos_i >= 0.
// Returns 1 for total internal reflection (sin_t >= 1).
inline float fresnelDielectric(float cosThetaI, float eta) {
  cosThetaI = std::clamp(cosThetaI, 0.f, 1.f);
  const float sin2T = (1.f - cosThetaI * cosThetaI) / (eta * eta);
  if (sin2T >= 1.f) return 1.f;
  const float cosT = safeSqrt(1.f - sin2T);
  const float rs = (cosThetaI - eta * cosT) / (cosThetaI + eta * cosT);
  const float rp = (eta * cosThetaI - cosT) / (eta * cosThetaI + cosT);
  return 0.5f * (rs * rs + rp * rp);
}

inline glm::vec3 reflect(const glm::vec3& wo, const glm::vec3& n) { return 2.f * glm::dot(wo, n) * n - wo; }

// ---------------------------------------------------------------------------------------------------
// KHR_materials_sheen: the Charlie distribution and Ashikhmin's visibility.

// Estevez and Kulla 2017, eq. 2: D(h) = (2 + 1 / alpha) sin(theta_h)^(1 / alpha) / (2 pi).
inline float charlieD(float cosThetaH, float alpha) {
  if (cosThetaH <= 0.f) return 0.f;
  const float invA = 1.f / alpha;
  const float sin2 = std::max(0.f, 1.f - cosThetaH * cosThetaH);
  return (2.f + invA) * std::pow(sin2, 0.5f * invA) / (2.f * kPi);
}
// Neubelt and Pettineo 2013: V = 1 / (4 (n.l + n.v - n.l n.v)), which includes 1 / (4 n.l n.v).
inline float sheenVisibility(float NdotL, float NdotV) {
  if (NdotL <= 0.f || NdotV <= 0.f) return 0.f;
  return 1.f / (4.f * (NdotL + NdotV - NdotL * NdotV));
}
inline float sheenAlphaFromRoughness(float r) { return sqr(std::clamp(r, gpu::kMinSheenRoughness, 1.f)); }

// E(mu, r) = integral of D_charlie V cos(theta_i) over the hemisphere for a white sheen, on the grid of
// shared.h (mu_i = i / (N - 1), r_j = kMinSheenRoughness + (1 - kMinSheenRoughness) j / (N - 1)), by
// midpoint quadrature in (cos theta_i, phi) with 128 x 64 cells (phi over [0, pi], doubled by symmetry).
// Built once per process; GpuScene uploads the same numbers, so both languages read one table.
inline const float* sheenAlbedoTable() {
  static const auto table = [] {
    constexpr int N = gpu::kSheenAlbedoSize, kCos = 128, kPhi = 64;
    static float t[N * N];
    for (int j = 0; j < N; ++j) {
      const float r = gpu::kMinSheenRoughness + (1.f - gpu::kMinSheenRoughness) * float(j) / float(N - 1);
      const float alpha = sheenAlphaFromRoughness(r);
      for (int i = 0; i < N; ++i) {
        const float mu = std::max(float(i) / float(N - 1), 1e-4f);
        const glm::vec3 wo(std::sqrt(1.f - mu * mu), 0.f, mu);
        double sum = 0.0;
        for (int a = 0; a < kCos; ++a) {
          const float ci = (float(a) + 0.5f) / float(kCos);
          const float si = std::sqrt(1.f - ci * ci);
          for (int b = 0; b < kPhi; ++b) {
            const float phi = kPi * (float(b) + 0.5f) / float(kPhi);
            const glm::vec3 wi(si * std::cos(phi), si * std::sin(phi), ci);
            const glm::vec3 h = glm::normalize(wo + wi);
            sum += double(charlieD(h.z, alpha) * sheenVisibility(ci, mu) * ci);
          }
        }
        t[j * N + i] = float(sum * (2.0 * kPi / kPhi) / kCos);
      }
    }
    return t;
  }();
  return table;
}
// Bilinear lookup of the table (the GLSL twin, sheenAlbedo() of brdf.glsl, does the same arithmetic).
inline float sheenAlbedo(const float* table, float mu, float roughness) {
  constexpr int N = gpu::kSheenAlbedoSize;
  const float x = std::clamp(mu, 0.f, 1.f) * float(N - 1);
  const float y = std::clamp((roughness - gpu::kMinSheenRoughness) / (1.f - gpu::kMinSheenRoughness), 0.f, 1.f) *
                  float(N - 1);
  const int x0 = std::min(int(x), N - 2), y0 = std::min(int(y), N - 2);
  const float fx = x - float(x0), fy = y - float(y0);
  const float a = table[y0 * N + x0] + (table[y0 * N + x0 + 1] - table[y0 * N + x0]) * fx;
  const float b = table[(y0 + 1) * N + x0] + (table[(y0 + 1) * N + x0 + 1] - table[(y0 + 1) * N + x0]) * fx;
  return a + (b - a) * fy;
}
inline float sheenAlbedo(float mu, float roughness) { return sheenAlbedo(sheenAlbedoTable(), mu, roughness); }

// Refraction of wo (wo.n > 0, pointing away) through an interface with normal n, eta = n_t / n_i.
// Returns false on total internal reflection.
inline bool refract(const glm::vec3& wo, const glm::vec3& n, float eta, glm::vec3& wi) {
  const float cosI = glm::dot(wo, n);
  const float sin2T = std::max(0.f, 1.f - cosI * cosI) / (eta * eta);
  if (sin2T >= 1.f) return false;
  const float cosT = safeSqrt(1.f - sin2T);
  wi = -wo / eta + (cosI / eta - cosT) * n;
  return true;
}

// ---------------------------------------------------------------------------------------------------
// The glTF material BSDF.

// What a path carries (pbrt-v4 TransportMode, Mitsuba's BSDFContext). The BSDF is not symmetric under
// refraction: radiance is compressed by (n_i / n_t)^2 = 1 / eta^2 when it enters a denser medium
// (Veach 1997, eq. 5.14), importance (photons, light tracing) is not.
enum class TransportMode { Radiance, Importance };

// Which lobe produced a sample. Light-path classes (LD+E, LS+DE, LG+DE) are built from these.
// The values are shared.h's, which GLSL's sampleMaterial() sets.
enum LobeFlags : unsigned {
  kLobeReflection = unsigned(gpu::kLobeReflection), kLobeTransmission = unsigned(gpu::kLobeTransmission),
  kLobeDiffuse = unsigned(gpu::kLobeDiffuse), kLobeGlossy = unsigned(gpu::kLobeGlossy),
  kLobeSpecular = unsigned(gpu::kLobeSpecular),  // specular = Dirac delta
};

struct GltfBsdf {
  glm::vec3 baseColor{1.f};
  float metallic = 1.f;
  float roughness = 1.f;
  float transmission = 0.f;
  float ior = 1.5f;
  // Relative index across the interface as seen from wo's side: n_(far side) / n_(wo side).
  // ior when wo is outside a transmissive solid, 1 / ior inside. Only transmission uses it.
  float eta = 1.5f;
  TransportMode mode = TransportMode::Radiance;
  // KHR_materials_specular: F0 tint and layer weight of the (opaque) dielectric.
  glm::vec3 specularColor{1.f};
  float specularWeight = 1.f;
  // KHR_materials_sheen: colour 0 = no sheen.
  glm::vec3 sheenColor{0.f};
  float sheenRoughness = gpu::kMinSheenRoughness;
  // KHR_materials_clearcoat: weight 0 = no coat. coatNormal in the local frame (the interpolated vertex
  // normal: the coat ignores the base's normal map); it faces wo's side like +z.
  float clearcoat = 0.f;
  float clearcoatRoughness = 0.f;
  glm::vec3 coatNormal{0.f, 0.f, 1.f};

  // The BSDF of a decoded material (MaterialDecode.h's decodeBsdfInputs; eta = ior, as seen from outside:
  // RayScene::shade turns it for hits from inside).
  static GltfBsdf fromParams(const gpu::MaterialParams& p, TransportMode mode = TransportMode::Radiance) {
    GltfBsdf b;
    b.baseColor = glm::vec3(p.baseColor);
    b.metallic = p.surface.x;
    b.roughness = p.surface.y;
    b.transmission = p.surface.z;
    b.mode = mode;
    b.ior = b.eta = p.surface.w;
    b.clearcoat = p.clearcoat.x;
    b.clearcoatRoughness = p.clearcoat.y;
    b.sheenColor = glm::vec3(p.sheen);
    b.sheenRoughness = p.sheen.w;
    b.specularColor = glm::vec3(p.specular);
    b.specularWeight = p.specular.w;
    return b;
  }

  // 1 / eta^2 on refraction for radiance, 1 for importance.
  float refractionScale() const { return mode == TransportMode::Radiance ? 1.f / (eta * eta) : 1.f; }

  bool isDelta() const { return roughness <= 0.f; }
  bool coatIsDelta() const { return clearcoatRoughness <= 0.f; }
  float alpha() const { return alphaFromRoughness(roughness); }
  float f0Dielectric() const { return f0FromIor(ior); }
  bool hasSheen() const { return maxComponent(sheenColor) > 0.f; }
  bool hasCoat() const { return clearcoat > 0.f; }
  // KHR_materials_specular: the dielectric's Fresnel at cos(theta) = v.h, rgb, F90 = 1.
  glm::vec3 specularF0() const { return glm::min(f0Dielectric() * specularColor, glm::vec3(1.f)); }
  glm::vec3 dielectricFresnel(float cosTheta) const { return schlickFresnel(specularF0(), cosTheta); }

  // The coat's mix weight clearcoat Fc(|n_c.w|) (KHR_materials_clearcoat, fresnel_coat).
  float coatWeight(const glm::vec3& w) const {
    return hasCoat() ? clearcoat * schlickFresnel(gpu::kClearcoatF0, std::abs(glm::dot(coatNormal, w))) : 0.f;
  }
  // The base's sheen albedo scaling min(1 - max3(c) E(|n.wo|), 1 - max3(c) E(|n.wi|)) (KHR_materials_sheen).
  float sheenScaling(float cosO, float cosI) const {
    if (!hasSheen()) return 1.f;
    const float c = maxComponent(sheenColor);
    return std::max(0.f, std::min(1.f - c * sheenAlbedo(std::abs(cosO), sheenRoughness),
                                  1.f - c * sheenAlbedo(std::abs(cosI), sheenRoughness)));
  }
  // What the layers above leave of the base for the pair (wo, wi): (1 - coat weight) x sheen scaling.
  float baseAttenuation(const glm::vec3& wo, const glm::vec3& wi) const {
    return (1.f - coatWeight(wo)) * sheenScaling(wo.z, wi.z);
  }

  // Lobe selection probabilities at wo: the coat, the sheen, reflection (metal + opaque dielectric
  // specular), diffuse, and the transmissive dielectric (its reflection and refraction). Proportional
  // to each lobe's albedo estimated with the Fresnel factor at n.wo.
  struct LobeProbabilities { float reflect = 0.f, diffuse = 0.f, dielectric = 0.f, coat = 0.f, sheen = 0.f; };
  LobeProbabilities lobeProbabilities(const glm::vec3& wo) const {
    const float m = metallic, t = transmission;
    const glm::vec3 fd = dielectricFresnel(wo.z);
    const float fe = fresnelDielectric(wo.z, eta);
    const float lumBase = std::max(luminance(baseColor), 0.f);
    const float cw = coatWeight(wo);
    const float sheenE = hasSheen() ? maxComponent(sheenColor) * sheenAlbedo(wo.z, sheenRoughness) : 0.f;
    const float below = (1.f - cw) * std::max(0.f, 1.f - sheenE);
    LobeProbabilities p;
    p.reflect = below * (m * luminance(schlickFresnel(baseColor, wo.z)) +
                         (1.f - m) * (1.f - t) * specularWeight * luminance(fd));
    p.diffuse = below * (1.f - m) * (1.f - t) * (1.f - specularWeight * maxComponent(fd)) * lumBase;
    p.dielectric = below * (1.f - m) * t * (fe + (1.f - fe) * lumBase);
    p.coat = cw;
    p.sheen = (1.f - cw) * sheenE;
    const float sum = p.reflect + p.diffuse + p.dielectric + p.coat + p.sheen;
    if (!(sum > 0.f)) return {1.f, 0.f, 0.f, 0.f, 0.f};
    p.reflect /= sum; p.diffuse /= sum; p.dielectric /= sum; p.coat /= sum; p.sheen /= sum;
    return p;
  }
  // True when some lobe is not a Dirac delta (so light sampling can contribute).
  bool hasNonDeltaLobe(const glm::vec3& wo) const {
    if (!isDelta() || hasSheen() || (hasCoat() && !coatIsDelta())) return true;
    return lobeProbabilities(wo).diffuse > 0.f;
  }

  // The coat's D V around coatNormal (0 for a Dirac coat or wi below it).
  float coatLobe(const glm::vec3& wo, const glm::vec3& wi) const {
    if (coatIsDelta()) return 0.f;
    const float cO = glm::dot(coatNormal, wo), cI = glm::dot(coatNormal, wi);
    if (cO <= 0.f || cI <= 0.f) return 0.f;
    const glm::vec3 h = glm::normalize(wo + wi);
    const float a = alphaFromRoughness(clearcoatRoughness);
    return ggxD(glm::dot(coatNormal, h), a) * ggxVisibility(cI, cO, a);
  }

  // f(wo, wi) of the base material alone (metal, dielectric, transmission), without the layers.
  glm::vec3 evalBase(const glm::vec3& wo, const glm::vec3& wi) const {
    const float m = metallic, t = transmission;
    if (wi.z > 0.f) {
      const glm::vec3 h = glm::normalize(wo + wi);
      const float voh = glm::dot(wo, h);
      const glm::vec3 fd = dielectricFresnel(voh);
      // fresnel_mix: diffuse weighted by (1 - w max3(F_dielectric)), Lambert c_diff / pi.
      glm::vec3 f = (1.f - m) * (1.f - t) * (1.f - specularWeight * maxComponent(fd)) * baseColor * kInvPi;
      if (!isDelta()) {
        const float a = alpha();
        const float dv = ggxD(h.z, a) * ggxVisibility(wi.z, wo.z, a);
        const glm::vec3 fresnel = m * schlickFresnel(baseColor, voh) + (1.f - m) * (1.f - t) * specularWeight * fd +
                                  glm::vec3((1.f - m) * t * fresnelDielectric(voh, eta));
        f += fresnel * dv;
      }
      return f;
    }
    if (t <= 0.f || isDelta()) return glm::vec3(0.f);
    // Walter et al. 2007, eq. 21, with the generalised half vector h = normalise(eta wi + wo) (eq. 16)
    // and the height-correlated G2; divided by eta^2 when transporting radiance (Veach 1997, 5.2).
    const float a = alpha();
    glm::vec3 h = eta * wi + wo;
    if (glm::dot(h, h) == 0.f) return glm::vec3(0.f);
    h = glm::normalize(h);
    if (h.z < 0.f) h = -h;
    const float woh = glm::dot(wo, h), wih = glm::dot(wi, h);
    if (woh <= 0.f || wih >= 0.f) return glm::vec3(0.f);
    const float fe = fresnelDielectric(woh, eta);
    const float denom = sqr(wih + woh / eta) * std::abs(wi.z) * wo.z;
    const float ft = (1.f - fe) * ggxD(h.z, a) * smithG2HeightCorrelated(wo.z, wi.z, a) *
                     std::abs(wih * woh) / denom * refractionScale();
    return (1.f - m) * t * ft * baseColor;
  }

  // f(wo, wi) of the non-delta lobes (the deltas have no value off their direction). Not multiplied by
  // the cosine. wi below the horizon is transmission.
  glm::vec3 eval(const glm::vec3& wo, const glm::vec3& wi) const {
    if (wo.z <= 0.f || wi.z == 0.f) return glm::vec3(0.f);
    glm::vec3 f = evalBase(wo, wi);
    if (!hasSheen() && !hasCoat()) return f;
    f *= sheenScaling(wo.z, wi.z);
    if (hasSheen() && wi.z > 0.f) {
      const glm::vec3 h = glm::normalize(wo + wi);
      f += sheenColor * (charlieD(h.z, sheenAlphaFromRoughness(sheenRoughness)) * sheenVisibility(wi.z, wo.z));
    }
    if (hasCoat()) {
      const float cw = coatWeight(wo);
      f = f * (1.f - cw) + glm::vec3(cw * coatLobe(wo, wi));
    }
    return f;
  }

  // Solid-angle pdf of wi = reflect(-wo, h) with h from the coat's visible normals.
  float coatPdf(const glm::vec3& wo, const glm::vec3& wi) const {
    if (coatIsDelta()) return 0.f;
    const ShadingFrame cf = ShadingFrame::fromNormal(coatNormal);
    return ggxReflectionPdf(cf.toLocal(wo), cf.toLocal(wi), alphaFromRoughness(clearcoatRoughness));
  }

  // Solid-angle pdf with which sample() produces wi from its non-delta lobes.
  float pdf(const glm::vec3& wo, const glm::vec3& wi) const {
    if (wo.z <= 0.f || wi.z == 0.f) return 0.f;
    const LobeProbabilities p = lobeProbabilities(wo);
    if (wi.z > 0.f) {
      float pdf = (p.diffuse + p.sheen) * cosineHemispherePdf(wi.z);
      if (p.coat > 0.f) pdf += p.coat * coatPdf(wo, wi);
      if (!isDelta()) {
        const float a = alpha();
        const float pr = ggxReflectionPdf(wo, wi, a);
        const glm::vec3 h = glm::normalize(wo + wi);
        pdf += p.reflect * pr + p.dielectric * fresnelDielectric(glm::dot(wo, h), eta) * pr;
      }
      return pdf;
    }
    if (isDelta() || p.dielectric <= 0.f) return 0.f;
    const float a = alpha();
    glm::vec3 h = eta * wi + wo;
    if (glm::dot(h, h) == 0.f) return 0.f;
    h = glm::normalize(h);
    if (h.z < 0.f) h = -h;
    const float woh = glm::dot(wo, h), wih = glm::dot(wi, h);
    if (woh <= 0.f || wih >= 0.f) return 0.f;
    // Jacobian of the refraction half vector: |wi.h| / (wi.h + wo.h / eta)^2 (Walter et al. 2007, eq. 17
    // written for h = normalise(eta wi + wo)).
    const float dhdwi = std::abs(wih) / sqr(wih + woh / eta);
    return p.dielectric * (1.f - fresnelDielectric(woh, eta)) * ggxVndfPdf(wo, h, a) * dhdwi;
  }

  struct Sample {
    glm::vec3 wi{0.f};
    glm::vec3 weight{0.f};  // f |wi.z| / pdf (for deltas: the lobe's reflectance / selection probability)
    float pdf = 0.f;        // solid-angle pdf of the non-delta mixture; 0 for a delta sample
    bool delta = false;
    unsigned flags = 0;     // LobeFlags of the lobe that produced wi
  };
  // uLobe picks the lobe, uFresnel picks reflection or refraction in the dielectric lobe, u the direction.
  bool sample(const glm::vec3& wo, float uLobe, float uFresnel, glm::vec2 u, Sample& s) const {
    if (wo.z <= 0.f) return false;
    const LobeProbabilities p = lobeProbabilities(wo);
    const float m = metallic, t = transmission;
    if (uLobe < p.coat) {
      if (coatIsDelta()) {
        s.wi = reflect(wo, coatNormal);
        if (s.wi.z <= 0.f) return false;
        s.weight = glm::vec3(coatWeight(wo) / p.coat);
        s.pdf = 0.f;
        s.delta = true;
        s.flags = kLobeReflection | kLobeSpecular;
        return true;
      }
      const ShadingFrame cf = ShadingFrame::fromNormal(coatNormal);
      const glm::vec3 woC = cf.toLocal(wo);
      if (woC.z <= 0.f) return false;
      const glm::vec3 h = sampleGgxVndf(woC, alphaFromRoughness(clearcoatRoughness), u);
      s.wi = cf.toWorld(reflect(woC, h));
      if (s.wi.z <= 0.f) return false;
      s.flags = kLobeReflection | kLobeGlossy;
    } else if (uLobe < p.coat + p.sheen) {
      s.wi = sampleCosineHemisphere(u);
      if (s.wi.z <= 0.f) return false;
      s.flags = kLobeReflection | kLobeGlossy;
    } else if ((uLobe -= p.coat + p.sheen) < p.reflect) {
      if (isDelta()) {
        s.wi = {-wo.x, -wo.y, wo.z};
        const glm::vec3 fr = m * schlickFresnel(baseColor, wo.z) + (1.f - m) * (1.f - t) * specularWeight *
                                                                        dielectricFresnel(wo.z);
        s.weight = fr * baseAttenuation(wo, s.wi) / p.reflect;
        s.pdf = 0.f;
        s.delta = true;
        s.flags = kLobeReflection | kLobeSpecular;
        return true;
      }
      const glm::vec3 h = sampleGgxVndf(wo, alpha(), u);
      s.wi = reflect(wo, h);
      if (s.wi.z <= 0.f) return false;
      s.flags = kLobeReflection | kLobeGlossy;
    } else if (uLobe < p.reflect + p.diffuse) {
      s.wi = sampleCosineHemisphere(u);
      if (s.wi.z <= 0.f) return false;
      s.flags = kLobeReflection | kLobeDiffuse;
    } else {
      const glm::vec3 h = isDelta() ? glm::vec3(0.f, 0.f, 1.f) : sampleGgxVndf(wo, alpha(), u);
      const float woh = glm::dot(wo, h);
      if (woh <= 0.f) return false;
      const float fe = fresnelDielectric(woh, eta);
      bool reflected = uFresnel < fe;
      glm::vec3 wi;
      if (!reflected && !refract(wo, h, eta, wi)) reflected = true;  // fe == 1 already covers TIR
      if (reflected) wi = reflect(wo, h);
      const unsigned side = reflected ? kLobeReflection : kLobeTransmission;
      if (isDelta()) {
        s.wi = wi;
        s.delta = true;
        s.pdf = 0.f;
        s.flags = side | kLobeSpecular;
        // Lobe value (1-m) t F (reflection) or (1-m) t (1-F) base / eta^2 (refraction, radiance only),
        // over its selection probability p.dielectric * F or p.dielectric * (1 - F); times what the
        // layers above leave of it.
        s.weight = (reflected ? glm::vec3((1.f - m) * t / p.dielectric)
                              : (1.f - m) * t * baseColor * refractionScale() / p.dielectric) *
                   baseAttenuation(wo, wi);
        return true;
      }
      if (reflected ? wi.z <= 0.f : wi.z >= 0.f) return false;
      s.wi = wi;
      s.flags = side | kLobeGlossy;
    }
    s.delta = false;
    s.pdf = pdf(wo, s.wi);
    if (!(s.pdf > 0.f)) return false;
    s.weight = eval(wo, s.wi) * std::abs(s.wi.z) / s.pdf;
    return std::isfinite(s.weight.x + s.weight.y + s.weight.z);
  }
};

}  // namespace radiant::rt
