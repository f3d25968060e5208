// The one GLSL material decoder: a glTF material (factors x textures, common/shared.h) at a surface
// point, as MaterialParams. Every pass that shades scene geometry calls it (gbuffer, env_diffuse
// cube maps, specular distance maps); renderer/scene/MaterialDecode.h is the C++ twin used by the
// ray-tracing core, and tests/gl/materials/parity_test.cpp holds the two equal.
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

// baseColorFactor x baseColorTexture (sRGB decoded by the texture format), rgb and alpha. Unclamped:
// the alpha test reads it before the rest is decoded.
vec4 decodeBaseColor(Material m, SurfaceUv t) {
  vec4 base = m.baseColorFactor;
  if (m.texturesA.x >= 0) base *= materialSample(t_matBaseColor, m, kSlotBaseColor, m.texturesA.x, t);
  return base;
}

// emissiveFactor x emissiveStrength x emissiveTexture.
vec3 decodeEmission(Material m, SurfaceUv t) {
  vec3 e = m.emission.rgb;
  if (m.texturesB.x >= 0) e *= materialSample(t_matEmissive, m, kSlotEmissive, m.texturesB.x, t).rgb;
  return e;
}

// KHR_materials_clearcoat, _sheen, _specular: factor x texture channel, as their specs define them
// (clearcoat = red of clearcoatTexture, coat roughness = green of clearcoatRoughnessTexture, sheen
// colour = rgb of sheenColorTexture (sRGB), sheen roughness = alpha of sheenRoughnessTexture, specular
// = alpha of specularTexture, specular colour = rgb of specularColorTexture (sRGB)), then clamped to
// their ranges. MaterialDecode.h's decodeLayers is the C++ twin.
void decodeLayerFactors(Material m, SurfaceUv t, inout MaterialParams p) {
  float coat = m.clearcoat.x, coatRoughness = m.clearcoat.y;
  if (m.texturesC.x >= 0) coat *= materialSample(t_matClearcoat, m, kSlotClearcoat, m.texturesC.x, t).r;
  if (m.texturesC.y >= 0)
    coatRoughness *= materialSample(t_matClearcoatRoughness, m, kSlotClearcoatRoughness, m.texturesC.y, t).g;
  vec3 sheenColor = m.sheen.rgb;
  float sheenRoughness = m.sheen.a;
  if (m.texturesC.w >= 0) sheenColor *= materialSample(t_matSheenColor, m, kSlotSheenColor, m.texturesC.w, t).rgb;
  if (m.texturesD.x >= 0)
    sheenRoughness *= materialSample(t_matSheenRoughness, m, kSlotSheenRoughness, m.texturesD.x, t).a;
  vec3 specularColor = m.specular.rgb;
  float specular = m.specular.a;
  if (m.texturesD.y >= 0) specular *= materialSample(t_matSpecular, m, kSlotSpecular, m.texturesD.y, t).a;
  if (m.texturesD.z >= 0)
    specularColor *= materialSample(t_matSpecularColor, m, kSlotSpecularColor, m.texturesD.z, t).rgb;
  p.clearcoat = vec4(clamp(coat, 0.0, 1.0), clamp(coatRoughness, 0.0, 1.0), 0.0, 0.0);
  p.sheen = vec4(clamp(sheenColor, 0.0, 1.0), clamp(sheenRoughness, kMinSheenRoughness, 1.0));
  p.specular = vec4(max(specularColor, vec3(0.0)), clamp(specular, 0.0, 1.0));
}

// The whole material at a point. glTF 3.9.2-3.9.3: metallic is the blue, roughness the green channel
// of metallicRoughnessTexture; occlusion = 1 + strength (texel.r - 1); KHR_materials_transmission
// reads the red channel of transmissionTexture.
MaterialParams decodeMaterial(Material m, SurfaceUv t) {
  vec4 base = decodeBaseColor(m, t);
  float metallic = m.metallicRoughness.x, roughness = m.metallicRoughness.y;
  if (m.texturesA.y >= 0) {
    vec4 mr = materialSample(t_matMetallicRoughness, m, kSlotMetallicRoughness, m.texturesA.y, t);
    roughness *= mr.g;
    metallic *= mr.b;
  }
  float transmission = m.metallicRoughness.z;
  if (m.texturesB.z >= 0) transmission *= materialSample(t_matTransmission, m, kSlotTransmission, m.texturesB.z, t).r;
  float occlusion = 1.0;
  if (m.texturesA.w >= 0)
    occlusion = 1.0 + m.scales.y * (materialSample(t_matOcclusion, m, kSlotOcclusion, m.texturesA.w, t).r - 1.0);
  float ior = m.metallicRoughness.w > 0.0 ? m.metallicRoughness.w : kDefaultIor;
  MaterialParams p;
  p.baseColor = vec4(clamp(base.rgb, 0.0, 1.0), base.a);
  p.emission = vec4(decodeEmission(m, t), occlusion);
  p.surface = vec4(clamp(metallic, 0.0, 1.0), clamp(roughness, 0.0, 1.0), clamp(transmission, 0.0, 1.0), ior);
  decodeLayerFactors(m, t, p);
  return p;
}

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

// A tangent-space normal map's texel tn (2 texel - 1, xy scaled) in the frame of the interpolated vertex
// normal n and tangent (xyz, w handedness).
vec3 mapTangentNormal(vec3 tn, vec3 n, vec4 tangent) {
  vec3 t = materialSafeNormalize(tangent.xyz - n * dot(n, tangent.xyz), vec3(1, 0, 0));
  vec3 b = cross(n, t) * (tangent.w < 0.0 ? -1.0 : 1.0);
  return materialSafeNormalize(t * tn.x + b * tn.y + n * tn.z, n);
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
    vec3 tn = materialSample(t_matNormal, m, kSlotNormal, m.texturesA.z, t).xyz * 2.0 - 1.0;
    tn.xy *= m.scales.x;
    mapped = mapTangentNormal(tn, n, tangent);
  }
  return frontFacing ? mapped : -mapped;
}

// KHR_materials_clearcoat: the coat's normal is the interpolated normal, or clearcoatNormalTexture
// mapped as decodeShadingNormal maps normalTexture (its scale in m.clearcoat.z); never the base's map.
vec3 decodeCoatNormal(Material m, vec3 n, vec4 tangent, SurfaceUv t, bool frontFacing) {
  vec3 mapped = n;
  if (m.texturesC.z >= 0) {
    vec3 tn = materialSample(t_matClearcoatNormal, m, kSlotClearcoatNormal, m.texturesC.z, t).xyz * 2.0 - 1.0;
    tn.xy *= m.clearcoat.z;
    mapped = mapTangentNormal(tn, n, tangent);
  }
  return frontFacing ? mapped : -mapped;
}
#endif
