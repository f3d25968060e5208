#pragma once
// The glTF 2.0 metallic-roughness BSDF of the CPU ray-tracing core, with its sampling routines. The
// reference path tracer (radiance) and the photon tracer (importance) share it.
//
// ONE SOURCE: the BSDF's value, pdf and sampling are shaders/common/brdf.glsl, compiled here as C++
// inside namespace radiant::rt::glsl (the beam.glsl approach, ARCHITECTURE.md "One material model in
// two languages"); GltfBsdf calls it with n = +z, for which the GLSL's dot products and shading basis
// are exact (0 x + 0 y + 1 z = z). What stays C++-only is what no shader needs: the sheen table's
// construction, the other samplers below, and GltfBsdf's interface.
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
// (D_max = 1 / (pi alpha^2) ~ 3e5) and nothing produces NaN. kMinAlpha is gpu::kMinGgxAlpha
// (shaders/common/shared.h).
#include <algorithm>
#include <cmath>

#include <glm/glm.hpp>

#include "renderer/frame/GpuTypes.h"
#include "shaders/common/dual.glsl"

namespace radiant::rt {

inline constexpr float kPi = 3.14159265358979323846f;
inline constexpr float kInvPi = 1.f / kPi;  // the same float as GLSL's INV_PI (common/constants.glsl)
inline constexpr float kMinAlpha = gpu::kMinGgxAlpha;

// The sheen's directional-albedo table (built below; brdf.glsl reads it through glsl::sheenTableAt).
inline const float* sheenAlbedoTable();

namespace glsl {
using glm::vec2;
using glm::vec3;
using glm::vec4;
using glm::abs;
using glm::any;
using glm::clamp;
using glm::cos;
using glm::cross;
using glm::dot;
using glm::isinf;
using glm::isnan;
using glm::max;
using glm::min;
using glm::normalize;
using glm::pow;
using glm::sin;
using glm::sqrt;
using gpu::MaterialParams;
using gpu::kClearcoatF0;
using gpu::kLobeDiffuse;
using gpu::kLobeGlossy;
using gpu::kLobeReflection;
using gpu::kLobeSpecular;
using gpu::kLobeTransmission;
using gpu::kMinGgxAlpha;
using gpu::kMinSheenRoughness;
using gpu::kSheenAlbedoSize;
inline constexpr float PI = kPi;
inline constexpr float INV_PI = kInvPi;
inline float sheenTableAt(int i) { return sheenAlbedoTable()[i]; }
#include "shaders/common/brdf.glsl"
}  // namespace glsl

inline float luminance(const glm::vec3& c) { return glsl::materialLuminance(c); }
using glsl::maxComponent;
inline float safeSqrt(float x) { return std::sqrt(std::max(0.f, x)); }
inline float sqr(float x) { return x * x; }

// Orthonormal basis around n (glsl::shadingBasis, Duff et al. 2017).
struct ShadingFrame {
  glm::vec3 t, b, n;
  static ShadingFrame fromNormal(const glm::vec3& n) {
    const glsl::ShadingBasis f = glsl::shadingBasis(n);
    return {f.t, f.b, f.n};
  }
  glm::vec3 toLocal(const glm::vec3& v) const { return {glm::dot(v, t), glm::dot(v, b), glm::dot(v, n)}; }
  glm::vec3 toWorld(const glm::vec3& v) const { return v.x * t + v.y * b + v.z * n; }
};

// ---------------------------------------------------------------------------------------------------
// Sampling routines, each next to its pdf (solid-angle measure).

// Concentric square-to-disk map (Shirley and Chiu 1997); Malley's method, p(w) = cos(theta) / pi.
using glsl::cosineHemispherePdf;
using glsl::sampleConcentricDisk;
using glsl::sampleCosineHemisphere;

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
// GGX (Trowbridge-Reitz) microfacet distribution, isotropic, alpha = roughness^2; Fresnel; the sheen's
// Charlie distribution: brdf.glsl's, in the local frame (+z the lobe's normal) where they take one.

inline float alphaFromRoughness(float roughness) { return std::max(roughness * roughness, kMinAlpha); }
using glsl::charlieD;
using glsl::f0FromIor;
using glsl::fresnelDielectric;
using glsl::ggxD;
using glsl::ggxLambda;
using glsl::sampleGgxVndf;
using glsl::schlickFresnel;
using glsl::schlickWeight;
using glsl::sheenAlphaFromRoughness;
using glsl::sheenVisibility;
using glsl::smithG1;
using glsl::smithG2HeightCorrelated;
// glTF Appendix B, "Specular BRDF": V = G2 / (4 |n.l| |n.v|).
inline float ggxVisibility(float NdotL, float NdotV, float alpha) { return glsl::smithVisibility(NdotL, NdotV, alpha); }
inline constexpr glm::vec3 kLocalNormal{0.f, 0.f, 1.f};
// Density of sampleGgxVndf's h (Heitz 2018, eq. 3), local frame.
inline float ggxVndfPdf(const glm::vec3& wo, const glm::vec3& h, float alpha) {
  return glsl::ggxVndfPdf(kLocalNormal, wo, h, alpha);
}
// Density of wi = reflect(-wo, h) in solid angle: D_wo(h) / (4 |wo.h|), local frame.
inline float ggxReflectionPdf(const glm::vec3& wo, const glm::vec3& wi, float alpha) {
  return glsl::ggxReflectionPdf(kLocalNormal, wo, wi, alpha);
}
inline glm::vec3 reflect(const glm::vec3& wo, const glm::vec3& n) { return glsl::reflectAbout(wo, n); }
// Refraction of wo (wo.n > 0, pointing away) through an interface with normal n, eta = n_t / n_i.
// Returns false on total internal reflection.
inline bool refract(const glm::vec3& wo, const glm::vec3& n, float eta, glm::vec3& wi) {
  return glsl::refractAbout(wo, n, eta, wi);
}

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
// Bilinear lookup of the table (glsl::sheenAlbedo, the GPU's arithmetic).
inline float sheenAlbedo(float mu, float roughness) { return glsl::sheenAlbedo(mu, roughness); }

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

// The material's BSDF in the local shading frame: the fields of a decoded material (gpu::MaterialParams),
// the interface's relative index and what the path carries. Every method is brdf.glsl's function of the
// same name with n = +z and nc = coatNormal.
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

  // The BSDF of a decoded material (material_decode.glsl's decodeBsdfInputs; eta = ior, as seen from outside:
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
  // The decoded material these fields are (fromParams' inverse; emission is not the BSDF's).
  gpu::MaterialParams params() const {
    gpu::MaterialParams p;
    p.baseColor = glm::vec4(baseColor, 1.f);
    p.emission = glm::vec4(0.f, 0.f, 0.f, 1.f);
    p.surface = glm::vec4(metallic, roughness, transmission, ior);
    p.clearcoat = glm::vec4(clearcoat, clearcoatRoughness, 0.f, 0.f);
    p.sheen = glm::vec4(sheenColor, sheenRoughness);
    p.specular = glm::vec4(specularColor, specularWeight);
    return p;
  }

  // 1 / eta^2 on refraction for radiance, 1 for importance.
  float refractionScale() const { return mode == TransportMode::Radiance ? 1.f / (eta * eta) : 1.f; }

  bool isDelta() const { return roughness <= 0.f; }
  bool coatIsDelta() const { return clearcoatRoughness <= 0.f; }
  float alpha() const { return alphaFromRoughness(roughness); }
  bool hasSheen() const { return maxComponent(sheenColor) > 0.f; }
  bool hasCoat() const { return clearcoat > 0.f; }
  // KHR_materials_specular: the dielectric's Fresnel at cos(theta) = v.h, rgb, F90 = 1.
  glm::vec3 specularF0() const { return glsl::specularF0(params()); }
  glm::vec3 dielectricFresnel(float cosTheta) const { return schlickFresnel(specularF0(), cosTheta); }

  // The coat's mix weight clearcoat Fc(|n_c.w|) (KHR_materials_clearcoat, fresnel_coat).
  float coatWeight(const glm::vec3& w) const { return glsl::coatWeight(params(), coatNormal, w); }
  // The base's sheen albedo scaling min(1 - max3(c) E(|n.wo|), 1 - max3(c) E(|n.wi|)) (KHR_materials_sheen).
  float sheenScaling(float cosO, float cosI) const { return glsl::sheenScaling(params(), cosO, cosI); }

  using LobeProbabilities = glsl::LobeProbabilities;
  LobeProbabilities lobeProbabilities(const glm::vec3& wo) const {
    return glsl::lobeProbabilities(kLocalNormal, coatNormal, wo, params(), eta);
  }
  // True when some lobe is not a Dirac delta (so light sampling can contribute).
  bool hasNonDeltaLobe(const glm::vec3& wo) const {
    if (!isDelta() || hasSheen() || (hasCoat() && !coatIsDelta())) return true;
    return lobeProbabilities(wo).diffuse > 0.f;
  }

  // f(wo, wi) of the non-delta lobes (the deltas have no value off their direction). Not multiplied by
  // the cosine. wi below the horizon is transmission.
  glm::vec3 eval(const glm::vec3& wo, const glm::vec3& wi) const {
    return glsl::gltfBsdf(kLocalNormal, coatNormal, wo, wi, params(), eta, refractionScale());
  }
  // Solid-angle pdf with which sample() produces wi from its non-delta lobes.
  float pdf(const glm::vec3& wo, const glm::vec3& wi) const {
    return glsl::pdfMaterial(kLocalNormal, coatNormal, wo, wi, params(), eta);
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
    const glsl::MaterialSample m = glsl::sampleMaterial(kLocalNormal, coatNormal, wo, params(), eta,
                                                        mode == TransportMode::Importance,
                                                        glm::vec4(uLobe, uFresnel, u.x, u.y));
    s.wi = m.wi;
    s.weight = m.weight;
    s.pdf = m.pdf;
    s.delta = m.delta;
    s.flags = unsigned(m.flags);
    return m.valid;
  }
};

}  // namespace radiant::rt
