#pragma once
// The C++ reading of the material decoder: shaders/common/material_decode.glsl (factors x texture
// channels, normal mapping), the one definition GLSL also compiles, included here inside namespace
// radiant::material_glsl; and the std430 record it reads (toGpuMaterial, shaders/common/shared.h),
// which GpuScene uploads for GLSL and RayScene keeps per mesh.
//
// `texel(ref, srgb)` returns the texture `ref` at the point (sRGB decoded when srgb); it is how each
// caller samples (bilinear on the CPU, RayScene::textureAt). It applies the slot's
// KHR_texture_transform (TextureRef::transformUv): the uv rows travel with the TextureRef, as they
// travel per slot in gpu::Material::uvTransform. The decoder calls it only for slots the material has.
#include <array>

#include <glm/glm.hpp>

#include "renderer/frame/GpuTypes.h"
#include "renderer/scene/Scene.h"
#include "shaders/common/dual.glsl"

namespace radiant {

// The material's TextureRef of slot `slot` (gpu::kSlot*).
inline const TextureRef& materialTextureSlot(const Material& m, int slot) {
  switch (slot) {
    case gpu::kSlotBaseColor: return m.baseColorTexture;
    case gpu::kSlotMetallicRoughness: return m.metallicRoughnessTexture;
    case gpu::kSlotNormal: return m.normalTexture;
    case gpu::kSlotOcclusion: return m.occlusionTexture;
    case gpu::kSlotEmissive: return m.emissiveTexture;
    case gpu::kSlotTransmission: return m.transmissionTexture;
    case gpu::kSlotClearcoat: return m.clearcoatTexture;
    case gpu::kSlotClearcoatRoughness: return m.clearcoatRoughnessTexture;
    case gpu::kSlotClearcoatNormal: return m.clearcoatNormalTexture;
    case gpu::kSlotSheenColor: return m.sheenColorTexture;
    case gpu::kSlotSheenRoughness: return m.sheenRoughnessTexture;
    case gpu::kSlotSpecular: return m.specularTexture;
    default: return m.specularColorTexture;  // gpu::kSlotSpecularColor
  }
}
// Every slot's TextureRef, in slot order.
inline std::array<const TextureRef*, gpu::kSlotCount> materialTextureSlots(const Material& m) {
  std::array<const TextureRef*, gpu::kSlotCount> slots{};
  for (int s = 0; s < gpu::kSlotCount; ++s) slots[s] = &materialTextureSlot(m, s);
  return slots;
}
// Whether a slot holds sRGB colour (base colour, emissive, sheen colour, specular colour) rather than data.
inline bool materialSlotIsSrgb(int slot) {
  return slot == gpu::kSlotBaseColor || slot == gpu::kSlotEmissive || slot == gpu::kSlotSheenColor ||
         slot == gpu::kSlotSpecularColor;
}

// The std430 record of a material (shaders/common/shared.h): what GLSL's decoder reads from the
// scene's material buffer and the C++ decoder reads from RayScene's copy.
inline gpu::Material toGpuMaterial(const Material& m) {
  gpu::Material g{};
  g.baseColorFactor = m.baseColorFactor;
  g.emission = glm::vec4(m.emission(), 0.f);
  g.metallicRoughness = glm::vec4(m.metallicFactor, m.roughnessFactor, m.transmissionFactor, m.ior);
  g.scales = glm::vec4(m.normalTexture.scale, m.occlusionTexture.scale, m.alphaCutoff,
                       static_cast<float>(static_cast<int>(m.alphaMode)));
  auto uvSet = [](const TextureRef& r) { return r.valid() ? r.texCoord : -1; };
  g.texturesA = glm::ivec4(uvSet(m.baseColorTexture), uvSet(m.metallicRoughnessTexture), uvSet(m.normalTexture),
                           uvSet(m.occlusionTexture));
  g.texturesB = glm::ivec4(uvSet(m.emissiveTexture), m.doubleSided ? 1 : 0, uvSet(m.transmissionTexture), 0);
  g.flags = glm::ivec4(m.unlit ? 1 : 0, m.isSpecular() ? 1 : 0, 0, 0);
  // KHR_texture_transform: the same rows TextureRef::transformUv applies on the CPU, slot by slot.
  for (int s = 0; s < gpu::kSlotCount; ++s) {
    const TextureRef& ref = materialTextureSlot(m, s);
    g.uvTransform[2 * s] = glm::vec4(ref.uvRow0, 0.f);
    g.uvTransform[2 * s + 1] = glm::vec4(ref.uvRow1, 0.f);
  }
  g.clearcoat = glm::vec4(m.clearcoatFactor, m.clearcoatRoughnessFactor, m.clearcoatNormalTexture.scale, 0.f);
  g.sheen = glm::vec4(m.sheenColorFactor, m.sheenRoughnessFactor);
  g.specular = glm::vec4(m.specularColorFactor, m.specularFactor);
  g.texturesC = glm::ivec4(uvSet(m.clearcoatTexture), uvSet(m.clearcoatRoughnessTexture),
                           uvSet(m.clearcoatNormalTexture), uvSet(m.sheenColorTexture));
  g.texturesD = glm::ivec4(uvSet(m.sheenRoughnessTexture), uvSet(m.specularTexture), uvSet(m.specularColorTexture), 0);
  return g;
}

namespace material_glsl {
using glm::clamp;
using glm::cross;
using glm::dot;
using glm::inversesqrt;
using glm::max;
using glm::vec3;
using glm::vec4;
using gpu::kDefaultIor;
using gpu::kMinSheenRoughness;
using gpu::kSlotBaseColor;
using gpu::kSlotClearcoat;
using gpu::kSlotClearcoatRoughness;
using gpu::kSlotEmissive;
using gpu::kSlotMetallicRoughness;
using gpu::kSlotOcclusion;
using gpu::kSlotSheenColor;
using gpu::kSlotSheenRoughness;
using gpu::kSlotSpecular;
using gpu::kSlotSpecularColor;
using gpu::kSlotTransmission;
using gpu::Material;
using gpu::MaterialParams;

// A surface point as the C++ decoder sees it: a texel callback (slot -> texel) and its context.
struct MaterialSite {
  glm::vec4 (*texel)(const void* context, int slot);
  const void* context;
};
inline glm::vec4 materialTexel(const Material&, int slot, int /*uv set: the TextureRef carries it*/,
                               const MaterialSite& site) {
  return site.texel(site.context, slot);
}
#include "shaders/common/material_decode.glsl"
}  // namespace material_glsl

using material_glsl::mapTangentNormal;

// Runs decode(record, site) with a MaterialSite over `texel` (above) for the material m.
template <class Texel, class Decode>
auto decodeWith(const gpu::Material& record, const Material& m, Texel& texel, Decode decode) {
  struct Context {
    const Material* material;
    Texel* texel;
  } context{&m, &texel};
  const material_glsl::MaterialSite site{
      [](const void* c, int slot) -> glm::vec4 {
        const Context& x = *static_cast<const Context*>(c);
        return (*x.texel)(materialTextureSlot(*x.material, slot), materialSlotIsSrgb(slot));
      },
      &context};
  return decode(record, site);
}

// The decoder's entry points for a material and its record (toGpuMaterial(m); RayScene keeps one per
// mesh). baseColorFactor x baseColorTexture, unclamped (the alpha test reads it):
template <class Texel>
glm::vec4 decodeBaseColor(const gpu::Material& record, const Material& m, Texel&& texel) {
  return decodeWith(record, m, texel, [](auto& r, auto& s) { return material_glsl::decodeBaseColor(r, s); });
}
// KHR_materials_unlit: the radiance leaving an unlit surface.
template <class Texel>
glm::vec3 decodeUnlitRadiance(const gpu::Material& record, const Material& m, Texel&& texel) {
  return decodeWith(record, m, texel, [](auto& r, auto& s) { return material_glsl::decodeUnlitRadiance(r, s); });
}
// emissiveFactor x emissiveStrength x emissiveTexture.
template <class Texel>
glm::vec3 decodeEmission(const gpu::Material& record, const Material& m, Texel&& texel) {
  return decodeWith(record, m, texel, [](auto& r, auto& s) { return material_glsl::decodeEmission(r, s); });
}
// What the BSDF reads: emission (0, 0, 0, 1), no emission or occlusion lookups.
template <class Texel>
gpu::MaterialParams decodeBsdfInputs(const gpu::Material& record, const Material& m, Texel&& texel) {
  return decodeWith(record, m, texel, [](auto& r, auto& s) { return material_glsl::decodeBsdfInputs(r, s); });
}
// The whole material at a point, occlusion in emission.a.
template <class Texel>
gpu::MaterialParams decodeMaterial(const gpu::Material& record, const Material& m, Texel&& texel) {
  return decodeWith(record, m, texel, [](auto& r, auto& s) { return material_glsl::decodeMaterial(r, s); });
}
// The same without a record at hand (tests, one-off decodes): packs the material first.
template <class Texel>
gpu::MaterialParams decodeMaterial(const Material& m, Texel&& texel) {
  return decodeMaterial(toGpuMaterial(m), m, texel);
}
template <class Texel>
gpu::MaterialParams decodeBsdfInputs(const Material& m, Texel&& texel) {
  return decodeBsdfInputs(toGpuMaterial(m), m, texel);
}

}  // namespace radiant
