#pragma once
// Structs shared by C++ and GLSL (shaders/common/scene.glsl mirrors them). std430 layout: every
// member is a vec4/mat4 or packed into one, so C++ and GLSL agree without padding rules.
#include <glm/glm.hpp>

namespace radiant::gpu {

enum : int { kLightDirectional = 0, kLightPoint = 1, kLightSpot = 2 };
// Texture slots bound per draw (units kMaterialTextureUnit0 + slot).
enum : int { kSlotBaseColor = 0, kSlotMetallicRoughness, kSlotNormal, kSlotOcclusion, kSlotEmissive, kSlotCount };
constexpr int kMaterialTextureUnit0 = 8;

struct Material {
  glm::vec4 baseColorFactor;
  glm::vec4 emission;           // rgb = emissiveFactor * emissiveStrength
  glm::vec4 metallicRoughness;  // x metallic, y roughness, z transmission, w ior
  glm::vec4 scales;             // x normal scale, y occlusion strength, z alpha cutoff, w alpha mode (0 opaque, 1 mask, 2 blend)
  glm::ivec4 texturesA;         // texCoord index per slot (base, mr, normal, occlusion) or -1 when absent
  glm::ivec4 texturesB;         // x emissive texCoord or -1, y doubleSided, z unlit (KHR_materials_unlit),
                                // w Material::isSpecular() (the specular pass owns its reflections)
  // KHR_texture_transform per slot: rows 2 slot and 2 slot + 1 of uv' = M (u, v, 1) (xyz used).
  glm::vec4 uvTransform[2 * kSlotCount];
};
static_assert(sizeof(Material) == 96 + 32 * kSlotCount, "std430 Material must be 256 bytes");

struct Light {
  glm::vec4 positionType;    // xyz world position, w type
  glm::vec4 directionRange;  // xyz direction light travels (unit), w range (0 = infinite)
  glm::vec4 radiantIntensity;  // rgb = color * intensity, w unused
  glm::vec4 spotCone;        // x cos(outer), y cos(inner), zw unused
};
static_assert(sizeof(Light) == 64, "std430 Light must be 64 bytes");

// Written by the shadow_maps pass, one per light (same index as Light).
enum : int { kShadowNone = 0, kShadowCube = 1, kShadow2D = 2 };
struct ShadowInfo {
  glm::mat4 viewProj;  // 2D maps: world -> light clip (x,y in [-1,1], z unused: maps store distance)
  glm::vec4 params;    // x kind, y layer in its array, z world size of one texel at unit distance
                       // (perspective) or absolute (orthographic), w normal-offset bias in texels
  glm::vec4 params2;   // x orthographic (1) or perspective (0), y constant bias in texels, zw unused
};
static_assert(sizeof(ShadowInfo) == 96, "std430 ShadowInfo must be 96 bytes");

}  // namespace radiant::gpu
