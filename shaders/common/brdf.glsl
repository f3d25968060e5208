// The glTF 2.0 metallic-roughness BSDF, spec Appendix B, with KHR_materials_ior (dielectric F0 from
// ior) and KHR_materials_transmission, evaluated as f(wo, wi) |cos(theta_i)| for a light direction.
// It is the GLSL twin of rt::GltfBsdf::eval (renderer/raytracing/Bsdf.h), term for term, in radiance
// mode; tests/gl/materials/parity_test.cpp holds the two to float tolerance on random inputs:
//   diffuse      (1 - metallic)(1 - transmission)(1 - F_schlick(f0_ior, v.h)) baseColor / pi
//   specular     D V [metallic F_schlick(baseColor, v.h) + (1 - metallic)(1 - transmission) F_schlick(f0_ior, v.h)
//                     + (1 - metallic) transmission F_exact(v.h, eta)]
//   transmission (wi below the surface) Walter et al. 2007 eq. 21, tinted by baseColor, / eta^2
// where the reflection off the transmissive part uses the exact unpolarised Fresnel factor (as the
// reference, which models a transmissive surface as the interface of a solid of index ior).
// Roughness 0 makes the specular and transmission lobes Dirac deltas: they carry no value towards a
// light direction (a punctual light seen in a perfect mirror has zero measure), only the diffuse
// lobe remains. Otherwise alpha = max(roughness^2, kMinGgxAlpha) (common/shared.h).
#ifndef RADIANT_COMMON_BRDF
#define RADIANT_COMMON_BRDF
#include "common/constants.glsl"
#include "common/shared.h"

// glTF Appendix B: D = alpha^2 chi+(n.h) / (pi ((n.h)^2 (alpha^2 - 1) + 1)^2).
float ggxD(float NdotH, float alpha) {
  if (NdotH <= 0.0) return 0.0;
  float a2 = alpha * alpha;
  float d = NdotH * NdotH * (a2 - 1.0) + 1.0;
  return a2 / (PI * d * d);
}

// Height-correlated Smith visibility V = G / (4 NdotL NdotV) (spec Appendix B, "Specular BRDF").
float smithVisibility(float NdotL, float NdotV, float alpha) {
  if (NdotL <= 0.0 || NdotV <= 0.0) return 0.0;
  float a2 = alpha * alpha;
  float gv = NdotL * sqrt(NdotV * NdotV * (1.0 - a2) + a2);
  float gl = NdotV * sqrt(NdotL * NdotL * (1.0 - a2) + a2);
  float s = gv + gl;
  return s > 0.0 ? 0.5 / s : 0.0;
}

// Smith Lambda for GGX (Heitz 2014, eq. 72) and the height-correlated G2 (eq. 99).
float ggxLambda(float cosTheta, float alpha) {
  float c2 = cosTheta * cosTheta;
  if (c2 <= 0.0) return 1e30;
  float tan2 = max(0.0, 1.0 - c2) / c2;
  return 0.5 * (-1.0 + sqrt(1.0 + alpha * alpha * tan2));
}
float smithG2HeightCorrelated(float cosO, float cosI, float alpha) {
  return 1.0 / (1.0 + ggxLambda(abs(cosO), alpha) + ggxLambda(abs(cosI), alpha));
}

float schlickWeight(float cosTheta) {
  float m = clamp(1.0 - abs(cosTheta), 0.0, 1.0);
  float m2 = m * m;
  return m2 * m2 * m;
}
vec3 schlickFresnel(vec3 f0, float cosTheta) { return f0 + (1.0 - f0) * schlickWeight(cosTheta); }
float schlickFresnel(float f0, float cosTheta) { return f0 + (1.0 - f0) * schlickWeight(cosTheta); }
float f0FromIor(float ior) {
  float r = (ior - 1.0) / (ior + 1.0);
  return r * r;
}

// Exact unpolarised Fresnel reflectance, eta = n_t / n_i, cos_i >= 0; 1 under total internal reflection.
float fresnelDielectric(float cosThetaI, float eta) {
  cosThetaI = clamp(cosThetaI, 0.0, 1.0);
  float sin2T = (1.0 - cosThetaI * cosThetaI) / (eta * eta);
  if (sin2T >= 1.0) return 1.0;
  float cosT = sqrt(max(0.0, 1.0 - sin2T));
  float rs = (cosThetaI - eta * cosT) / (cosThetaI + eta * cosT);
  float rp = (eta * cosThetaI - cosT) / (eta * cosThetaI + cosT);
  return 0.5 * (rs * rs + rp * rp);
}

// KHR_materials_sheen: Charlie D (Estevez and Kulla 2017, eq. 2) and Ashikhmin's visibility (Neubelt and
// Pettineo 2013), and the directional albedo E(mu, r) from the table rt::sheenAlbedoTable() builds
// (GpuScene uploads it at kBindingSheenAlbedo), interpolated as rt::sheenAlbedo does.
layout(std430, binding = kBindingSheenAlbedo) readonly buffer SheenAlbedoTable { float sheenAlbedoTable[]; };
float charlieD(float NdotH, float alpha) {
  if (NdotH <= 0.0) return 0.0;
  float invA = 1.0 / alpha;
  float sin2 = max(0.0, 1.0 - NdotH * NdotH);
  return (2.0 + invA) * pow(sin2, 0.5 * invA) / (2.0 * PI);
}
float sheenVisibility(float NdotL, float NdotV) {
  if (NdotL <= 0.0 || NdotV <= 0.0) return 0.0;
  return 1.0 / (4.0 * (NdotL + NdotV - NdotL * NdotV));
}
float sheenAlbedo(float mu, float roughness) {
  const int N = kSheenAlbedoSize;
  float x = clamp(mu, 0.0, 1.0) * float(N - 1);
  float y = clamp((roughness - kMinSheenRoughness) / (1.0 - kMinSheenRoughness), 0.0, 1.0) * float(N - 1);
  int x0 = min(int(x), N - 2), y0 = min(int(y), N - 2);
  float fx = x - float(x0), fy = y - float(y0);
  float a = sheenAlbedoTable[y0 * N + x0] + (sheenAlbedoTable[y0 * N + x0 + 1] - sheenAlbedoTable[y0 * N + x0]) * fx;
  float b = sheenAlbedoTable[(y0 + 1) * N + x0] +
            (sheenAlbedoTable[(y0 + 1) * N + x0 + 1] - sheenAlbedoTable[(y0 + 1) * N + x0]) * fx;
  return a + (b - a) * fy;
}
float maxComponent(vec3 c) { return max(c.r, max(c.g, c.b)); }
bool materialHasSheen(MaterialParams p) { return maxComponent(p.sheen.rgb) > 0.0; }
// min(1 - max3(c) E(|n.v|), 1 - max3(c) E(|n.l|)), 1 without sheen.
float sheenScaling(MaterialParams p, float cosO, float cosI) {
  if (!materialHasSheen(p)) return 1.0;
  float c = maxComponent(p.sheen.rgb);
  return max(0.0, min(1.0 - c * sheenAlbedo(abs(cosO), p.sheen.a), 1.0 - c * sheenAlbedo(abs(cosI), p.sheen.a)));
}
// KHR_materials_clearcoat: the coat's mix weight clearcoat Fc(|n_c.v|), F0 0.04.
float coatWeight(MaterialParams p, vec3 nc, vec3 wo) {
  return p.clearcoat.x > 0.0 ? p.clearcoat.x * schlickFresnel(kClearcoatF0, abs(dot(nc, wo))) : 0.0;
}
// KHR_materials_specular: the opaque dielectric's F0 = min(F0(ior) specularColor, 1).
vec3 specularF0(MaterialParams p) { return min(f0FromIor(p.surface.w) * p.specular.rgb, vec3(1.0)); }

// f(wo, wi) |n.wi| of the base material (metal, dielectric, transmission), without the layers.
vec3 gltfBaseBsdfCos(vec3 n, vec3 wo, vec3 wi, MaterialParams p, float eta) {
  float NdotV = dot(n, wo);
  float NdotL = dot(n, wi);
  vec3 base = p.baseColor.rgb;
  float m = p.surface.x, roughness = p.surface.y, t = p.surface.z, w = p.specular.a;
  bool delta = roughness <= 0.0;
  float alpha = max(roughness * roughness, kMinGgxAlpha);
  if (NdotL > 0.0) {
    vec3 h = normalize(wo + wi);
    float VdotH = dot(wo, h);
    vec3 fd = schlickFresnel(specularF0(p), VdotH);
    // fresnel_mix: the diffuse lobe weighted by (1 - w max3(F_dielectric)), Lambert c_diff / pi.
    vec3 f = (1.0 - m) * (1.0 - t) * (1.0 - w * maxComponent(fd)) * base * INV_PI;
    if (!delta) {
      float dv = ggxD(dot(n, h), alpha) * smithVisibility(NdotL, NdotV, alpha);
      vec3 fresnel = m * schlickFresnel(base, VdotH) + (1.0 - m) * (1.0 - t) * w * fd +
                     vec3((1.0 - m) * t * fresnelDielectric(VdotH, eta));
      f += fresnel * dv;
    }
    return f * NdotL;
  }
  if (t <= 0.0 || delta) return vec3(0.0);
  // Walter et al. 2007, eq. 21 with h = normalise(eta wi + wo) (eq. 16) and the height-correlated G2;
  // radiance is compressed by 1 / eta^2 on refraction (Veach 1997, eq. 5.14).
  vec3 h = eta * wi + wo;
  if (dot(h, h) == 0.0) return vec3(0.0);
  h = normalize(h);
  if (dot(n, h) < 0.0) h = -h;
  float woh = dot(wo, h), wih = dot(wi, h);
  if (woh <= 0.0 || wih >= 0.0) return vec3(0.0);
  float fe = fresnelDielectric(woh, eta);
  float s = wih + woh / eta;
  float denom = s * s * abs(NdotL) * NdotV;
  float ft = (1.0 - fe) * ggxD(dot(n, h), alpha) * smithG2HeightCorrelated(NdotV, NdotL, alpha) *
             abs(wih * woh) / denom / (eta * eta);
  return (1.0 - m) * t * ft * base * abs(NdotL);
}

// f(wo, wi) |n.wi| for the decoded material p with its layers (sheen over the base, the clear coat over
// both; rt::GltfBsdf::eval). n the shading normal, nc the coat's normal (the interpolated normal, not
// normal-mapped), wo, wi unit vectors, wo on n's side; wi below the surface is transmission.
// eta = n_(far side) / n_(wo side): ior seen from outside, 1 / ior inside.
vec3 gltfBsdfCos(vec3 n, vec3 nc, vec3 wo, vec3 wi, MaterialParams p, float eta) {
  float NdotV = dot(n, wo);
  float NdotL = dot(n, wi);
  if (NdotV <= 0.0 || NdotL == 0.0) return vec3(0.0);
  vec3 f = gltfBaseBsdfCos(n, wo, wi, p, eta);
  bool sheen = materialHasSheen(p);
  if (!sheen && p.clearcoat.x <= 0.0) return f;
  f *= sheenScaling(p, NdotV, NdotL);
  if (sheen && NdotL > 0.0) {
    vec3 h = normalize(wo + wi);
    float as = p.sheen.a * p.sheen.a;
    f += p.sheen.rgb * (charlieD(dot(n, h), as) * sheenVisibility(NdotL, NdotV) * NdotL);
  }
  if (p.clearcoat.x > 0.0) {
    float cw = coatWeight(p, nc, wo);
    float coat = 0.0;
    float cO = dot(nc, wo), cI = dot(nc, wi);
    if (p.clearcoat.y > 0.0 && cO > 0.0 && cI > 0.0) {
      float a = max(p.clearcoat.y * p.clearcoat.y, kMinGgxAlpha);
      coat = ggxD(dot(nc, normalize(wo + wi)), a) * smithVisibility(cI, cO, a);
    }
    f = f * (1.0 - cw) + vec3(cw * coat * abs(NdotL));
  }
  return f;
}
vec3 gltfBsdfCos(vec3 n, vec3 wo, vec3 wi, MaterialParams p, float eta) { return gltfBsdfCos(n, n, wo, wi, p, eta); }

// The surface seen from outside (eta = ior), as every raster pass sees it.
vec3 gltfBrdfCos(vec3 n, vec3 wo, vec3 wi, MaterialParams p) { return gltfBsdfCos(n, wo, wi, p, p.surface.w); }

MaterialParams materialParams(vec3 baseColor, float metallic, float roughness, float transmission, float ior) {
  MaterialParams p;
  p.baseColor = vec4(baseColor, 1.0);
  p.emission = vec4(0.0, 0.0, 0.0, 1.0);
  p.surface = vec4(metallic, roughness, transmission, ior);
  p.clearcoat = vec4(0.0);
  p.sheen = vec4(0.0, 0.0, 0.0, kMinSheenRoughness);
  p.specular = vec4(1.0);
  return p;
}

// The former positional signature, kept for callers not yet on MaterialParams.
vec3 gltfBrdfCos(vec3 n, vec3 wo, vec3 wi, vec3 baseColor, float metallic, float roughness, float transmission,
                 float ior) {
  return gltfBrdfCos(n, wo, wi, materialParams(baseColor, metallic, roughness, transmission, ior));
}
#endif
