// The GLSL side of the material decoder: the material textures, how a surface point samples them
// (SurfaceUv, materialTexel), and the material's flags. The decoding itself (factors x texture
// channels, normal mapping) is common/material_decode.glsl, the one definition GLSL and C++
// (renderer/scene/MaterialDecode.h, the ray-tracing core) both compile; this file includes it.
//
// The material textures are bound by GpuScene::bindMaterialTextures() at gpu::materialTextureUnit(slot).
// Every lookup is textureGrad() with the derivatives a SurfaceUv carries (below): never texture()'s
// implicit ones.
#ifndef RADIANT_COMMON_MATERIAL
#define RADIANT_COMMON_MATERIAL
#include "common/octahedral.glsl"
#include "common/scene.glsl"

// A surface point's texture coordinates, both sets (uv.xy TEXCOORD_0, uv.zw TEXCOORD_1), and their
// derivatives along the frame's x and y, which select the mip level.
//
// Why explicit derivatives (docs/GBUFFER.md, "Texture derivatives"): texture()'s implicit ones difference
// the coordinate across a 2 x 2 quad, whose helper invocations (pixels outside the triangle) run the
// shader too. The coordinate a slot samples depends on the Material record (its uv set, its
// KHR_texture_transform rows), read from a storage buffer, and llvmpipe (Mesa 22.3) returns zeros for
// storage-buffer loads in helper invocations: there the coordinate was (0, 0), every quad across a
// triangle edge saw a derivative of up to the whole texture, and sampled a coarse mip, the texture's
// mean colour: a line along every triangle edge of every textured model (Fox, BoxTextured; the normal map's
// too). The derivatives of the interpolated attributes themselves are right in every invocation, and the
// transform is affine, so the slot's derivatives are the transform's linear part times them.
struct SurfaceUv {
  vec4 uv;
  vec4 dx;  // d uv / d x (pixels)
  vec4 dy;  // d uv / d y
};

// In a fragment shader: the interpolated uv sets and their derivatives. Take it at the top of main(),
// before any discard or branch (derivatives need every invocation of the quad). A macro because dFdx
// does not compile in the other stages, which include this file too.
#define SURFACE_UV_FRAGMENT(uv0, uv1) SurfaceUv(vec4(uv0, uv1), dFdx(vec4(uv0, uv1)), dFdy(vec4(uv0, uv1)))

// A point without a footprint: the textures' base level (compute stages, parity tests), as the
// ray-tracing core samples them (RayScene::textureAt).
SurfaceUv surfaceUvPoint(vec2 uv0, vec2 uv1) { return SurfaceUv(vec4(uv0, uv1), vec4(0.0), vec4(0.0)); }

layout(binding = kUnitMaterial0 + kSlotBaseColor) uniform sampler2D t_matBaseColor;
layout(binding = kUnitMaterial0 + kSlotMetallicRoughness) uniform sampler2D t_matMetallicRoughness;
layout(binding = kUnitMaterial0 + kSlotNormal) uniform sampler2D t_matNormal;
layout(binding = kUnitMaterial0 + kSlotOcclusion) uniform sampler2D t_matOcclusion;
layout(binding = kUnitMaterial0 + kSlotEmissive) uniform sampler2D t_matEmissive;
layout(binding = kUnitMaterial0 + kSlotTransmission) uniform sampler2D t_matTransmission;
layout(binding = kUnitMaterialLayer0 + kSlotClearcoat - kSlotLayer0) uniform sampler2D t_matClearcoat;
layout(binding = kUnitMaterialLayer0 + kSlotClearcoatRoughness - kSlotLayer0) uniform sampler2D t_matClearcoatRoughness;
layout(binding = kUnitMaterialLayer0 + kSlotClearcoatNormal - kSlotLayer0) uniform sampler2D t_matClearcoatNormal;
layout(binding = kUnitMaterialLayer0 + kSlotSheenColor - kSlotLayer0) uniform sampler2D t_matSheenColor;
layout(binding = kUnitMaterialLayer0 + kSlotSheenRoughness - kSlotLayer0) uniform sampler2D t_matSheenRoughness;
layout(binding = kUnitMaterialLayer0 + kSlotSpecular - kSlotLayer0) uniform sampler2D t_matSpecular;
layout(binding = kUnitMaterialLayer0 + kSlotSpecularColor - kSlotLayer0) uniform sampler2D t_matSpecularColor;

// The uv texture slot `slot` samples: its uv set, then its KHR_texture_transform rows (identity
// without the extension). TextureRef::transformUv (renderer/scene/Scene.h) is the C++ twin.
vec2 materialSlotUv(Material m, int slot, int set, SurfaceUv t) {
  vec3 h = vec3(set == 1 ? t.uv.zw : t.uv.xy, 1.0);
  return vec2(dot(m.uvTransform[2 * slot].xyz, h), dot(m.uvTransform[2 * slot + 1].xyz, h));
}

// Texture slot `slot`, read through uv set `set`, at t: the transform maps the point, and its linear
// part the derivatives (chain rule; the transform is affine).
vec4 materialSample(sampler2D tex, Material m, int slot, int set, SurfaceUv t) {
  vec2 dx = set == 1 ? t.dx.zw : t.dx.xy, dy = set == 1 ? t.dy.zw : t.dy.xy;
  vec2 row0 = m.uvTransform[2 * slot].xy, row1 = m.uvTransform[2 * slot + 1].xy;
  return textureGrad(tex, materialSlotUv(m, slot, set, t), vec2(dot(row0, dx), dot(row1, dx)),
                     vec2(dot(row0, dy), dot(row1, dy)));
}

bool materialDoubleSided(Material m) { return m.texturesB.y != 0; }
// KHR_materials_unlit: the surface shows its base colour (decodeBaseColor, clamped as MaterialParams'
// baseColor) as the radiance leaving it, and nothing lights it.
bool materialUnlit(Material m) { return m.flags.x != 0; }
// Material::isSpecular(): the specular pass owns the surface's reflections.
bool materialSpecularOwned(Material m) { return m.flags.y != 0; }
int materialAlphaMode(Material m) { return int(m.scales.w); }  // 0 opaque, 1 mask, 2 blend
// glTF 3.9.4: MASK surfaces below the cutoff are not rendered.
bool materialMasked(Material m, float alpha) { return materialAlphaMode(m) == 1 && alpha < m.scales.z; }

// Texture slot `slot` (a constant at every call: the switch folds) through uv set `set` at t: the
// decoder's one way to a texel (common/material_decode.glsl). sRGB slots are decoded by their formats.
vec4 materialTexel(Material m, int slot, int set, SurfaceUv t) {
  switch (slot) {
    case kSlotBaseColor: return materialSample(t_matBaseColor, m, slot, set, t);
    case kSlotMetallicRoughness: return materialSample(t_matMetallicRoughness, m, slot, set, t);
    case kSlotNormal: return materialSample(t_matNormal, m, slot, set, t);
    case kSlotOcclusion: return materialSample(t_matOcclusion, m, slot, set, t);
    case kSlotEmissive: return materialSample(t_matEmissive, m, slot, set, t);
    case kSlotTransmission: return materialSample(t_matTransmission, m, slot, set, t);
    case kSlotClearcoat: return materialSample(t_matClearcoat, m, slot, set, t);
    case kSlotClearcoatRoughness: return materialSample(t_matClearcoatRoughness, m, slot, set, t);
    case kSlotClearcoatNormal: return materialSample(t_matClearcoatNormal, m, slot, set, t);
    case kSlotSheenColor: return materialSample(t_matSheenColor, m, slot, set, t);
    case kSlotSheenRoughness: return materialSample(t_matSheenRoughness, m, slot, set, t);
    case kSlotSpecular: return materialSample(t_matSpecular, m, slot, set, t);
    case kSlotSpecularColor: return materialSample(t_matSpecularColor, m, slot, set, t);
  }
  return vec4(1.0);
}

#define MaterialSite SurfaceUv
#include "common/material_decode.glsl"

vec3 materialSafeNormalize(vec3 v, vec3 fallback) {
  float l2 = dot(v, v);
  return l2 > 1e-30 ? v * inversesqrt(l2) : fallback;
}

// The G-buffer's `gbuffer_layers` target (docs/GBUFFER.md): x = halves (clear coat, coat roughness),
// y = the coat normal octahedron-encoded in two snorm16 (Cigolle et al. 2014), z = halves (sheen r, g),
// w = halves (sheen b, sheen roughness). decodeLayers() is its inverse.
uvec4 encodeLayers(MaterialParams p, vec3 coatNormal) {
  return uvec4(packHalf2x16(p.clearcoat.xy), packSnorm2x16(octEncode(coatNormal)), packHalf2x16(p.sheen.rg),
               packHalf2x16(p.sheen.ba));
}
// Fills p.clearcoat and p.sheen from the target and returns the coat normal.
vec3 decodeLayers(uvec4 layers, inout MaterialParams p) {
  p.clearcoat = vec4(unpackHalf2x16(layers.x), 0.0, 0.0);
  p.sheen = vec4(unpackHalf2x16(layers.z), unpackHalf2x16(layers.w));
  return octDecode(unpackSnorm2x16(layers.y));
}

// The interpolated vertex normal n turned to the side of the winding's normal before normal mapping, as
// RayScene::shade does: vertex normals inconsistent with the winding would otherwise shade the front
// as a back. viewerFace is the geometric normal on the viewer's side; frontFacing says whether the
// viewer sees the winding's front (gl_FrontFacing).
vec3 windingSideNormal(vec3 n, vec3 viewerFace, bool frontFacing) {
  vec3 winding = frontFacing ? viewerFace : -viewerFace;
  return dot(n, winding) < 0.0 ? -n : n;
}

// The normal-mapped shading normal (glTF 3.9.3): n is the interpolated vertex normal (on the front
// side of the winding), tangent the interpolated vertex tangent (xyz, w handedness). The back face of a
// double-sided surface sees the whole tangent frame reversed (t, b and n, as the glTF sample viewer
// and RayScene::shade): the mapped normal is negated, not re-mapped around -n.
vec3 decodeShadingNormal(Material m, vec3 n, vec4 tangent, SurfaceUv t, bool frontFacing) {
  vec3 mapped = n;
  if (m.texturesA.z >= 0) {
    mapped = mapTangentNormal(materialTexel(m, kSlotNormal, m.texturesA.z, t), m.scales.x, n, tangent);
  }
  return frontFacing ? mapped : -mapped;
}

// KHR_materials_clearcoat: the coat's normal is the interpolated normal, or clearcoatNormalTexture
// mapped as decodeShadingNormal maps normalTexture (its scale in m.clearcoat.z); never the base's map.
vec3 decodeCoatNormal(Material m, vec3 n, vec4 tangent, SurfaceUv t, bool frontFacing) {
  vec3 mapped = n;
  if (m.texturesC.z >= 0) {
    mapped = mapTangentNormal(materialTexel(m, kSlotClearcoatNormal, m.texturesC.z, t), m.clearcoat.z, n, tangent);
  }
  return frontFacing ? mapped : -mapped;
}
#endif
