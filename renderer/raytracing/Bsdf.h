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
enum LobeFlags : unsigned {
  kLobeReflection = 1u, kLobeTransmission = 2u,
  kLobeDiffuse = 4u, kLobeGlossy = 8u, kLobeSpecular = 16u,  // specular = Dirac delta
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

  // 1 / eta^2 on refraction for radiance, 1 for importance.
  float refractionScale() const { return mode == TransportMode::Radiance ? 1.f / (eta * eta) : 1.f; }

  bool isDelta() const { return roughness <= 0.f; }
  float alpha() const { return alphaFromRoughness(roughness); }
  float f0Dielectric() const { return f0FromIor(ior); }

  // Lobe selection probabilities at wo: reflection (metal + opaque dielectric specular), diffuse, and
  // the transmissive dielectric (its reflection and refraction). Proportional to each lobe's albedo
  // estimated with the Fresnel factor at n.wo.
  struct LobeProbabilities { float reflect = 0.f, diffuse = 0.f, dielectric = 0.f; };
  LobeProbabilities lobeProbabilities(const glm::vec3& wo) const {
    const float m = metallic, t = transmission;
    const float fd = schlickFresnel(f0Dielectric(), wo.z);
    const float fe = fresnelDielectric(wo.z, eta);
    const float lumBase = std::max(luminance(baseColor), 0.f);
    LobeProbabilities p;
    p.reflect = m * luminance(schlickFresnel(baseColor, wo.z)) + (1.f - m) * (1.f - t) * fd;
    p.diffuse = (1.f - m) * (1.f - t) * (1.f - fd) * lumBase;
    p.dielectric = (1.f - m) * t * (fe + (1.f - fe) * lumBase);
    const float sum = p.reflect + p.diffuse + p.dielectric;
    if (!(sum > 0.f)) return {1.f, 0.f, 0.f};
    p.reflect /= sum; p.diffuse /= sum; p.dielectric /= sum;
    return p;
  }
  // True when some lobe is not a Dirac delta (so light sampling can contribute).
  bool hasNonDeltaLobe(const glm::vec3& wo) const {
    if (!isDelta()) return true;
    return lobeProbabilities(wo).diffuse > 0.f;
  }

  // f(wo, wi) of the non-delta lobes (the deltas have no value off their direction). Not multiplied by
  // the cosine. wi below the horizon is transmission.
  glm::vec3 eval(const glm::vec3& wo, const glm::vec3& wi) const {
    if (wo.z <= 0.f || wi.z == 0.f) return glm::vec3(0.f);
    const float m = metallic, t = transmission;
    if (wi.z > 0.f) {
      const glm::vec3 h = glm::normalize(wo + wi);
      const float voh = glm::dot(wo, h);
      const float fd = schlickFresnel(f0Dielectric(), voh);
      // fresnel_mix: diffuse weighted by (1 - F_dielectric), Lambert c_diff / pi.
      glm::vec3 f = (1.f - m) * (1.f - t) * (1.f - fd) * baseColor * kInvPi;
      if (!isDelta()) {
        const float a = alpha();
        const float dv = ggxD(h.z, a) * ggxVisibility(wi.z, wo.z, a);
        const glm::vec3 fresnel = m * schlickFresnel(baseColor, voh) + glm::vec3((1.f - m) * (1.f - t) * fd) +
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

  // Solid-angle pdf with which sample() produces wi from its non-delta lobes.
  float pdf(const glm::vec3& wo, const glm::vec3& wi) const {
    if (wo.z <= 0.f || wi.z == 0.f) return 0.f;
    const LobeProbabilities p = lobeProbabilities(wo);
    if (wi.z > 0.f) {
      float pdf = p.diffuse * cosineHemispherePdf(wi.z);
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
    if (uLobe < p.reflect) {
      if (isDelta()) {
        s.wi = {-wo.x, -wo.y, wo.z};
        const glm::vec3 fr = m * schlickFresnel(baseColor, wo.z) +
                             glm::vec3((1.f - m) * (1.f - t) * schlickFresnel(f0Dielectric(), wo.z));
        s.weight = fr / p.reflect;
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
        // over its selection probability p.dielectric * F or p.dielectric * (1 - F).
        s.weight = reflected ? glm::vec3((1.f - m) * t / p.dielectric)
                             : (1.f - m) * t * baseColor * refractionScale() / p.dielectric;
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
