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
// refractionScale: 1 / eta^2 when transporting radiance, 1 for importance (rt::TransportMode).
vec3 gltfBaseBsdfCos(vec3 n, vec3 wo, vec3 wi, MaterialParams p, float eta, float refractionScale) {
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
             abs(wih * woh) / denom * refractionScale;
  return (1.0 - m) * t * ft * base * abs(NdotL);
}
vec3 gltfBaseBsdfCos(vec3 n, vec3 wo, vec3 wi, MaterialParams p, float eta) {
  return gltfBaseBsdfCos(n, wo, wi, p, eta, 1.0 / (eta * eta));
}

// f(wo, wi) |n.wi| for the decoded material p with its layers (sheen over the base, the clear coat over
// both; rt::GltfBsdf::eval). n the shading normal, nc the coat's normal (the interpolated normal, not
// normal-mapped), wo, wi unit vectors, wo on n's side; wi below the surface is transmission.
// eta = n_(far side) / n_(wo side): ior seen from outside, 1 / ior inside.
vec3 gltfBsdfCos(vec3 n, vec3 nc, vec3 wo, vec3 wi, MaterialParams p, float eta, float refractionScale) {
  float NdotV = dot(n, wo);
  float NdotL = dot(n, wi);
  if (NdotV <= 0.0 || NdotL == 0.0) return vec3(0.0);
  vec3 f = gltfBaseBsdfCos(n, wo, wi, p, eta, refractionScale);
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
vec3 gltfBsdfCos(vec3 n, vec3 nc, vec3 wo, vec3 wi, MaterialParams p, float eta) {
  return gltfBsdfCos(n, nc, wo, wi, p, eta, 1.0 / (eta * eta));
}
vec3 gltfBsdfCos(vec3 n, vec3 wo, vec3 wi, MaterialParams p, float eta) { return gltfBsdfCos(n, n, wo, wi, p, eta); }

// The material's f(wo, wi) |n.wi| for a path carrying radiance (importance = false: camera paths) or
// importance (true: photons, light paths; no 1 / eta^2 on refraction). evalMaterial / pdfMaterial /
// sampleMaterial are the GLSL twins of rt::GltfBsdf::eval / pdf / sample, world-space here (n the
// shading normal, nc the coat's), in the shading frame there.
vec3 evalMaterial(vec3 n, vec3 nc, vec3 wo, vec3 wi, MaterialParams p, float eta, bool importance) {
  return gltfBsdfCos(n, nc, wo, wi, p, eta, importance ? 1.0 : 1.0 / (eta * eta));
}

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
// ---------------------------------------------------------------------------------------------------
// Sampling: rt::GltfBsdf::sample and ::pdf (renderer/raytracing/Bsdf.h), step for step, so that the same
// random numbers give the same direction, weight, pdf and lobe flags (tests/gl/materials/parity_test.cpp).

// Orthonormal basis around n (Duff et al. 2017; rt::ShadingFrame): the cosine-weighted lobes map u to a
// direction through it, so both languages build the same one.
struct ShadingBasis { vec3 t; vec3 b; vec3 n; };
ShadingBasis shadingBasis(vec3 n) {
  float s = n.z >= 0.0 ? 1.0 : -1.0;
  float a = -1.0 / (s + n.z);
  float bb = n.x * n.y * a;
  ShadingBasis f;
  f.t = vec3(1.0 + s * n.x * n.x * a, s * bb, -s * n.x);
  f.b = vec3(bb, s + n.y * n.y * a, -n.y);
  f.n = n;
  return f;
}
vec3 basisToLocal(ShadingBasis f, vec3 v) { return vec3(dot(v, f.t), dot(v, f.b), dot(v, f.n)); }
vec3 basisToWorld(ShadingBasis f, vec3 v) { return v.x * f.t + v.y * f.b + v.z * f.n; }

// Concentric square-to-disk map (Shirley and Chiu 1997) and Malley's method, p(w) = cos(theta) / pi.
vec2 sampleConcentricDisk(vec2 u) {
  vec2 o = 2.0 * u - 1.0;
  if (o.x == 0.0 && o.y == 0.0) return vec2(0.0);
  float r, theta;
  if (abs(o.x) > abs(o.y)) {
    r = o.x;
    theta = (PI / 4.0) * (o.y / o.x);
  } else {
    r = o.y;
    theta = PI / 2.0 - (PI / 4.0) * (o.x / o.y);
  }
  return r * vec2(cos(theta), sin(theta));
}
vec3 sampleCosineHemisphere(vec2 u) {
  vec2 d = sampleConcentricDisk(u);
  return vec3(d.x, d.y, sqrt(max(0.0, 1.0 - d.x * d.x - d.y * d.y)));
}
float cosineHemispherePdf(float cosTheta) { return max(cosTheta, 0.0) * INV_PI; }

// Heitz 2018, "Sampling the GGX Distribution of Visible Normals", listing 1 (isotropic), in the local
// frame of the lobe's normal: h distributed as D_wo(h) = G1(wo) max(0, wo.h) D(h) / wo.z.
vec3 sampleGgxVndf(vec3 wo, float alpha, vec2 u) {
  vec3 vh = normalize(vec3(alpha * wo.x, alpha * wo.y, wo.z));
  float lensq = vh.x * vh.x + vh.y * vh.y;
  vec3 t1 = lensq > 0.0 ? vec3(-vh.y, vh.x, 0.0) / sqrt(lensq) : vec3(1.0, 0.0, 0.0);
  vec3 t2 = cross(vh, t1);
  float r = sqrt(u.x);
  float phi = 2.0 * PI * u.y;
  float p1 = r * cos(phi);
  float p2 = r * sin(phi);
  float s = 0.5 * (1.0 + vh.z);
  p2 = (1.0 - s) * sqrt(max(0.0, 1.0 - p1 * p1)) + s * p2;
  vec3 nh = p1 * t1 + p2 * t2 + sqrt(max(0.0, 1.0 - p1 * p1 - p2 * p2)) * vh;
  return normalize(vec3(alpha * nh.x, alpha * nh.y, max(1e-7, nh.z)));
}
float smithG1(float cosTheta, float alpha) { return 1.0 / (1.0 + ggxLambda(cosTheta, alpha)); }
// Heitz 2018, eq. 3, with the cosines to the lobe's normal m.
float ggxVndfPdf(vec3 m, vec3 wo, vec3 h, float alpha) {
  float cO = dot(m, wo);
  if (cO <= 0.0) return 0.0;
  return smithG1(cO, alpha) * max(0.0, dot(wo, h)) * ggxD(dot(m, h), alpha) / cO;
}
// wi = reflect(-wo, h): D_wo(h) / (4 |wo.h|).
float ggxReflectionPdf(vec3 m, vec3 wo, vec3 wi, float alpha) {
  if (dot(m, wo) <= 0.0 || dot(m, wi) <= 0.0) return 0.0;
  vec3 h = normalize(wo + wi);
  float voh = dot(wo, h);
  return voh > 0.0 ? ggxVndfPdf(m, wo, h, alpha) / (4.0 * voh) : 0.0;
}
vec3 reflectAbout(vec3 wo, vec3 n) { return 2.0 * dot(wo, n) * n - wo; }
// Refraction of wo (pointing away, wo.n > 0) through normal n, eta = n_t / n_i; false on total
// internal reflection.
bool refractAbout(vec3 wo, vec3 n, float eta, out vec3 wi) {
  float cosI = dot(wo, n);
  float sin2T = max(0.0, 1.0 - cosI * cosI) / (eta * eta);
  wi = vec3(0.0);
  if (sin2T >= 1.0) return false;
  float cosT = sqrt(max(0.0, 1.0 - sin2T));
  wi = -wo / eta + (cosI / eta - cosT) * n;
  return true;
}
float materialLuminance(vec3 c) { return 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b; }

// rt::GltfBsdf::lobeProbabilities: coat, sheen, reflection (metal + opaque dielectric specular), diffuse,
// transmissive dielectric, each proportional to its albedo estimated with the Fresnel factor at n.wo.
struct LobeProbabilities { float reflect; float diffuse; float dielectric; float coat; float sheen; };
LobeProbabilities lobeProbabilities(vec3 n, vec3 nc, vec3 wo, MaterialParams p, float eta) {
  float m = p.surface.x, t = p.surface.z, cO = dot(n, wo);
  vec3 base = p.baseColor.rgb;
  vec3 fd = schlickFresnel(specularF0(p), cO);
  float fe = fresnelDielectric(cO, eta);
  float lumBase = max(materialLuminance(base), 0.0);
  float cw = coatWeight(p, nc, wo);
  float sheenE = materialHasSheen(p) ? maxComponent(p.sheen.rgb) * sheenAlbedo(cO, p.sheen.a) : 0.0;
  float below = (1.0 - cw) * max(0.0, 1.0 - sheenE);
  LobeProbabilities l;
  l.reflect = below * (m * materialLuminance(schlickFresnel(base, cO)) +
                       (1.0 - m) * (1.0 - t) * p.specular.a * materialLuminance(fd));
  l.diffuse = below * (1.0 - m) * (1.0 - t) * (1.0 - p.specular.a * maxComponent(fd)) * lumBase;
  l.dielectric = below * (1.0 - m) * t * (fe + (1.0 - fe) * lumBase);
  l.coat = cw;
  l.sheen = (1.0 - cw) * sheenE;
  float sum = l.reflect + l.diffuse + l.dielectric + l.coat + l.sheen;
  if (!(sum > 0.0)) return LobeProbabilities(1.0, 0.0, 0.0, 0.0, 0.0);
  l.reflect /= sum;
  l.diffuse /= sum;
  l.dielectric /= sum;
  l.coat /= sum;
  l.sheen /= sum;
  return l;
}

// Solid-angle pdf with which sampleMaterial produces wi from the non-delta lobes (rt::GltfBsdf::pdf).
float pdfMaterial(vec3 n, vec3 nc, vec3 wo, vec3 wi, MaterialParams p, float eta) {
  float cO = dot(n, wo), cI = dot(n, wi);
  if (cO <= 0.0 || cI == 0.0) return 0.0;
  LobeProbabilities l = lobeProbabilities(n, nc, wo, p, eta);
  bool delta = p.surface.y <= 0.0;
  float alpha = max(p.surface.y * p.surface.y, kMinGgxAlpha);
  if (cI > 0.0) {
    float pdf = (l.diffuse + l.sheen) * cosineHemispherePdf(cI);
    if (l.coat > 0.0 && p.clearcoat.y > 0.0)
      pdf += l.coat * ggxReflectionPdf(nc, wo, wi, max(p.clearcoat.y * p.clearcoat.y, kMinGgxAlpha));
    if (!delta) {
      float pr = ggxReflectionPdf(n, wo, wi, alpha);
      vec3 h = normalize(wo + wi);
      pdf += l.reflect * pr + l.dielectric * fresnelDielectric(dot(wo, h), eta) * pr;
    }
    return pdf;
  }
  if (delta || l.dielectric <= 0.0) return 0.0;
  vec3 h = eta * wi + wo;
  if (dot(h, h) == 0.0) return 0.0;
  h = normalize(h);
  if (dot(n, h) < 0.0) h = -h;
  float woh = dot(wo, h), wih = dot(wi, h);
  if (woh <= 0.0 || wih >= 0.0) return 0.0;
  float s = wih + woh / eta;
  float dhdwi = abs(wih) / (s * s);  // Walter et al. 2007, eq. 17 for h = normalise(eta wi + wo)
  return l.dielectric * (1.0 - fresnelDielectric(woh, eta)) * ggxVndfPdf(n, wo, h, alpha) * dhdwi;
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
MaterialSample sampleMaterial(vec3 n, vec3 nc, vec3 wo, MaterialParams p, float eta, bool importance, vec4 u) {
  MaterialSample s = MaterialSample(vec3(0.0), vec3(0.0), 0.0, 0, false, false);
  if (dot(n, wo) <= 0.0) return s;
  ShadingBasis f = shadingBasis(n);
  vec3 woL = basisToLocal(f, wo);
  LobeProbabilities l = lobeProbabilities(n, nc, wo, p, eta);
  float m = p.surface.x, t = p.surface.z;
  bool delta = p.surface.y <= 0.0;
  float alpha = max(p.surface.y * p.surface.y, kMinGgxAlpha);
  float refractionScale = importance ? 1.0 : 1.0 / (eta * eta);
  float uLobe = u.x;
  vec3 wi;
  if (uLobe < l.coat) {
    if (p.clearcoat.y <= 0.0) {
      s.wi = reflectAbout(wo, nc);
      if (dot(n, s.wi) <= 0.0) return s;
      s.weight = vec3(coatWeight(p, nc, wo) / l.coat);
      s.flags = kLobeReflection | kLobeSpecular;
      s.delta = true;
      s.valid = true;
      return s;
    }
    ShadingBasis cf = shadingBasis(nc);
    vec3 woC = basisToLocal(cf, wo);
    if (woC.z <= 0.0) return s;
    vec3 h = sampleGgxVndf(woC, max(p.clearcoat.y * p.clearcoat.y, kMinGgxAlpha), u.zw);
    wi = basisToWorld(cf, reflectAbout(woC, h));
    if (dot(n, wi) <= 0.0) return s;
    s.flags = kLobeReflection | kLobeGlossy;
  } else if (uLobe < l.coat + l.sheen) {
    wi = basisToWorld(f, sampleCosineHemisphere(u.zw));
    if (dot(n, wi) <= 0.0) return s;
    s.flags = kLobeReflection | kLobeGlossy;
  } else if ((uLobe -= l.coat + l.sheen) < l.reflect) {
    if (delta) {
      s.wi = reflectAbout(wo, n);
      float cO = dot(n, wo);
      vec3 fr = m * schlickFresnel(p.baseColor.rgb, cO) + (1.0 - m) * (1.0 - t) * p.specular.a * schlickFresnel(specularF0(p), cO);
      s.weight = fr * (1.0 - coatWeight(p, nc, wo)) * sheenScaling(p, cO, dot(n, s.wi)) / l.reflect;
      s.flags = kLobeReflection | kLobeSpecular;
      s.delta = true;
      s.valid = true;
      return s;
    }
    vec3 h = basisToWorld(f, sampleGgxVndf(woL, alpha, u.zw));
    wi = reflectAbout(wo, h);
    if (dot(n, wi) <= 0.0) return s;
    s.flags = kLobeReflection | kLobeGlossy;
  } else if (uLobe < l.reflect + l.diffuse) {
    wi = basisToWorld(f, sampleCosineHemisphere(u.zw));
    if (dot(n, wi) <= 0.0) return s;
    s.flags = kLobeReflection | kLobeDiffuse;
  } else {
    vec3 h = delta ? n : basisToWorld(f, sampleGgxVndf(woL, alpha, u.zw));
    float woh = dot(wo, h);
    if (woh <= 0.0) return s;
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
      vec3 lobe = reflected ? vec3((1.0 - m) * t / l.dielectric) : (1.0 - m) * t * p.baseColor.rgb * refractionScale / l.dielectric;
      s.weight = lobe * (1.0 - coatWeight(p, nc, wo)) * sheenScaling(p, dot(n, wo), dot(n, wi));
      s.valid = true;
      return s;
    }
    if (reflected ? dot(n, wi) <= 0.0 : dot(n, wi) >= 0.0) return s;
    s.flags = side | kLobeGlossy;
  }
  s.wi = wi;
  s.pdf = pdfMaterial(n, nc, wo, wi, p, eta);
  if (!(s.pdf > 0.0)) return s;
  s.weight = gltfBsdfCos(n, nc, wo, wi, p, eta, refractionScale) / s.pdf;
  s.valid = !any(isnan(s.weight)) && !any(isinf(s.weight));
  return s;
}
#endif
