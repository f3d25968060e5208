// The glTF 2.0 metallic-roughness BRDF, spec Appendix B, with KHR_materials_ior (dielectric F0 from
// ior) and KHR_materials_transmission (the diffuse lobe is replaced by transmission, which a punctual
// light cannot reach through a smooth surface, so it contributes nothing to direct light).
// The CPU reference (renderer/reference/Brdf.h) implements the same equations.
#ifndef RADIANT_COMMON_BRDF
#define RADIANT_COMMON_BRDF
#include "common/constants.glsl"

// alpha = roughness^2, clamped so a roughness-0 surface stays finite under a punctual light.
const float MIN_ALPHA = 2e-3;

float ggxD(float NdotH, float alpha) {
  float a2 = alpha * alpha;
  float d = NdotH * NdotH * (a2 - 1.0) + 1.0;
  return a2 / (PI * d * d);
}

// Height-correlated Smith visibility V = G / (4 NdotL NdotV) (spec Appendix B, "Specular BRDF").
float smithVisibility(float NdotL, float NdotV, float alpha) {
  float a2 = alpha * alpha;
  float gv = NdotL * sqrt(NdotV * NdotV * (1.0 - a2) + a2);
  float gl = NdotV * sqrt(NdotL * NdotL * (1.0 - a2) + a2);
  float s = gv + gl;
  return s > 0.0 ? 0.5 / s : 0.0;
}

vec3 schlickFresnel(vec3 f0, float VdotH) {
  float m = clamp(1.0 - VdotH, 0.0, 1.0);
  float m2 = m * m;
  return f0 + (1.0 - f0) * (m2 * m2 * m);
}

// f(wi, wo) * cos(theta_i) for the glTF material. n, wo, wi unit vectors.
vec3 gltfBrdfCos(vec3 n, vec3 wo, vec3 wi, vec3 baseColor, float metallic, float roughness,
                 float transmission, float ior) {
  float NdotL = dot(n, wi);
  float NdotV = dot(n, wo);
  if (NdotL <= 0.0 || NdotV <= 0.0) return vec3(0.0);
  vec3 h = normalize(wi + wo);
  float NdotH = max(dot(n, h), 0.0);
  float VdotH = max(dot(wo, h), 0.0);
  float alpha = max(roughness * roughness, MIN_ALPHA);
  float specular = ggxD(NdotH, alpha) * smithVisibility(NdotL, NdotV, alpha);
  float r = (ior - 1.0) / (ior + 1.0);
  float f0Dielectric = r * r;
  // fresnel_mix(ior, base, layer) = mix(base, layer, F_schlick(f0(ior), VdotH))
  float fd = schlickFresnel(vec3(f0Dielectric), VdotH).x;
  vec3 diffuse = baseColor * INV_PI * (1.0 - transmission);
  vec3 dielectric = mix(diffuse, vec3(specular), fd);
  // conductor_fresnel(f0 = baseColor, bsdf = specular)
  vec3 metal = specular * schlickFresnel(baseColor, VdotH);
  return mix(dielectric, metal, metallic) * NdotL;
}
#endif
