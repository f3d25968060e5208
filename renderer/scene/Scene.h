#pragma once
// The renderer's scene: what a glTF file becomes after loading. Shared by the raster passes and the
// CPU reference renderer, so both see exactly the same geometry, materials and lights.
//
// Conventions (documented in docs/TECHNIQUES.md, "Units and conventions"):
// - Right-handed, Y up, metres, as glTF.
// - Geometry is flattened to world space at load time: every MeshInstance holds world-space
//   positions, normals and tangents, so a consumer never walks the node hierarchy.
// - Light intensities are glTF's numbers as they are (KHR_lights_punctual): point and spot in
//   candela (W/sr in our radiometric reading), directional in lux (W/m^2). A point light of
//   intensity I lights a white Lambertian plane head-on at distance d with radiance I/(pi d^2).

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "api/Media.h"

namespace radiant {

struct Bounds {
  glm::vec3 min{std::numeric_limits<float>::max()};
  glm::vec3 max{-std::numeric_limits<float>::max()};
  bool empty() const { return min.x > max.x; }
  void extend(const glm::vec3& p) { min = glm::min(min, p); max = glm::max(max, p); }
  void extend(const Bounds& b) { if (!b.empty()) { extend(b.min); extend(b.max); } }
  glm::vec3 center() const { return empty() ? glm::vec3(0) : 0.5f * (min + max); }
  glm::vec3 extent() const { return empty() ? glm::vec3(0) : max - min; }
  float radius() const { return 0.5f * glm::length(extent()); }
};

enum class TextureColorSpace { Linear, SRGB };

// A decoded 8-bit RGBA image, as stored in the file (not linearised: the sampler decides).
struct Texture {
  std::string name;
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgba8;  // width * height * 4, row 0 is the top row (glTF uv (0,0) = top-left)
  int wrapS = 10497, wrapT = 10497;  // GL enums from the glTF sampler (REPEAT default)
  int minFilter = 9987, magFilter = 9729;
  // How the texels are encoded: SRGB when a material uses the texture as baseColor or emissive
  // (glTF spec 3.9.2), Linear for data (metallic-roughness, normal, occlusion, transmission).
  TextureColorSpace colorSpace = TextureColorSpace::Linear;
};

struct TextureRef {
  int texture = -1;   // index into Scene::textures, -1 = none
  int texCoord = 0;   // which UV set (KHR_texture_transform's texCoord when it sets one)
  float scale = 1.f;  // normalTexture.scale or occlusionTexture.strength
  // KHR_texture_transform as the two rows of the affine map uv' = T R S uv (identity without it);
  // the GLSL side reads the same rows (gpu::Material::uvTransform).
  glm::vec3 uvRow0{1.f, 0.f, 0.f}, uvRow1{0.f, 1.f, 0.f};
  bool valid() const { return texture >= 0; }
  glm::vec2 transformUv(const glm::vec2& uv) const {
    const glm::vec3 h(uv, 1.f);
    return {glm::dot(uvRow0, h), glm::dot(uvRow1, h)};
  }
};

enum class AlphaMode { Opaque, Mask, Blend };

// glTF 2.0 metallic-roughness material plus KHR_materials_transmission / _ior / _emissive_strength.
struct Material {
  std::string name;
  glm::vec4 baseColorFactor{1.f};
  float metallicFactor = 1.f;
  float roughnessFactor = 1.f;
  glm::vec3 emissiveFactor{0.f};
  float emissiveStrength = 1.f;  // KHR_materials_emissive_strength
  float transmissionFactor = 0.f;  // KHR_materials_transmission
  float ior = 1.5f;                // KHR_materials_ior
  float clearcoatFactor = 0.f;           // KHR_materials_clearcoat
  float clearcoatRoughnessFactor = 0.f;
  glm::vec3 sheenColorFactor{0.f};       // KHR_materials_sheen
  float sheenRoughnessFactor = 0.f;
  float specularFactor = 1.f;            // KHR_materials_specular
  glm::vec3 specularColorFactor{1.f};
  // KHR_materials_volume: thicknessFactor > 0 makes the closed mesh the boundary of a homogeneous
  // absorbing medium (0, the default, is the spec's thin wall: no medium). attenuationDistance is in
  // world units (infinite = no absorption); attenuationColor is what white light turns into after
  // travelling that distance inside. thicknessFactor (mesh units) and thicknessTexture (green) are the
  // spec's hint for renderers that cannot trace the inside: every path here traces the real distance
  // (docs/TECHNIQUES.md, "Volume absorption"), so they only decide that the medium exists.
  float thicknessFactor = 0.f;
  float attenuationDistance = std::numeric_limits<float>::infinity();
  glm::vec3 attenuationColor{1.f};
  TextureRef baseColorTexture, metallicRoughnessTexture, normalTexture, occlusionTexture,
      emissiveTexture, transmissionTexture;
  // The layered extensions' textures (their channels: shaders/common/material_decode.glsl): KHR_materials_clearcoat
  // (clearcoatNormalTexture.scale is its normal scale), KHR_materials_sheen, KHR_materials_specular.
  TextureRef clearcoatTexture, clearcoatRoughnessTexture, clearcoatNormalTexture, sheenColorTexture,
      sheenRoughnessTexture, specularTexture, specularColorTexture;
  TextureRef thicknessTexture;  // KHR_materials_volume (green channel; see thicknessFactor)
  bool doubleSided = false;
  bool unlit = false;  // KHR_materials_unlit: the surface shows its base colour, lit by nothing
  AlphaMode alphaMode = AlphaMode::Opaque;
  float alphaCutoff = 0.5f;

  // Below this roughness a surface is treated as specular by the planner (mirror-like).
  static constexpr float kSpecularRoughness = 0.2f;
  glm::vec3 emission() const { return emissiveFactor * emissiveStrength; }
  bool isEmissive() const { return emission() != glm::vec3(0.f) || emissiveTexture.valid(); }
  bool isTransmissive() const { return transmissionFactor > 0.f; }
  // KHR_materials_volume: the inside of this closed mesh absorbs (Beer-Lambert).
  bool hasVolume() const { return thicknessFactor > 0.f; }
  // The medium's extinction coefficient sigma_t = -ln(attenuationColor) / attenuationDistance per
  // channel (KHR_materials_volume, "Attenuation"), so that transmittance T(x) = exp(-sigma_t x) equals
  // attenuationColor at x = attenuationDistance. Zero without a medium or with an infinite distance;
  // finite always (a black colour or a vanishing distance gives FLT_MAX: opaque, never NaN: 0 x FLT_MAX = 0).
  glm::vec3 attenuationCoefficient() const {
    glm::vec3 sigma(0.f);
    if (!hasVolume() || !(attenuationDistance > 0.f) || !(attenuationDistance < std::numeric_limits<float>::infinity()))
      return sigma;
    for (int k = 0; k < 3; ++k) {
      const float c = attenuationColor[k];
      if (!(c < 1.f)) continue;  // 1 (or NaN, refused by the loader): no absorption in this channel
      const double s = -std::log(std::max(double(c), 1e-300)) / double(attenuationDistance);
      sigma[k] = float(std::min(s, double(std::numeric_limits<float>::max())));
    }
    return sigma;
  }
  // A tangent frame is needed for the base's or the clear coat's normal map.
  bool hasNormalMap() const { return normalTexture.valid() || clearcoatNormalTexture.valid(); }
  bool isSpecular() const {
    if (unlit) return false;
    return (metallicFactor > 0.5f && roughnessFactor < kSpecularRoughness) || isTransmissive();
  }
  // Up to this roughness a metal's or glass's lobe is narrow enough to be traced as a beam.
  static constexpr float kNarrowLobeRoughness = 0.5f;
  // Metal or glass whose reflection or refraction is a Dirac or narrow glossy lobe: the S or G vertex
  // of the light-path classes LS+DE and LG+DE. light_volumes builds beams from these surfaces and
  // photon_gi leaves the paths scattered by them to it when it owns those classes (docs/TECHNIQUES.md).
  // Factors only: a metallic-roughness texture does not change the classification.
  bool scattersNarrowLobe() const {
    if (unlit) return false;
    return (metallicFactor >= 0.5f || isTransmissive()) && roughnessFactor <= kNarrowLobeRoughness;
  }
};

// One glTF primitive instanced by one node, flattened to world space. Always an indexed triangle list.
struct MeshInstance {
  std::string name;      // node name (used for per-request overrides such as receivers)
  int node = -1;         // glTF node index
  int mesh = -1;         // glTF mesh index
  int primitive = 0;     // primitive index within the mesh
  int material = -1;     // index into Scene::materials; -1 = glTF default material
  glm::mat4 world{1.f};  // node-to-world transform already applied to the arrays below
  std::vector<glm::vec3> positions;  // world space
  std::vector<glm::vec3> normals;    // world space, unit length (generated if the file had none)
  std::vector<glm::vec4> tangents;   // world space xyz + handedness w; empty unless a normal map needs them
  std::vector<glm::vec2> uv0, uv1;   // empty when absent
  std::vector<std::uint32_t> indices;  // triangle list
  std::string extrasJson;  // the node's glTF "extras" as JSON text ("" when none)
  Bounds bounds;           // world space
  std::size_t triangleCount() const { return indices.size() / 3; }
};

enum class LightType { Directional, Point, Spot };

struct Light {
  std::string name;
  LightType type = LightType::Point;
  glm::vec3 color{1.f};
  float intensity = 1.f;
  float range = 0.f;  // 0 = infinite (glTF: undefined range)
  float innerConeAngle = 0.f;
  float outerConeAngle = 0.7853981634f;  // pi/4, glTF default
  glm::vec3 position{0.f};              // world space (point, spot)
  glm::vec3 direction{0.f, 0.f, -1.f};  // world space, the direction light travels (node's -Z)
  // Directional lights taken from an environment map (renderer/shading/EnvironmentLights.h): the radius
  // of the cone they subtend, in radians; 0 for glTF's punctual lights.
  float angularRadius = 0.f;
};

enum class ProjectionType { Perspective, Orthographic };

struct Camera {
  std::string name;
  ProjectionType projection = ProjectionType::Perspective;
  float yfov = 0.6911f;     // radians (perspective)
  float aspectRatio = 0.f;  // 0 = take it from the image size
  float xmag = 1.f, ymag = 1.f;  // orthographic half extents
  float znear = 0.01f;
  float zfar = 0.f;         // 0 = infinite far plane (perspective)
  glm::mat4 world{1.f};     // camera-to-world; the camera looks down its -Z
  bool fromFile = false;    // false when synthesised to frame the scene bounds
};

// What the scene contains. The FramePlanner reads this to decide which passes run.
struct SceneFeatures {
  int pointLights = 0, spotLights = 0, directionalLights = 0;
  int emissiveTriangles = 0;
  int specularMaterials = 0;      // used materials with isSpecular(): smooth metal or transmissive
  int transmissiveMaterials = 0;  // used materials with KHR_materials_transmission > 0
  int textures = 0;
  std::size_t triangles = 0;
  Bounds bounds;
  bool hasCamera = false;
  // Participating media (glTF RADIANT_particle_system nodes): systems, their particles, and how many
  // systems emit (fire) or scatter (smoke, dust, cloud). A request's media add to these per frame
  // (mediaFeatures below), so the planner runs media techniques only when a frame has media.
  int particleSystems = 0, emissiveMedia = 0, scatteringMedia = 0;
  std::size_t particles = 0;
  int lightCount() const { return pointLights + spotLights + directionalLights; }
  bool hasEmissive() const { return emissiveTriangles > 0; }
  bool hasMedia() const { return particles > 0; }
};

struct Scene {
  std::string digest;  // "sha256:<hex>" of the bytes it was loaded from ("" when built in code)
  std::string name;
  std::vector<MeshInstance> meshes;
  std::vector<Material> materials;
  std::vector<Texture> textures;
  std::vector<Light> lights;
  Camera camera;  // the first camera in the file, or a default that frames the bounds
  SceneFeatures features;
  // Particle systems from RADIANT_particle_system nodes, in world space (api/Media.h).
  std::vector<api::ParticleSystem> media;
  std::vector<std::string> nodeNames;  // every node of the default scene, depth-first order ("" unnamed)
  // What the loader could not honour (an unsupported optional extension, ...): frames list them in
  // stats.warnings, so nothing is dropped silently.
  std::vector<std::string> warnings;

  // glTF's default material (used when MeshInstance::material == -1).
  const Material& material(int index) const {
    static const Material kDefault{};
    return index >= 0 && index < static_cast<int>(materials.size()) ? materials[index] : kDefault;
  }
};

// Recomputes Scene::features (and bounds) from the scene's contents. The loader calls it; code that
// builds or edits a Scene by hand calls it too.
SceneFeatures computeFeatures(const Scene& scene);

// The media counts of SceneFeatures for the scene's systems plus `extra` (a request's media).
SceneFeatures mediaFeatures(const SceneFeatures& scene, const std::vector<api::ParticleSystem>& extra);

// A camera that frames `bounds` from the +Z side, looking at the centre, for the given aspect.
// yfov in radians (the default is glTF viewers' customary 39.6 degrees).
Camera defaultCameraFor(const Bounds& bounds, float aspect, float yfov = 0.6911f);

}  // namespace radiant
