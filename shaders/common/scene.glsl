// Mirrors renderer/frame/GpuTypes.h (std430). Keep the two in step; the C++ side static_asserts sizes.
#ifndef RADIANT_COMMON_SCENE
#define RADIANT_COMMON_SCENE

#define LIGHT_DIRECTIONAL 0
#define LIGHT_POINT 1
#define LIGHT_SPOT 2
#define SHADOW_NONE 0
#define SHADOW_CUBE 1
#define SHADOW_2D 2

struct Material {
  vec4 baseColorFactor;
  vec4 emission;           // rgb = emissiveFactor * emissiveStrength
  vec4 metallicRoughness;  // x metallic, y roughness, z transmission, w ior
  vec4 scales;             // x normal scale, y occlusion strength, z alpha cutoff, w alpha mode
  ivec4 texturesA;         // uv set per slot (base, mr, normal, occlusion), -1 = none
  ivec4 texturesB;         // x emissive uv set, y doubleSided, z unlit (KHR_materials_unlit), w specular-owned
  vec4 uvTransform[10];    // KHR_texture_transform: rows 2 slot, 2 slot + 1 of the affine uv map
};

struct Light {
  vec4 positionType;
  vec4 directionRange;
  vec4 radiantIntensity;
  vec4 spotCone;  // x cos(outer), y cos(inner)
};

struct ShadowInfo {
  mat4 viewProj;
  vec4 params;   // x kind, y layer, z texel world size (per unit distance if perspective), w normal offset (texels)
  vec4 params2;  // x orthographic, y constant bias (texels)
};

layout(std430, binding = 0) readonly buffer Materials { Material materials[]; };

#define SLOT_BASE_COLOR 0
#define SLOT_METALLIC_ROUGHNESS 1
#define SLOT_NORMAL 2
#define SLOT_OCCLUSION 3
#define SLOT_EMISSIVE 4

// The uv a material's texture slot samples at (KHR_texture_transform; identity rows without it).
vec2 materialUv(Material m, int slot, vec2 uv) {
  vec3 h = vec3(uv, 1.0);
  return vec2(dot(m.uvTransform[2 * slot].xyz, h), dot(m.uvTransform[2 * slot + 1].xyz, h));
}
layout(std430, binding = 1) readonly buffer Lights { Light lights[]; };
layout(std430, binding = 2) readonly buffer Shadows { ShadowInfo shadows[]; };

#endif
