#pragma once
// The glTF extensions the loader implements beyond the core spec, in one table, and the material
// extensions that change what a texture lookup or a material means. The loader (GltfMaterials.cpp) calls these hooks;
// mesh compression (KHR_draco_mesh_compression, EXT_meshopt_compression) is in GltfCompression.h.
//
// - An unsupported extension in extensionsRequired refuses the file (SceneError -> 422) naming it and,
//   where a conversion exists, how to convert the file (KHR_texture_basisu: re-encode the textures as PNG).
// - An unsupported extension only in extensionsUsed is ignored *with a warning* (Scene::warnings ->
//   stats.warnings), as are material features rendered in a simpler way (alphaMode BLEND as opaque).
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/scene/Scene.h"

namespace tinygltf {
class Value;
}

namespace radiant::gltf {

// Every extension whose meaning the loader implements.
const std::vector<std::string>& supportedExtensions();
bool isSupportedExtension(const std::string& name);

// Throws SceneError("/extensionsRequired/i") for an unsupported required extension; appends one
// warning per unsupported extension that is used but not required.
void checkExtensions(const nlohmann::json& doc, std::vector<std::string>& warnings);

// KHR_texture_transform on a textureInfo (`extension` is its value, or null): sets ref's uv rows and,
// when the extension names one, its texCoord. `ptr` is the textureInfo's JSON pointer.
void applyTextureTransform(const tinygltf::Value* extension, TextureRef& ref, const std::string& ptr);

// The KHR_texture_transform rows for offset, rotation (radians) and scale (spec: uv' = T R S uv).
void textureTransformRows(glm::vec2 offset, float rotation, glm::vec2 scale, glm::vec3& row0, glm::vec3& row1);

}  // namespace radiant::gltf
