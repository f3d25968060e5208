// Image-based lighting, split-sum (Karis 2013) and SH irradiance (Ramamoorthi and Hanrahan 2001):
// the GLSL half of renderer/shading/ImageBasedLighting.h, which documents the equations.
#ifndef RADIANT_COMMON_IBL
#define RADIANT_COMMON_IBL
#include "common/constants.glsl"

#define IBL_NONE 0
#define IBL_UNIFORM 1
#define IBL_MAP 2
#define IBL_DFG_SIZE 32.0
#define IBL_LEVELS 6.0

uniform int u_iblMode;
uniform vec3 u_iblUniform;  // the uniform sky radiance (IBL_UNIFORM)
uniform vec3 u_sh[9];       // irradiance SH, A_l folded in: E(n) = sum u_sh[i] Y_i(n)

// (A, B, Dp) at (mu = n.v, roughness): columns at mu = (i + 0.5) / 32, rows at roughness j / 31.
vec3 iblDfg(sampler2D dfg, float mu, float roughness) {
  vec2 uv = vec2(clamp(mu, 0.0, 1.0), (clamp(roughness, 0.0, 1.0) * (IBL_DFG_SIZE - 1.0) + 0.5) / IBL_DFG_SIZE);
  return texture(dfg, uv).rgb;
}

// GGX-prefiltered radiance around direction r for `roughness` (levels k / 5, blended linearly).
vec3 iblPrefiltered(sampler2DArray map, vec3 r, float roughness) {
  if (u_iblMode == IBL_UNIFORM) return u_iblUniform;
  if (u_iblMode != IBL_MAP) return vec3(0.0);
  vec2 uv = vec2(0.5 + atan(r.x, -r.z) / (2.0 * PI), acos(clamp(r.y, -1.0, 1.0)) / PI);
  float level = clamp(roughness, 0.0, 1.0) * (IBL_LEVELS - 1.0);
  float l0 = floor(level);
  vec3 a = texture(map, vec3(uv, l0)).rgb;
  vec3 b = texture(map, vec3(uv, min(l0 + 1.0, IBL_LEVELS - 1.0))).rgb;
  return mix(a, b, level - l0);
}

vec3 iblIrradiance(vec3 n) {
  vec3 e = u_sh[0] * 0.282095
         + u_sh[1] * (0.488603 * n.y) + u_sh[2] * (0.488603 * n.z) + u_sh[3] * (0.488603 * n.x)
         + u_sh[4] * (1.092548 * n.x * n.y) + u_sh[5] * (1.092548 * n.y * n.z)
         + u_sh[6] * (0.315392 * (3.0 * n.z * n.z - 1.0)) + u_sh[7] * (1.092548 * n.x * n.z)
         + u_sh[8] * (0.546274 * (n.x * n.x - n.y * n.y));
  return max(e, vec3(0.0));
}

float iblF0Dielectric(float ior) {
  float r = (ior - 1.0) / (ior + 1.0);
  return r * r;
}

// Split-sum specular of the glTF BRDF: Lpre(R) [(1 - m)(f0 A + B) + m (baseColor A + B)].
vec3 iblSpecular(sampler2D dfg, sampler2DArray map, vec3 n, vec3 wo, vec3 baseColor, float metallic,
                 float roughness, float ior) {
  float mu = max(dot(n, wo), 0.0);
  vec3 ab = iblDfg(dfg, mu, roughness);
  vec3 r = reflect(-wo, n);
  vec3 scale = (1.0 - metallic) * vec3(iblF0Dielectric(ior) * ab.x + ab.y) + metallic * (baseColor * ab.x + ab.y);
  return iblPrefiltered(map, r, roughness) * scale;
}

#ifdef RADIANT_COMMON_BRDF
// The split-sum of the whole layered material (common/brdf.glsl's gltfBsdfCos): the base's specular
// with KHR_materials_specular's F0 = min(F0(ior) specularColor, 1) and weight w, under the sheen and the
// clear coat; the sheen's reflection of the irradiance, c E(mu) E(n) / pi (exact for a uniform sky); the
// coat's own lobe, Lpre(R_c, r_c) cw (A_c + B_c) (its layer is D V with the Fresnel in the mix weight cw).
// The base's attenuation by the layers is taken at mu: (1 - cw(wo)) (1 - max3(c) E(mu)).
vec3 iblSpecular(sampler2D dfg, sampler2DArray map, vec3 n, vec3 nc, vec3 wo, MaterialParams p) {
  float mu = max(dot(n, wo), 0.0);
  float m = p.surface.x, roughness = p.surface.y;
  vec3 ab = iblDfg(dfg, mu, roughness);
  vec3 r = reflect(-wo, n);
  vec3 scale = (1.0 - m) * p.specular.a * (specularF0(p) * ab.x + ab.y) + m * (p.baseColor.rgb * ab.x + ab.y);
  vec3 L = iblPrefiltered(map, r, roughness) * scale;
  if (materialHasSheen(p)) {
    float e = sheenAlbedo(mu, p.sheen.a);
    L = L * max(0.0, 1.0 - maxComponent(p.sheen.rgb) * e) + p.sheen.rgb * e * iblIrradiance(n) * INV_PI;
  }
  if (p.clearcoat.x > 0.0) {
    float cw = coatWeight(p, nc, wo);
    vec3 abc = iblDfg(dfg, max(dot(nc, wo), 0.0), p.clearcoat.y);
    L = L * (1.0 - cw) + cw * (abc.x + abc.y) * iblPrefiltered(map, reflect(-wo, nc), p.clearcoat.y);
  }
  return L;
}

// The diffuse base's weight under the layers, as the layered iblSpecular attenuates the base: glTF's
// fresnel_mix with KHR_materials_specular's F0 and weight, 1 - w max3(F0s + (1 - F0s) Dp(mu)) (the
// plain iblDiffuseWeight's (1 - f0)(1 - Dp) when w = 1 and F0s = f0 grey), times (1 - max3(c) E(mu))
// under the sheen and (1 - cw(wo)) under the clear coat. The base's (1 - metallic)(1 - transmission)
// and its colour are the caller's.
float iblDiffuseWeight(sampler2D dfg, vec3 nc, vec3 wo, float mu, MaterialParams p) {
  vec3 f0 = specularF0(p);
  float w = 1.0 - p.specular.a * maxComponent(f0 + (1.0 - f0) * iblDfg(dfg, mu, 1.0).z);
  if (materialHasSheen(p)) w *= max(0.0, 1.0 - maxComponent(p.sheen.rgb) * sheenAlbedo(mu, p.sheen.a));
  if (p.clearcoat.x > 0.0) w *= 1.0 - coatWeight(p, nc, wo);
  return w;
}
#endif

// The diffuse weight glTF's fresnel_mix leaves the base: (1 - f0)(1 - Dp(mu)).
float iblDiffuseWeight(sampler2D dfg, float mu, float ior) {
  return (1.0 - iblF0Dielectric(ior)) * (1.0 - iblDfg(dfg, mu, 1.0).z);
}
#endif
