#pragma once
// The one C++ material decoder: a glTF Material (factors x textures) at a surface point, as the
// MaterialParams record GLSL also reads (shaders/common/shared.h). It is the twin of decodeMaterial()
// in shaders/common/material.glsl, formula for formula; the ray-tracing core (RayScene::shade,
// emissionAt, alpha) calls it, and tests/gl/materials/parity_test.cpp holds the two equal.
//
// `texel(ref, srgb)` returns the texture `ref` at the point (sRGB decoded when srgb), vec4(1) when
// the slot is empty; it is how each caller samples (bilinear on the CPU, the GPU's samplers there).
// It applies the slot's KHR_texture_transform (TextureRef::transformUv, as RayScene::textureAt does):
// the uv rows travel with the TextureRef, as they travel per slot in gpu::Material::uvTransform.
#include <algorithm>

#include <glm/glm.hpp>

#include "renderer/frame/GpuTypes.h"
#include "renderer/scene/Scene.h"

namespace radiant {

// baseColorFactor x baseColorTexture, unclamped (the alpha test reads it).
template <class Texel>
glm::vec4 decodeBaseColor(const Material& m, Texel&& texel) {
  glm::vec4 base = m.baseColorFactor;
  if (m.baseColorTexture.valid()) base *= texel(m.baseColorTexture, true);
  return base;
}

// KHR_materials_unlit: the radiance leaving an unlit surface is its base colour, clamped as
// MaterialParams::baseColor (the G-buffer stores decodeMaterial's baseColor as its emission).
template <class Texel>
glm::vec3 decodeUnlitRadiance(const Material& m, Texel&& texel) {
  return glm::clamp(glm::vec3(decodeBaseColor(m, texel)), 0.f, 1.f);
}

// emissiveFactor x emissiveStrength x emissiveTexture.
template <class Texel>
glm::vec3 decodeEmission(const Material& m, Texel&& texel) {
  glm::vec3 e = m.emission();
  if (m.emissiveTexture.valid()) e *= glm::vec3(texel(m.emissiveTexture, true));
  return e;
}

// The layered extensions, factor x texture channel as their specs define them, clamped to their
// ranges (decodeLayerFactors() of material.glsl): KHR_materials_clearcoat (clearcoat = red of
// clearcoatTexture, roughness = green of clearcoatRoughnessTexture), KHR_materials_sheen (colour = rgb
// of sheenColorTexture, sRGB; roughness = alpha of sheenRoughnessTexture), KHR_materials_specular
// (weight = alpha of specularTexture, colour = rgb of specularColorTexture, sRGB).
template <class Texel>
void decodeLayers(const Material& m, Texel&& texel, gpu::MaterialParams& p) {
  float coat = m.clearcoatFactor, coatRoughness = m.clearcoatRoughnessFactor;
  if (m.clearcoatTexture.valid()) coat *= texel(m.clearcoatTexture, false).r;
  if (m.clearcoatRoughnessTexture.valid()) coatRoughness *= texel(m.clearcoatRoughnessTexture, false).g;
  glm::vec3 sheenColor = m.sheenColorFactor;
  float sheenRoughness = m.sheenRoughnessFactor;
  if (m.sheenColorTexture.valid()) sheenColor *= glm::vec3(texel(m.sheenColorTexture, true));
  if (m.sheenRoughnessTexture.valid()) sheenRoughness *= texel(m.sheenRoughnessTexture, false).a;
  glm::vec3 specularColor = m.specularColorFactor;
  float specular = m.specularFactor;
  if (m.specularTexture.valid()) specular *= texel(m.specularTexture, false).a;
  if (m.specularColorTexture.valid()) specularColor *= glm::vec3(texel(m.specularColorTexture, true));
  p.clearcoat = glm::vec4(std::clamp(coat, 0.f, 1.f), std::clamp(coatRoughness, 0.f, 1.f), 0.f, 0.f);
  p.sheen = glm::vec4(glm::clamp(sheenColor, 0.f, 1.f), std::clamp(sheenRoughness, gpu::kMinSheenRoughness, 1.f));
  p.specular = glm::vec4(glm::max(specularColor, 0.f), std::clamp(specular, 0.f, 1.f));
}

// A tangent-space normal map's texel (2 texel - 1, xy times `scale`) in the frame of the interpolated
// normal n (unit) and tangent t4 (xyz, w handedness): mapTangentNormal() of material.glsl. Returns n
// when the tangent is degenerate or the mapped normal vanishes.
inline glm::vec3 mapTangentNormal(const glm::vec4& texel, float scale, const glm::vec3& n, const glm::vec4& t4) {
  glm::vec3 t = glm::vec3(t4) - n * glm::dot(n, glm::vec3(t4));
  if (glm::dot(t, t) <= 0.f) return n;
  t = glm::normalize(t);
  const glm::vec3 b = glm::cross(n, t) * (t4.w < 0.f ? -1.f : 1.f);
  glm::vec3 tn = glm::vec3(texel) * 2.f - 1.f;
  tn.x *= scale;
  tn.y *= scale;
  const glm::vec3 mapped = tn.x * t + tn.y * b + tn.z * n;
  return glm::dot(mapped, mapped) > 0.f ? glm::normalize(mapped) : n;
}

// What the BSDF reads (baseColor, surface), without the emission and occlusion lookups: the ray
// tracer's shade() needs only these. emission is (0, 0, 0, 1). glTF 3.9.2: metallic = blue, roughness
// = green of metallicRoughnessTexture; KHR_materials_transmission: red channel of transmissionTexture.
template <class Texel>
gpu::MaterialParams decodeBsdfInputs(const Material& m, Texel&& texel) {
  const glm::vec4 base = decodeBaseColor(m, texel);
  float metallic = m.metallicFactor, roughness = m.roughnessFactor;
  if (m.metallicRoughnessTexture.valid()) {
    const glm::vec4 mr = texel(m.metallicRoughnessTexture, false);
    roughness *= mr.g;
    metallic *= mr.b;
  }
  float transmission = m.transmissionFactor;
  if (m.transmissionTexture.valid()) transmission *= texel(m.transmissionTexture, false).r;
  const float ior = m.ior > 0.f ? m.ior : gpu::kDefaultIor;
  gpu::MaterialParams p;
  p.baseColor = glm::vec4(glm::clamp(glm::vec3(base), 0.f, 1.f), base.a);
  p.emission = glm::vec4(0.f, 0.f, 0.f, 1.f);
  p.surface = glm::vec4(std::clamp(metallic, 0.f, 1.f), std::clamp(roughness, 0.f, 1.f),
                        std::clamp(transmission, 0.f, 1.f), ior);
  decodeLayers(m, texel, p);
  return p;
}

// The whole material at a point (decodeMaterial() of material.glsl): the BSDF inputs, the emission and
// the occlusion = 1 + strength (texel.r - 1) (glTF 3.9.3).
template <class Texel>
gpu::MaterialParams decodeMaterial(const Material& m, Texel&& texel) {
  gpu::MaterialParams p = decodeBsdfInputs(m, texel);
  float occlusion = 1.f;
  if (m.occlusionTexture.valid()) occlusion = 1.f + m.occlusionTexture.scale * (texel(m.occlusionTexture, false).r - 1.f);
  p.emission = glm::vec4(decodeEmission(m, texel), occlusion);
  return p;
}

}  // namespace radiant
