#pragma once
// The C++ reading of shaders/common/shared.h, the one definition of the structs and constants C++ and
// GLSL share (std430: every member is a vec4/ivec4/mat4, so the two layouts agree without padding
// rules). The static_asserts below pin the layout GLSL sees. A technique's own records and units
// (shaders/<technique>/shared.h) are read the same way beside it, after this header.
#include <cstddef>

#include <glm/glm.hpp>

namespace radiant::gpu {

using vec4 = glm::vec4;
using ivec4 = glm::ivec4;
using mat4 = glm::mat4;
#include "shaders/common/shared.h"

static_assert(sizeof(Light) == 64, "std430 Light must be 64 bytes");
static_assert(sizeof(ShadowInfo) == 96, "std430 ShadowInfo must be 96 bytes");
static_assert(sizeof(Material) == 112 + 32 * kSlotCount + 80, "std430 Material must be 608 bytes");
static_assert(offsetof(Material, texturesC) == 112 + 32 * kSlotCount + 48, "std430 Material: layer uv sets follow the layer factors");
static_assert(offsetof(Material, clearcoat) == 112 + 32 * kSlotCount, "std430 Material: layer factors follow the uv rows");
static_assert(offsetof(Material, texturesA) == 64 && offsetof(Material, texturesB) == 80,
              "std430 Material: texture slots follow the four factor vec4s");
static_assert(offsetof(Material, flags) == 96 && offsetof(Material, uvTransform) == 112,
              "std430 Material: flags, then two uv-transform rows per slot");
static_assert(sizeof(MaterialParams) == 96, "std430 MaterialParams must be 96 bytes");
static_assert(offsetof(MaterialParams, clearcoat) == 48 && offsetof(MaterialParams, specular) == 80,
              "std430 MaterialParams: the layers follow surface");
static_assert(offsetof(MaterialParams, emission) == 16 && offsetof(MaterialParams, surface) == 32,
              "std430 MaterialParams: baseColor, emission, surface");
static_assert(kUnitMaterial0 + kSlotLayer0 <= kUnitEnvironment, "material texture units overlap the environment");
static_assert(kUnitMaterialLayer0 + kSlotCount - kSlotLayer0 <= kUnitCount, "material units beyond kUnitCount");
// The unit material texture slot `slot` is bound to (GpuScene::bindMaterialTextures; material.glsl's bindings).
constexpr int materialTextureUnit(int slot) {
  return slot < kSlotLayer0 ? kUnitMaterial0 + slot : kUnitMaterialLayer0 + (slot - kSlotLayer0);
}
static_assert(kUnitShadow2D < kUnitMaterial0, "shadow units overlap the material units");
static_assert(sizeof(MediaParticle) == 64, "std430 MediaParticle must be 64 bytes");
static_assert(sizeof(FrameConstants) == 4 * 64 + 4 * 16, "std140 FrameConstants: four mat4, four vec4");
// Kept for existing callers: the first material texture unit.
inline constexpr int kMaterialTextureUnit0 = kUnitMaterial0;

}  // namespace radiant::gpu
