// The glTF material at a surface point: factors x texture channels as the specs define them, clamped
// to their ranges, as the MaterialParams record the BSDF reads (common/shared.h). The one definition
// for GLSL and C++ (the common/brdf.glsl approach; its rules hold here):
//   GLSL: common/material.glsl includes this file after defining MaterialSite (= SurfaceUv, the point's
//         uv sets and derivatives) and materialTexel() over its samplers; every pass that shades scene
//         geometry calls it (gbuffer, env_diffuse cube maps, specular distance maps, caustics, ...).
//   C++:  renderer/scene/MaterialDecode.h includes it inside namespace radiant::material_glsl with its
//         own MaterialSite (a texel callback: bilinear on the CPU, RayScene::textureAt) for the
//         ray-tracing core (RayScene::shade, emissionAt, the alpha test).
// What stays per language is how a texel is fetched: materialTexel(m, slot, set, site) returns texture
// slot `slot` (gpu::kSlot*) read through uv set `set` at the point, with the slot's
// KHR_texture_transform applied and sRGB colour decoded (the texture formats on the GPU,
// materialSlotIsSrgb on the CPU). It is called only for slots the material has (set >= 0).
// tests/gl/materials/parity_test.cpp checks the two compilers of this file against each other.
#ifndef RADIANT_COMMON_MATERIAL_DECODE
#define RADIANT_COMMON_MATERIAL_DECODE
#ifndef __cplusplus
#include "common/dual.glsl"
#include "common/shared.h"
#endif

// baseColorFactor x baseColorTexture, rgb and alpha. Unclamped: the alpha test reads it before the
// rest is decoded.
RADIANT_FN vec4 decodeBaseColor(RADIANT_IN(Material) m, RADIANT_IN(MaterialSite) site) {
  vec4 base = m.baseColorFactor;
  if (m.texturesA.x >= 0) base *= materialTexel(m, kSlotBaseColor, m.texturesA.x, site);
  return base;
}

// KHR_materials_unlit: the radiance leaving an unlit surface is its base colour, clamped as
// MaterialParams::baseColor (the G-buffer stores decodeMaterial's baseColor as its emission).
RADIANT_FN vec3 decodeUnlitRadiance(RADIANT_IN(Material) m, RADIANT_IN(MaterialSite) site) {
  return clamp(vec3(decodeBaseColor(m, site)), 0.0f, 1.0f);
}

// emissiveFactor x emissiveStrength x emissiveTexture.
RADIANT_FN vec3 decodeEmission(RADIANT_IN(Material) m, RADIANT_IN(MaterialSite) site) {
  vec3 e = vec3(m.emission);
  if (m.texturesB.x >= 0) e *= vec3(materialTexel(m, kSlotEmissive, m.texturesB.x, site));
  return e;
}

// The layered extensions, each as its MaterialParams member. KHR_materials_clearcoat: clearcoat = red
// of clearcoatTexture, coat roughness = green of clearcoatRoughnessTexture.
RADIANT_FN vec4 decodeClearcoat(RADIANT_IN(Material) m, RADIANT_IN(MaterialSite) site) {
  float coat = m.clearcoat.x;
  float coatRoughness = m.clearcoat.y;
  if (m.texturesC.x >= 0) coat *= materialTexel(m, kSlotClearcoat, m.texturesC.x, site).x;
  if (m.texturesC.y >= 0) coatRoughness *= materialTexel(m, kSlotClearcoatRoughness, m.texturesC.y, site).y;
  return vec4(clamp(coat, 0.0f, 1.0f), clamp(coatRoughness, 0.0f, 1.0f), 0.0f, 0.0f);
}
// KHR_materials_sheen: colour = rgb of sheenColorTexture (sRGB), roughness = alpha of
// sheenRoughnessTexture; the roughness is clamped to [kMinSheenRoughness, 1] (common/shared.h).
RADIANT_FN vec4 decodeSheen(RADIANT_IN(Material) m, RADIANT_IN(MaterialSite) site) {
  vec3 sheenColor = vec3(m.sheen);
  float sheenRoughness = m.sheen.w;
  if (m.texturesC.w >= 0) sheenColor *= vec3(materialTexel(m, kSlotSheenColor, m.texturesC.w, site));
  if (m.texturesD.x >= 0) sheenRoughness *= materialTexel(m, kSlotSheenRoughness, m.texturesD.x, site).w;
  return vec4(clamp(sheenColor, 0.0f, 1.0f), clamp(sheenRoughness, kMinSheenRoughness, 1.0f));
}
// KHR_materials_specular: weight = alpha of specularTexture, colour = rgb of specularColorTexture (sRGB).
RADIANT_FN vec4 decodeSpecular(RADIANT_IN(Material) m, RADIANT_IN(MaterialSite) site) {
  vec3 specularColor = vec3(m.specular);
  float specular = m.specular.w;
  if (m.texturesD.y >= 0) specular *= materialTexel(m, kSlotSpecular, m.texturesD.y, site).w;
  if (m.texturesD.z >= 0) specularColor *= vec3(materialTexel(m, kSlotSpecularColor, m.texturesD.z, site));
  return vec4(max(specularColor, vec3(0.0f)), clamp(specular, 0.0f, 1.0f));
}

// What the BSDF reads (baseColor, surface, the layers), without the emission and occlusion lookups:
// the ray tracer's shade() needs only these; emission is (0, 0, 0, 1). glTF 3.9.2: metallic is the
// blue, roughness the green channel of metallicRoughnessTexture; KHR_materials_transmission reads the
// red channel of transmissionTexture; KHR_materials_ior: kDefaultIor when the material gives none.
RADIANT_FN MaterialParams decodeBsdfInputs(RADIANT_IN(Material) m, RADIANT_IN(MaterialSite) site) {
  vec4 base = decodeBaseColor(m, site);
  float metallic = m.metallicRoughness.x;
  float roughness = m.metallicRoughness.y;
  if (m.texturesA.y >= 0) {
    vec4 mr = materialTexel(m, kSlotMetallicRoughness, m.texturesA.y, site);
    roughness *= mr.y;
    metallic *= mr.z;
  }
  float transmission = m.metallicRoughness.z;
  if (m.texturesB.z >= 0) transmission *= materialTexel(m, kSlotTransmission, m.texturesB.z, site).x;
  float ior = m.metallicRoughness.w > 0.0f ? m.metallicRoughness.w : kDefaultIor;
  MaterialParams p;
  p.baseColor = vec4(clamp(vec3(base), 0.0f, 1.0f), base.w);
  p.emission = vec4(0.0f, 0.0f, 0.0f, 1.0f);
  p.surface = vec4(clamp(metallic, 0.0f, 1.0f), clamp(roughness, 0.0f, 1.0f), clamp(transmission, 0.0f, 1.0f), ior);
  p.clearcoat = decodeClearcoat(m, site);
  p.sheen = decodeSheen(m, site);
  p.specular = decodeSpecular(m, site);
  return p;
}

// The whole material at a point: the BSDF inputs, the emission, and the ambient occlusion
// 1 + strength (texel.r - 1) (glTF 3.9.3) in emission.a.
RADIANT_FN MaterialParams decodeMaterial(RADIANT_IN(Material) m, RADIANT_IN(MaterialSite) site) {
  MaterialParams p = decodeBsdfInputs(m, site);
  float occlusion = 1.0f;
  if (m.texturesA.w >= 0)
    occlusion = 1.0f + m.scales.y * (materialTexel(m, kSlotOcclusion, m.texturesA.w, site).x - 1.0f);
  p.emission = vec4(decodeEmission(m, site), occlusion);
  return p;
}

// A tangent-space normal map's texel (2 texel - 1, xy times `scale`) in the frame of the interpolated
// normal n (unit) and tangent (xyz, w handedness), glTF 3.9.3. Returns n where the tangent is
// parallel to n (no frame: the map is not applied) or the mapped normal vanishes.
RADIANT_FN vec3 mapTangentNormal(vec4 texel, float scale, vec3 n, vec4 tangent) {
  vec3 t = vec3(tangent) - n * dot(n, vec3(tangent));
  float t2 = dot(t, t);
  if (!(t2 > 1e-30f)) return n;
  t = t * inversesqrt(t2);
  vec3 b = cross(n, t) * (tangent.w < 0.0f ? -1.0f : 1.0f);
  vec3 tn = vec3(texel) * 2.0f - 1.0f;
  vec3 mapped = t * (tn.x * scale) + b * (tn.y * scale) + n * tn.z;
  float m2 = dot(mapped, mapped);
  return m2 > 1e-30f ? mapped * inversesqrt(m2) : n;
}
#endif
