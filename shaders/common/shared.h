// The one definition of what C++ and GLSL share: the std430 records of the scene buffers, the decoded
// material, the texture units and the constants of the material model. Both languages include this
// file (ARCHITECTURE.md, "One material model in two languages"):
//   GLSL: #include "common/shared.h" (through common/scene.glsl), after the library's #version line;
//   C++:  renderer/frame/GpuTypes.h includes it inside namespace radiant::gpu, with vec4 = glm::vec4,
//         and static_asserts the sizes and offsets.
// Rules that keep the two readings identical: every struct member is a vec4/ivec4/mat4 (std430 then
// has no padding), the file includes nothing (the shader library expands #include even inside
// #ifdef __cplusplus), and constants are declared with RADIANT_CONST.
#ifndef RADIANT_COMMON_SHARED_H
#define RADIANT_COMMON_SHARED_H

#ifdef __cplusplus
#define RADIANT_CONST inline constexpr
#else
#define RADIANT_CONST const
#endif

// ---------------------------------------------------------------------------------------------------
// Material model constants.

// GGX alpha = max(roughness^2, kMinGgxAlpha) for roughness > 0, so D stays finite in float
// (D_max = 1 / (pi alpha^2) ~ 3e5). Roughness exactly 0 is a Dirac lobe on both sides.
RADIANT_CONST float kMinGgxAlpha = 1e-3;
// Index of refraction when a material gives none (glTF default, KHR_materials_ior).
RADIANT_CONST float kDefaultIor = 1.5;
// KHR_materials_clearcoat: the coat is a dielectric of index 1.5, F0 = ((1 - 1.5) / (1 + 1.5))^2.
RADIANT_CONST float kClearcoatF0 = 0.04;
// KHR_materials_sheen: sheen roughness is clamped to [kMinSheenRoughness, 1] (Charlie alpha = r^2), so the
// exponent 1 / alpha of sin(theta_h) stays below ~204 and the directional-albedo table resolves it.
RADIANT_CONST float kMinSheenRoughness = 0.07;
// The sheen directional-albedo table E(mu, r) (Bsdf.h rt::sheenAlbedoTable, read by both languages with
// the same bilinear interpolation): kSheenAlbedoSize^2 floats, row r_j = j / (size - 1) over the
// clamped roughness, column mu_i = i / (size - 1).
RADIANT_CONST int kSheenAlbedoSize = 32;
// Lobe flags of a BSDF sample (rt::LobeFlags, GLSL sampleMaterial): the side, then the lobe's kind
// (specular = Dirac delta). Light-path classes (LD+E, LS+DE, LG+DE) are built from them.
RADIANT_CONST int kLobeReflection = 1;
RADIANT_CONST int kLobeTransmission = 2;
RADIANT_CONST int kLobeDiffuse = 4;
RADIANT_CONST int kLobeGlossy = 8;
RADIANT_CONST int kLobeSpecular = 16;

// ---------------------------------------------------------------------------------------------------
// Texture units. Every sampler of every program has its own unit, so a pass can bind anything it
// declares without overwriting another's input. Units 0-5 are the G-buffer's (kUnitGbufferPosition ...
// below) or a pass's own full-screen inputs. The units, bindings and records only one technique (or one
// technique's product) uses are declared in its folder, shaders/<technique>/shared.h, under the same
// rules as this file (`grep -n "kUnit\|kBinding" shaders/*/shared.h` lists them;
// RenderCore.SamplerUnitsAreUniqueAcrossEveryTechniquesPrograms, over every program the techniques link,
// fails when two samplers share a unit). Taken there: 15-18 and 25
// (specular), 21 (ambient_occlusion), 24 (caustics), 33-34 (depth_impostors); storage bindings 4-5
// (depth_impostors) and 8 (specular).
RADIANT_CONST int kUnitShadowCube = 6;
RADIANT_CONST int kUnitShadow2D = 7;
// Material textures: slot s < kSlotLayer0 at unit kUnitMaterial0 + s, the layered extensions' slots
// at kUnitMaterialLayer0 + (s - kSlotLayer0) (materialTextureUnit() in GpuTypes.h; slots below).
RADIANT_CONST int kUnitMaterial0 = 8;
RADIANT_CONST int kSlotBaseColor = 0;
RADIANT_CONST int kSlotMetallicRoughness = 1;
RADIANT_CONST int kSlotNormal = 2;
RADIANT_CONST int kSlotOcclusion = 3;
RADIANT_CONST int kSlotEmissive = 4;
RADIANT_CONST int kSlotTransmission = 5;  // KHR_materials_transmission, red channel
// The layered extensions' textures (channels as their specs say: common/material_decode.glsl).
RADIANT_CONST int kSlotLayer0 = 6;
RADIANT_CONST int kSlotClearcoat = 6;           // KHR_materials_clearcoat: clearcoatTexture, red
RADIANT_CONST int kSlotClearcoatRoughness = 7;  // clearcoatRoughnessTexture, green
RADIANT_CONST int kSlotClearcoatNormal = 8;     // clearcoatNormalTexture (tangent space, like normalTexture)
RADIANT_CONST int kSlotSheenColor = 9;          // KHR_materials_sheen: sheenColorTexture, rgb (sRGB)
RADIANT_CONST int kSlotSheenRoughness = 10;     // sheenRoughnessTexture, alpha
RADIANT_CONST int kSlotSpecular = 11;           // KHR_materials_specular: specularTexture, alpha
RADIANT_CONST int kSlotSpecularColor = 12;      // specularColorTexture, rgb (sRGB)
RADIANT_CONST int kSlotCount = 13;
RADIANT_CONST int kUnitEnvironment = 14;  // equirect environment radiance (direct, specular)
RADIANT_CONST int kUnitIblDfg = 19;       // image-based lighting: split-sum DFG table (direct, ambient_occlusion)
RADIANT_CONST int kUnitIblPrefiltered = 20;  // image-based lighting: GGX-prefiltered environment (direct)
// The G-buffer's attachments, where a program that reads them the common way declares them (the pass
// binds them with gbuffer::bind, renderer/shading/GBufferInputs.h). Units 0-5 are these, or a pass's own
// full-screen inputs in a program that binds the attachments it reads elsewhere (gbuffer::bindAt).
RADIANT_CONST int kUnitGbufferPosition = 0;         // gbuffer_position: xyz world, w linear view depth
RADIANT_CONST int kUnitGbufferNormal = 1;           // normal
RADIANT_CONST int kUnitGbufferAlbedo = 2;           // albedo
RADIANT_CONST int kUnitGbufferMaterial = 3;         // material
RADIANT_CONST int kUnitGbufferEmission = 4;         // emission
RADIANT_CONST int kUnitGbufferGeometricNormal = 5;  // geometric_normal
RADIANT_CONST int kUnitGbufferLayers = 22;    // gbuffer_layers (KHR_materials_clearcoat, sheen)
RADIANT_CONST int kUnitGbufferSpecular = 23;  // gbuffer_specular (KHR_materials_specular)
RADIANT_CONST int kUnitMaterialLayer0 = 26;  // material slots kSlotLayer0.. (units 26-32)
// Units used. A binding must be below GL_MAX_COMBINED_TEXTURE_IMAGE_UNITS (GL 4.5 guarantees 80); a
// stage may read at most GL_MAX_TEXTURE_IMAGE_UNITS samplers (16 guaranteed, 32 on llvmpipe), which
// render_core_test checks per program. Units 33-34 are depth_impostors' (above).
RADIANT_CONST int kUnitCount = 35;

// Shader storage bindings of the scene buffers.
RADIANT_CONST int kBindingMaterials = 0;
RADIANT_CONST int kBindingLights = 1;
RADIANT_CONST int kBindingShadows = 2;
RADIANT_CONST int kBindingSheenAlbedo = 7;  // float[kSheenAlbedoSize^2] (GpuScene::sheenAlbedo)

// ---------------------------------------------------------------------------------------------------
// The frame's camera: one uniform buffer per frame (FrameResources::beginFrame uploads
// frameConstants(view)), declared once for GLSL by common/frame.glsl as `u_frame`. A pass that looks
// through the frame's camera reads it there instead of setting camera uniforms of its own; a program
// that draws other views too (cube faces, light cameras: specular/map.vert, env_diffuse/cube.vert,
// shadow_maps, caustics' photon.frag) keeps its own u_viewProj.
RADIANT_CONST int kBindingFrameConstants = 1;  // uniform-buffer binding (ambient_occlusion's samples use 0)
struct FrameConstants {
  mat4 view;         // world -> view (FrameView::view; the camera looks down -z)
  mat4 proj;         // reversed-Z projection (FrameView::proj)
  mat4 viewProj;     // proj view
  mat4 invViewProj;  // its inverse
  vec4 eye;          // xyz the camera's position (FrameView::eye), w unused
  vec4 viewForward;  // xyz the unit direction it looks along (-z of the camera's world matrix), w unused
  vec4 background;   // rgb the radiance seen where no surface is (FrameView::ambient: the uniform sky)
  ivec4 flags;       // x 1 for an orthographic camera, y 1 when the frame has an environment map
};

// ---------------------------------------------------------------------------------------------------
// Lights.
RADIANT_CONST int kLightDirectional = 0;
RADIANT_CONST int kLightPoint = 1;
RADIANT_CONST int kLightSpot = 2;

// One KHR_lights_punctual light (GpuScene's toGpuLight fills it).
struct Light {
  vec4 positionType;      // xyz world position, w type
  vec4 directionRange;    // xyz direction light travels (unit), w range (0 = infinite)
  vec4 radiantIntensity;  // rgb = color * intensity, w unused
  vec4 spotCone;          // x cos(outer), y cos(inner), z angular radius (environment lights), w unused
};

// Written by the shadow_maps pass, one per light (same index as Light).
RADIANT_CONST int kShadowNone = 0;
RADIANT_CONST int kShadowCube = 1;
RADIANT_CONST int kShadow2D = 2;
struct ShadowInfo {
  mat4 viewProj;  // 2D maps: world -> light clip (x,y in [-1,1], z unused: maps store distance)
  vec4 params;    // x kind, y layer in its array, z world size of one texel at unit distance
                  // (perspective) or absolute (orthographic), w normal-offset bias in texels
  vec4 params2;   // x orthographic (1) or perspective (0), y constant bias in texels, zw unused
};

// ---------------------------------------------------------------------------------------------------
// Materials.

// A glTF material as stored (toGpuMaterial, renderer/scene/MaterialDecode.h, fills it): factors and,
// per texture slot, the uv set it reads or -1 when the slot is empty. decodeMaterial()
// (common/material_decode.glsl, compiled by both languages) turns it into MaterialParams at a surface point.
struct Material {
  vec4 baseColorFactor;
  vec4 emission;           // rgb = emissiveFactor * emissiveStrength
  vec4 metallicRoughness;  // x metallic, y roughness, z transmission factor, w ior
  vec4 scales;             // x normal scale, y occlusion strength, z alpha cutoff, w alpha mode (0 opaque, 1 mask, 2 blend)
  ivec4 texturesA;         // uv set per slot (base colour, metallic-roughness, normal, occlusion), -1 = none
  ivec4 texturesB;         // x emissive uv set, y doubleSided, z transmission uv set, w unused
  ivec4 flags;             // x unlit (KHR_materials_unlit), y Material::isSpecular() (the specular pass
                           // owns its reflections), zw unused
  // KHR_texture_transform per slot: rows 2 slot and 2 slot + 1 of uv' = M (u, v, 1) (xyz used, w 0);
  // identity rows for a slot without the extension.
  vec4 uvTransform[2 * kSlotCount];
  // Layered extensions: factors, and the uv set per texture slot (-1 = none).
  vec4 clearcoat;  // KHR_materials_clearcoat: x clearcoatFactor, y clearcoatRoughnessFactor,
                   // z clearcoatNormalTexture.scale, w unused
  vec4 sheen;      // KHR_materials_sheen: rgb sheenColorFactor, a sheenRoughnessFactor
  vec4 specular;   // KHR_materials_specular: rgb specularColorFactor, a specularFactor
  ivec4 texturesC; // uv set of kSlotClearcoat, kSlotClearcoatRoughness, kSlotClearcoatNormal, kSlotSheenColor
  ivec4 texturesD; // uv set of kSlotSheenRoughness, kSlotSpecular, kSlotSpecularColor; w unused
};

// The material decoded at a surface point (factors x textures): what the BRDF reads. gltfBrdfCos
// (common/brdf.glsl) and rt::GltfBsdf (renderer/raytracing/Bsdf.h) take these values.
struct MaterialParams {
  vec4 baseColor;  // rgb linear base colour clamped to [0,1], a alpha (coverage)
  vec4 emission;   // rgb emitted radiance, a ambient occlusion (1 = none)
  vec4 surface;    // x metallic, y roughness (both clamped to [0,1]), z transmission in [0,1], w ior
  vec4 clearcoat;  // x coat weight in [0,1], y coat roughness in [0,1], zw 0 (KHR_materials_clearcoat)
  vec4 sheen;      // rgb sheen colour in [0,1], a sheen roughness in [kMinSheenRoughness,1] (KHR_materials_sheen)
  vec4 specular;   // rgb specular colour (>= 0), a specular weight in [0,1] (KHR_materials_specular):
                   // dielectric F0 = min(F0(ior) rgb, 1), F90 = 1, scaled by a; (1, 1, 1, 1) without it
};

// ---------------------------------------------------------------------------------------------------
// Participating media: the media layer of every media technique (renderer/shading/MediaLayer.h).

RADIANT_CONST int kProfileConstant = 0;
RADIANT_CONST int kProfileThesis = 1;       // thesis eq. 7.4
RADIANT_CONST int kProfileLinearExact = 2;  // tau (1 - |x - c| / r), integrated exactly

RADIANT_CONST int kPhaseIsotropic = 0;
RADIANT_CONST int kPhaseHenyeyGreenstein = 1;
RADIANT_CONST int kPhaseCornetteShanks = 2;  // thesis eq. 1.3

// The particle buffer's binding (after the scene's materials, lights and shadows).
RADIANT_CONST int kBindingMediaParticles = 3;

// One particle as the billboard shaders read it, in draw order (back to front).
struct MediaParticle {
  vec4 centerRadius;  // xyz world centre, w radius
  vec4 sourceTau;     // rgb the direction-independent source ((1 - a) L_e + a L_ambient), w tau
  vec4 albedoG;       // rgb albedo (scales the punctual lights' in-scattering), w phase g
  ivec4 models;       // x density profile (kProfile*), y phase model (kPhase*), z block (depth_impostors), w unused
};

#endif
