// The glTF 2.0 metallic-roughness BSDF, spec Appendix B, with KHR_materials_ior (dielectric F0 from
// ior), KHR_materials_transmission, _specular, _sheen and _clearcoat: its value, its pdf and its
// sampling, the one definition for GLSL and C++ (the beam.glsl approach).
//   GLSL: #include "common/brdf.glsl" (the shader library prepends #version 450 core);
//   C++:  renderer/raytracing/Bsdf.h includes this file inside namespace radiant::rt::glsl with glm's
//         vector types and functions, and rt::GltfBsdf (the reference path tracer's and the photon
//         tracer's BSDF) calls these functions with n = +z, its local shading frame.
// Rules that keep the two readings identical: float literals carry the f suffix (a C++ double literal
// would make the arithmetic double), functions are marked RADIANT_FN (inline in C++), out parameters
// are RADIANT_OUT(type), struct parameters RADIANT_IN(type) (a const reference in C++, not a copy;
// the macros are common/dual.glsl's, which C++ includes before the namespace), no struct
// constructors, no swizzles (vec3(v) takes xyz; .x/.a members are fine), and the GLSL-only lines
// (includes, the sheen table's buffer) sit in #ifndef __cplusplus.
// tests/gl/materials/parity_test.cpp now checks the two compilers of this file against each other.
//
// The BSDF, evaluated as f(wo, wi) for a light direction wi (gltfBsdf) or f |n.wi| (gltfBsdfCos):
//   diffuse      (1 - metallic)(1 - transmission)(1 - w max3(F_schlick(f0, v.h))) baseColor / pi
//   specular     D V [metallic F_schlick(baseColor, v.h) + (1 - metallic)(1 - transmission) w F_schlick(f0, v.h)
//                     + (1 - metallic) transmission F_exact(v.h, eta)]
//   transmission (wi below the surface) Walter et al. 2007 eq. 21, tinted by baseColor, / eta^2
// with f0 = min(f0(ior) specularColor, 1) and w the specular weight (KHR_materials_specular), and the
// reflection off the transmissive part with the exact unpolarised Fresnel factor (a transmissive
// surface is the interface of a solid of index ior; renderer/raytracing/Bsdf.h says why). The sheen
// (Charlie D, Ashikhmin V) scales the base by min(1 - max3(c) E(n.v), 1 - max3(c) E(n.l)); the clear
// coat mixes with weight clearcoat F_schlick(0.04, |n_c.v|). Roughness 0 makes the specular and
// transmission lobes Dirac deltas: they carry no value towards a light direction (a punctual light
// seen in a perfect mirror has zero measure), only sampleMaterial() produces them. Otherwise
// alpha = max(roughness^2, kMinGgxAlpha) (common/shared.h).
#ifndef RADIANT_COMMON_BRDF
#define RADIANT_COMMON_BRDF
#ifndef __cplusplus
#include "common/constants.glsl"
#include "common/dual.glsl"
#include "common/shared.h"
#endif

// glTF Appendix B: D = alpha^2 chi+(n.h) / (pi ((n.h)^2 (alpha^2 - 1) + 1)^2).
RADIANT_FN float ggxD(float NdotH, float alpha) {
  if (NdotH <= 0.0f) return 0.0f;
  float a2 = alpha * alpha;
  float d = NdotH * NdotH * (a2 - 1.0f) + 1.0f;
  return a2 / (PI * d * d);
}

// Height-correlated Smith visibility V = G / (4 NdotL NdotV) (spec Appendix B, "Specular BRDF").
RADIANT_FN float smithVisibility(float NdotL, float NdotV, float alpha) {
  if (NdotL <= 0.0f || NdotV <= 0.0f) return 0.0f;
  float a2 = alpha * alpha;
  float gv = NdotL * sqrt(NdotV * NdotV * (1.0f - a2) + a2);
  float gl = NdotV * sqrt(NdotL * NdotL * (1.0f - a2) + a2);
  float s = gv + gl;
  return s > 0.0f ? 0.5f / s : 0.0f;
}

// Smith Lambda for GGX (Heitz 2014, eq. 72) and the height-correlated G2 (eq. 99).
RADIANT_FN float ggxLambda(float cosTheta, float alpha) {
  float c2 = cosTheta * cosTheta;
  if (c2 <= 0.0f) return 1e30f;
  float tan2 = max(0.0f, 1.0f - c2) / c2;
  return 0.5f * (-1.0f + sqrt(1.0f + alpha * alpha * tan2));
}
RADIANT_FN float smithG1(float cosTheta, float alpha) { return 1.0f / (1.0f + ggxLambda(cosTheta, alpha)); }
RADIANT_FN float smithG2HeightCorrelated(float cosO, float cosI, float alpha) {
  return 1.0f / (1.0f + ggxLambda(abs(cosO), alpha) + ggxLambda(abs(cosI), alpha));
}

RADIANT_FN float schlickWeight(float cosTheta) {
  float m = clamp(1.0f - abs(cosTheta), 0.0f, 1.0f);
  float m2 = m * m;
  return m2 * m2 * m;
}
RADIANT_FN vec3 schlickFresnel(vec3 f0, float cosTheta) { return f0 + (1.0f - f0) * schlickWeight(cosTheta); }
RADIANT_FN float schlickFresnel(float f0, float cosTheta) { return f0 + (1.0f - f0) * schlickWeight(cosTheta); }
RADIANT_FN float f0FromIor(float ior) {
  float r = (ior - 1.0f) / (ior + 1.0f);
  return r * r;
}

// Exact unpolarised Fresnel reflectance R = (Rs + Rp) / 2, eta = n_t / n_i (the far side's index over
// the incident side's), cos_i >= 0; 1 under total internal reflection.
RADIANT_FN float fresnelDielectric(float cosThetaI, float eta) {
  cosThetaI = clamp(cosThetaI, 0.0f, 1.0f);
  float sin2T = (1.0f - cosThetaI * cosThetaI) / (eta * eta);
  if (sin2T >= 1.0f) return 1.0f;
  float cosT = sqrt(max(0.0f, 1.0f - sin2T));
  float rs = (cosThetaI - eta * cosT) / (cosThetaI + eta * cosT);
  float rp = (eta * cosThetaI - cosT) / (eta * cosThetaI + cosT);
  return 0.5f * (rs * rs + rp * rp);
}

// KHR_materials_sheen: Charlie D (Estevez and Kulla 2017, eq. 2) and Ashikhmin's visibility (Neubelt and
// Pettineo 2013, which includes 1 / (4 n.l n.v)), and the directional albedo E(mu, r) from the table
// rt::sheenAlbedoTable() builds (GpuScene uploads it at kBindingSheenAlbedo; C++ reads it through
// sheenTableAt, declared before this file is included), interpolated bilinearly.
#ifndef __cplusplus
layout(std430, binding = kBindingSheenAlbedo) readonly buffer SheenAlbedoTable { float sheenAlbedoTable[]; };
float sheenTableAt(int i) { return sheenAlbedoTable[i]; }
#endif
RADIANT_FN float charlieD(float NdotH, float alpha) {
  if (NdotH <= 0.0f) return 0.0f;
  float invA = 1.0f / alpha;
  float sin2 = max(0.0f, 1.0f - NdotH * NdotH);
  return (2.0f + invA) * pow(sin2, 0.5f * invA) / (2.0f * PI);
}
RADIANT_FN float sheenVisibility(float NdotL, float NdotV) {
  if (NdotL <= 0.0f || NdotV <= 0.0f) return 0.0f;
  return 1.0f / (4.0f * (NdotL + NdotV - NdotL * NdotV));
}
// The Charlie alpha = r^2 of the sheen roughness r clamped to [kMinSheenRoughness, 1].
RADIANT_FN float sheenAlphaFromRoughness(float r) {
  float c = clamp(r, kMinSheenRoughness, 1.0f);
  return c * c;
}
RADIANT_FN float sheenAlbedo(float mu, float roughness) {
  const int N = kSheenAlbedoSize;
  float x = clamp(mu, 0.0f, 1.0f) * float(N - 1);
  float y = clamp((roughness - kMinSheenRoughness) / (1.0f - kMinSheenRoughness), 0.0f, 1.0f) * float(N - 1);
  int x0 = min(int(x), N - 2), y0 = min(int(y), N - 2);
  float fx = x - float(x0), fy = y - float(y0);
  float a = sheenTableAt(y0 * N + x0) + (sheenTableAt(y0 * N + x0 + 1) - sheenTableAt(y0 * N + x0)) * fx;
  float b = sheenTableAt((y0 + 1) * N + x0) +
            (sheenTableAt((y0 + 1) * N + x0 + 1) - sheenTableAt((y0 + 1) * N + x0)) * fx;
  return a + (b - a) * fy;
}
RADIANT_FN float maxComponent(vec3 c) { return max(c.r, max(c.g, c.b)); }
RADIANT_FN float materialLuminance(vec3 c) { return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b; }
RADIANT_FN bool materialHasSheen(RADIANT_IN(MaterialParams) p) { return maxComponent(vec3(p.sheen)) > 0.0f; }
// min(1 - max3(c) E(|n.v|), 1 - max3(c) E(|n.l|)), 1 without sheen.
RADIANT_FN float sheenScaling(RADIANT_IN(MaterialParams) p, float cosO, float cosI) {
  if (!materialHasSheen(p)) return 1.0f;
  float c = maxComponent(vec3(p.sheen));
  return max(0.0f, min(1.0f - c * sheenAlbedo(abs(cosO), p.sheen.a), 1.0f - c * sheenAlbedo(abs(cosI), p.sheen.a)));
}
// KHR_materials_clearcoat: the coat's mix weight clearcoat Fc(|n_c.w|), F0 0.04.
RADIANT_FN float coatWeight(RADIANT_IN(MaterialParams) p, vec3 nc, vec3 w) {
  return p.clearcoat.x > 0.0f ? p.clearcoat.x * schlickFresnel(kClearcoatF0, abs(dot(nc, w))) : 0.0f;
}
// KHR_materials_specular: the opaque dielectric's F0 = min(F0(ior) specularColor, 1).
RADIANT_FN vec3 specularF0(RADIANT_IN(MaterialParams) p) { return min(f0FromIor(p.surface.w) * vec3(p.specular), vec3(1.0f)); }

// f(wo, wi) of the base material (metal, dielectric, transmission), without the layers; wi below the
// surface is transmission. refractionScale: 1 / eta^2 when transporting radiance, 1 for importance
// (rt::TransportMode).
RADIANT_FN vec3 gltfBaseBsdf(vec3 n, vec3 wo, vec3 wi, RADIANT_IN(MaterialParams) p, float eta, float refractionScale) {
  float NdotV = dot(n, wo);
  float NdotL = dot(n, wi);
  vec3 base = vec3(p.baseColor);
  float m = p.surface.x, roughness = p.surface.y, t = p.surface.z, w = p.specular.a;
  bool delta = roughness <= 0.0f;
  float alpha = max(roughness * roughness, kMinGgxAlpha);
  if (NdotL > 0.0f) {
    vec3 h = normalize(wo + wi);
    float VdotH = dot(wo, h);
    vec3 fd = schlickFresnel(specularF0(p), VdotH);
    // fresnel_mix: the diffuse lobe weighted by (1 - w max3(F_dielectric)), Lambert c_diff / pi.
    vec3 f = (1.0f - m) * (1.0f - t) * (1.0f - w * maxComponent(fd)) * base * INV_PI;
    if (!delta) {
      float dv = ggxD(dot(n, h), alpha) * smithVisibility(NdotL, NdotV, alpha);
      vec3 fresnel = m * schlickFresnel(base, VdotH) + (1.0f - m) * (1.0f - t) * w * fd +
                     vec3((1.0f - m) * t * fresnelDielectric(VdotH, eta));
      f += fresnel * dv;
    }
    return f;
  }
  if (t <= 0.0f || delta) return vec3(0.0f);
  // Walter et al. 2007, eq. 21 with h = normalise(eta wi + wo) (eq. 16) and the height-correlated G2;
  // radiance is compressed by 1 / eta^2 on refraction (Veach 1997, eq. 5.14).
  vec3 h = eta * wi + wo;
  if (dot(h, h) == 0.0f) return vec3(0.0f);
  h = normalize(h);
  if (dot(n, h) < 0.0f) h = -h;
  float woh = dot(wo, h), wih = dot(wi, h);
  if (woh <= 0.0f || wih >= 0.0f) return vec3(0.0f);
  float fe = fresnelDielectric(woh, eta);
  float s = wih + woh / eta;
  float denom = s * s * abs(NdotL) * NdotV;
  float ft = (1.0f - fe) * ggxD(dot(n, h), alpha) * smithG2HeightCorrelated(NdotV, NdotL, alpha) *
             abs(wih * woh) / denom * refractionScale;
  return (1.0f - m) * t * ft * base;
}

// f(wo, wi) for the decoded material p with its layers (sheen over the base, the clear coat over both).
// n the shading normal, nc the coat's normal (the interpolated normal, not normal-mapped), wo, wi unit
// vectors, wo on n's side; wi below the surface is transmission. eta = n_(far side) / n_(wo side): ior
// seen from outside, 1 / ior inside. The coat's mix weight depends on wo alone, so a coated BSDF is
// not reciprocal (tests/unit/raytracing/BsdfTest.cpp states the ratio).
RADIANT_FN vec3 gltfBsdf(vec3 n, vec3 nc, vec3 wo, vec3 wi, RADIANT_IN(MaterialParams) p, float eta, float refractionScale) {
  float NdotV = dot(n, wo);
  float NdotL = dot(n, wi);
  if (NdotV <= 0.0f || NdotL == 0.0f) return vec3(0.0f);
  vec3 f = gltfBaseBsdf(n, wo, wi, p, eta, refractionScale);
  bool sheen = materialHasSheen(p);
  if (!sheen && p.clearcoat.x <= 0.0f) return f;
  f *= sheenScaling(p, NdotV, NdotL);
  if (sheen && NdotL > 0.0f) {
    vec3 h = normalize(wo + wi);
    f += vec3(p.sheen) * (charlieD(dot(n, h), sheenAlphaFromRoughness(p.sheen.a)) * sheenVisibility(NdotL, NdotV));
  }
  if (p.clearcoat.x > 0.0f) {
    float cw = coatWeight(p, nc, wo);
    float coat = 0.0f;
    float cO = dot(nc, wo), cI = dot(nc, wi);
    if (p.clearcoat.y > 0.0f && cO > 0.0f && cI > 0.0f) {
      float a = max(p.clearcoat.y * p.clearcoat.y, kMinGgxAlpha);
      coat = ggxD(dot(nc, normalize(wo + wi)), a) * smithVisibility(cI, cO, a);
    }
    f = f * (1.0f - cw) + vec3(cw * coat);
  }
  return f;
}
// f(wo, wi) |n.wi|.
RADIANT_FN vec3 gltfBsdfCos(vec3 n, vec3 nc, vec3 wo, vec3 wi, RADIANT_IN(MaterialParams) p, float eta, float refractionScale) {
  return gltfBsdf(n, nc, wo, wi, p, eta, refractionScale) * abs(dot(n, wi));
}
RADIANT_FN vec3 gltfBsdfCos(vec3 n, vec3 nc, vec3 wo, vec3 wi, RADIANT_IN(MaterialParams) p, float eta) {
  return gltfBsdfCos(n, nc, wo, wi, p, eta, 1.0f / (eta * eta));
}
RADIANT_FN vec3 gltfBsdfCos(vec3 n, vec3 wo, vec3 wi, RADIANT_IN(MaterialParams) p, float eta) {
  return gltfBsdfCos(n, n, wo, wi, p, eta);
}
// The surface seen from outside (eta = ior), as every raster pass sees it.
RADIANT_FN vec3 gltfBrdfCos(vec3 n, vec3 wo, vec3 wi, RADIANT_IN(MaterialParams) p) { return gltfBsdfCos(n, wo, wi, p, p.surface.w); }

RADIANT_FN MaterialParams materialParams(vec3 baseColor, float metallic, float roughness, float transmission, float ior) {
  MaterialParams p;
  p.baseColor = vec4(baseColor, 1.0f);
  p.emission = vec4(0.0f, 0.0f, 0.0f, 1.0f);
  p.surface = vec4(metallic, roughness, transmission, ior);
  p.clearcoat = vec4(0.0f);
  p.sheen = vec4(0.0f, 0.0f, 0.0f, kMinSheenRoughness);
  p.specular = vec4(1.0f);
  return p;
}

// ---------------------------------------------------------------------------------------------------
// Sampling: sampleMaterial and pdfMaterial, so that the same random numbers give the same direction,
// weight, pdf and lobe flags in both languages.

// Orthonormal basis around n (Duff et al. 2017, "Building an Orthonormal Basis, Revisited"): the
// cosine-weighted lobes map u to a direction through it. For n = +z it is the identity, exactly.
struct ShadingBasis {
  vec3 t;
  vec3 b;
  vec3 n;
};
RADIANT_FN ShadingBasis shadingBasis(vec3 n) {
  float s = n.z >= 0.0f ? 1.0f : -1.0f;
  float a = -1.0f / (s + n.z);
  float bb = n.x * n.y * a;
  ShadingBasis f;
  f.t = vec3(1.0f + s * n.x * n.x * a, s * bb, -s * n.x);
  f.b = vec3(bb, s + n.y * n.y * a, -n.y);
  f.n = n;
  return f;
}
RADIANT_FN vec3 basisToLocal(RADIANT_IN(ShadingBasis) f, vec3 v) { return vec3(dot(v, f.t), dot(v, f.b), dot(v, f.n)); }
RADIANT_FN vec3 basisToWorld(RADIANT_IN(ShadingBasis) f, vec3 v) { return v.x * f.t + v.y * f.b + v.z * f.n; }

// Concentric square-to-disk map (Shirley and Chiu 1997) and Malley's method, p(w) = cos(theta) / pi.
RADIANT_FN vec2 sampleConcentricDisk(vec2 u) {
  vec2 o = 2.0f * u - 1.0f;
  if (o.x == 0.0f && o.y == 0.0f) return vec2(0.0f);
  float r, theta;
  if (abs(o.x) > abs(o.y)) {
    r = o.x;
    theta = (PI / 4.0f) * (o.y / o.x);
  } else {
    r = o.y;
    theta = PI / 2.0f - (PI / 4.0f) * (o.x / o.y);
  }
  return r * vec2(cos(theta), sin(theta));
}
RADIANT_FN vec3 sampleCosineHemisphere(vec2 u) {
  vec2 d = sampleConcentricDisk(u);
  return vec3(d.x, d.y, sqrt(max(0.0f, 1.0f - d.x * d.x - d.y * d.y)));
}
RADIANT_FN float cosineHemispherePdf(float cosTheta) { return max(cosTheta, 0.0f) * INV_PI; }

// Heitz 2018, "Sampling the GGX Distribution of Visible Normals", listing 1 (isotropic), in the local
// frame of the lobe's normal: h distributed as D_wo(h) = G1(wo) max(0, wo.h) D(h) / wo.z.
RADIANT_FN vec3 sampleGgxVndf(vec3 wo, float alpha, vec2 u) {
  vec3 vh = normalize(vec3(alpha * wo.x, alpha * wo.y, wo.z));
  float lensq = vh.x * vh.x + vh.y * vh.y;
  vec3 t1 = lensq > 0.0f ? vec3(-vh.y, vh.x, 0.0f) / sqrt(lensq) : vec3(1.0f, 0.0f, 0.0f);
  vec3 t2 = cross(vh, t1);
  float r = sqrt(u.x);
  float phi = 2.0f * PI * u.y;
  float p1 = r * cos(phi);
  float p2 = r * sin(phi);
  float s = 0.5f * (1.0f + vh.z);
  p2 = (1.0f - s) * sqrt(max(0.0f, 1.0f - p1 * p1)) + s * p2;
  vec3 nh = p1 * t1 + p2 * t2 + sqrt(max(0.0f, 1.0f - p1 * p1 - p2 * p2)) * vh;
  return normalize(vec3(alpha * nh.x, alpha * nh.y, max(1e-7f, nh.z)));
}
// Heitz 2018, eq. 3, with the cosines to the lobe's normal m.
RADIANT_FN float ggxVndfPdf(vec3 m, vec3 wo, vec3 h, float alpha) {
  float cO = dot(m, wo);
  if (cO <= 0.0f) return 0.0f;
  return smithG1(cO, alpha) * max(0.0f, dot(wo, h)) * ggxD(dot(m, h), alpha) / cO;
}
// wi = reflect(-wo, h): D_wo(h) / (4 |wo.h|) (the Jacobian of the reflection).
RADIANT_FN float ggxReflectionPdf(vec3 m, vec3 wo, vec3 wi, float alpha) {
  if (dot(m, wo) <= 0.0f || dot(m, wi) <= 0.0f) return 0.0f;
  vec3 h = normalize(wo + wi);
  float voh = dot(wo, h);
  return voh > 0.0f ? ggxVndfPdf(m, wo, h, alpha) / (4.0f * voh) : 0.0f;
}
RADIANT_FN vec3 reflectAbout(vec3 wo, vec3 n) { return 2.0f * dot(wo, n) * n - wo; }
// Refraction of wo (pointing away, wo.n > 0) through normal n, eta = n_t / n_i; false on total
// internal reflection.
RADIANT_FN bool refractAbout(vec3 wo, vec3 n, float eta, RADIANT_OUT(vec3) wi) {
  float cosI = dot(wo, n);
  float sin2T = max(0.0f, 1.0f - cosI * cosI) / (eta * eta);
  wi = vec3(0.0f);
  if (sin2T >= 1.0f) return false;
  float cosT = sqrt(max(0.0f, 1.0f - sin2T));
  wi = -wo / eta + (cosI / eta - cosT) * n;
  return true;
}

// Lobe selection probabilities at wo: the coat, the sheen, reflection (metal + opaque dielectric
// specular), diffuse, and the transmissive dielectric (its reflection and refraction), each
// proportional to its albedo estimated with the Fresnel factor at n.wo.
struct LobeProbabilities {
  float reflect;
  float diffuse;
  float dielectric;
  float coat;
  float sheen;
};
RADIANT_FN LobeProbabilities lobeProbabilities(vec3 n, vec3 nc, vec3 wo, RADIANT_IN(MaterialParams) p, float eta) {
  float m = p.surface.x, t = p.surface.z, cO = dot(n, wo);
  vec3 base = vec3(p.baseColor);
  vec3 fd = schlickFresnel(specularF0(p), cO);
  float fe = fresnelDielectric(cO, eta);
  float lumBase = max(materialLuminance(base), 0.0f);
  float cw = coatWeight(p, nc, wo);
  float sheenE = materialHasSheen(p) ? maxComponent(vec3(p.sheen)) * sheenAlbedo(cO, p.sheen.a) : 0.0f;
  float below = (1.0f - cw) * max(0.0f, 1.0f - sheenE);
  LobeProbabilities l;
  l.reflect = below * (m * materialLuminance(schlickFresnel(base, cO)) +
                       (1.0f - m) * (1.0f - t) * p.specular.a * materialLuminance(fd));
  l.diffuse = below * (1.0f - m) * (1.0f - t) * (1.0f - p.specular.a * maxComponent(fd)) * lumBase;
  l.dielectric = below * (1.0f - m) * t * (fe + (1.0f - fe) * lumBase);
  l.coat = cw;
  l.sheen = (1.0f - cw) * sheenE;
  float sum = l.reflect + l.diffuse + l.dielectric + l.coat + l.sheen;
  if (!(sum > 0.0f)) {
    l.reflect = 1.0f;
    l.diffuse = 0.0f;
    l.dielectric = 0.0f;
    l.coat = 0.0f;
    l.sheen = 0.0f;
    return l;
  }
  l.reflect /= sum;
  l.diffuse /= sum;
  l.dielectric /= sum;
  l.coat /= sum;
  l.sheen /= sum;
  return l;
}

// Solid-angle pdf with which sampleMaterial produces wi from the non-delta lobes.
RADIANT_FN float pdfMaterial(vec3 n, vec3 nc, vec3 wo, vec3 wi, RADIANT_IN(MaterialParams) p, float eta) {
  float cO = dot(n, wo), cI = dot(n, wi);
  if (cO <= 0.0f || cI == 0.0f) return 0.0f;
  LobeProbabilities l = lobeProbabilities(n, nc, wo, p, eta);
  bool delta = p.surface.y <= 0.0f;
  float alpha = max(p.surface.y * p.surface.y, kMinGgxAlpha);
  if (cI > 0.0f) {
    float pdf = (l.diffuse + l.sheen) * cosineHemispherePdf(cI);
    if (l.coat > 0.0f && p.clearcoat.y > 0.0f)
      pdf += l.coat * ggxReflectionPdf(nc, wo, wi, max(p.clearcoat.y * p.clearcoat.y, kMinGgxAlpha));
    if (!delta) {
      float pr = ggxReflectionPdf(n, wo, wi, alpha);
      vec3 h = normalize(wo + wi);
      pdf += l.reflect * pr + l.dielectric * fresnelDielectric(dot(wo, h), eta) * pr;
    }
    return pdf;
  }
  if (delta || l.dielectric <= 0.0f) return 0.0f;
  vec3 h = eta * wi + wo;
  if (dot(h, h) == 0.0f) return 0.0f;
  h = normalize(h);
  if (dot(n, h) < 0.0f) h = -h;
  float woh = dot(wo, h), wih = dot(wi, h);
  if (woh <= 0.0f || wih >= 0.0f) return 0.0f;
  float s = wih + woh / eta;
  float dhdwi = abs(wih) / (s * s);  // Walter et al. 2007, eq. 17 for h = normalise(eta wi + wo)
  return l.dielectric * (1.0f - fresnelDielectric(woh, eta)) * ggxVndfPdf(n, wo, h, alpha) * dhdwi;
}

struct MaterialSample {
  vec3 wi;
  vec3 weight;  // f |n.wi| / pdf (deltas: the lobe's reflectance over its selection probability)
  float pdf;    // solid-angle pdf of the non-delta mixture; 0 for a delta sample
  int flags;    // kLobe* of the lobe that produced wi
  bool delta;
  bool valid;
};

// u.x picks the lobe, u.y reflection or refraction in the dielectric lobe, u.zw the direction.
// importance: the path carries importance (photons, light paths: no 1 / eta^2 on refraction).
RADIANT_FN MaterialSample sampleMaterial(vec3 n, vec3 nc, vec3 wo, RADIANT_IN(MaterialParams) p, float eta, bool importance, vec4 u) {
  MaterialSample s;
  s.wi = vec3(0.0f);
  s.weight = vec3(0.0f);
  s.pdf = 0.0f;
  s.flags = 0;
  s.delta = false;
  s.valid = false;
  if (dot(n, wo) <= 0.0f) return s;
  ShadingBasis f = shadingBasis(n);
  vec3 woL = basisToLocal(f, wo);
  vec2 uDir = vec2(u.z, u.w);
  LobeProbabilities l = lobeProbabilities(n, nc, wo, p, eta);
  float m = p.surface.x, t = p.surface.z;
  bool delta = p.surface.y <= 0.0f;
  float alpha = max(p.surface.y * p.surface.y, kMinGgxAlpha);
  float refractionScale = importance ? 1.0f : 1.0f / (eta * eta);
  float uLobe = u.x;
  vec3 wi = vec3(0.0f);
  if (uLobe < l.coat) {
    if (p.clearcoat.y <= 0.0f) {
      s.wi = reflectAbout(wo, nc);
      if (dot(n, s.wi) <= 0.0f) return s;
      s.weight = vec3(coatWeight(p, nc, wo) / l.coat);
      s.flags = kLobeReflection | kLobeSpecular;
      s.delta = true;
      s.valid = true;
      return s;
    }
    ShadingBasis cf = shadingBasis(nc);
    vec3 woC = basisToLocal(cf, wo);
    if (woC.z <= 0.0f) return s;
    vec3 h = sampleGgxVndf(woC, max(p.clearcoat.y * p.clearcoat.y, kMinGgxAlpha), uDir);
    wi = basisToWorld(cf, reflectAbout(woC, h));
    if (dot(n, wi) <= 0.0f) return s;
    s.flags = kLobeReflection | kLobeGlossy;
  } else if (uLobe < l.coat + l.sheen) {
    wi = basisToWorld(f, sampleCosineHemisphere(uDir));
    if (dot(n, wi) <= 0.0f) return s;
    s.flags = kLobeReflection | kLobeGlossy;
  } else if ((uLobe -= l.coat + l.sheen) < l.reflect) {
    if (delta) {
      s.wi = reflectAbout(wo, n);
      float cO = dot(n, wo);
      vec3 fr = m * schlickFresnel(vec3(p.baseColor), cO) +
                (1.0f - m) * (1.0f - t) * p.specular.a * schlickFresnel(specularF0(p), cO);
      // times what the layers above leave of the base: (1 - coat weight) x sheen scaling
      s.weight = fr * ((1.0f - coatWeight(p, nc, wo)) * sheenScaling(p, cO, dot(n, s.wi))) / l.reflect;
      s.flags = kLobeReflection | kLobeSpecular;
      s.delta = true;
      s.valid = true;
      return s;
    }
    vec3 h = basisToWorld(f, sampleGgxVndf(woL, alpha, uDir));
    wi = reflectAbout(wo, h);
    if (dot(n, wi) <= 0.0f) return s;
    s.flags = kLobeReflection | kLobeGlossy;
  } else if (uLobe < l.reflect + l.diffuse) {
    wi = basisToWorld(f, sampleCosineHemisphere(uDir));
    if (dot(n, wi) <= 0.0f) return s;
    s.flags = kLobeReflection | kLobeDiffuse;
  } else {
    vec3 h = delta ? n : basisToWorld(f, sampleGgxVndf(woL, alpha, uDir));
    float woh = dot(wo, h);
    if (woh <= 0.0f) return s;
    float fe = fresnelDielectric(woh, eta);
    bool reflected = u.y < fe;
    if (!reflected && !refractAbout(wo, h, eta, wi)) reflected = true;
    if (reflected) wi = reflectAbout(wo, h);
    int side = reflected ? kLobeReflection : kLobeTransmission;
    if (delta) {
      s.wi = wi;
      s.flags = side | kLobeSpecular;
      s.delta = true;
      // (1-m) t F or (1-m) t (1-F) base / eta^2 (radiance) over p.dielectric F or p.dielectric (1-F),
      // times what the layers above leave of it.
      vec3 lobe = reflected ? vec3((1.0f - m) * t / l.dielectric)
                            : (1.0f - m) * t * vec3(p.baseColor) * refractionScale / l.dielectric;
      s.weight = lobe * ((1.0f - coatWeight(p, nc, wo)) * sheenScaling(p, dot(n, wo), dot(n, wi)));
      s.valid = true;
      return s;
    }
    if (reflected ? dot(n, wi) <= 0.0f : dot(n, wi) >= 0.0f) return s;
    s.flags = side | kLobeGlossy;
  }
  s.wi = wi;
  s.pdf = pdfMaterial(n, nc, wo, wi, p, eta);
  if (!(s.pdf > 0.0f)) return s;
  s.weight = gltfBsdfCos(n, nc, wo, wi, p, eta, refractionScale) / s.pdf;
  s.valid = !any(isnan(s.weight)) && !any(isinf(s.weight));
  return s;
}
#endif
