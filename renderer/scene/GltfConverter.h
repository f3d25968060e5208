#pragma once
// The conversion of tinygltf's parsed model into a Scene (after GltfFiles' checks): one class whose
// members are defined by topic in GltfConverter.cpp (the node hierarchy: cameras, lights, particle
// systems), GltfMaterials.cpp (textures and materials) and GltfMeshes.cpp (primitives).
// Part of the glTF loader (GltfLoader.h: what is supported; its modules: docs/DEVELOPMENT.md).
#include <cstddef>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <tiny_gltf.h>

#include "renderer/scene/Scene.h"

namespace radiant::gltf {

// An extension object of a glTF object, or nullptr; a number member of one, or `fallback`.
const tinygltf::Value* extension(const tinygltf::ExtensionMap& ext, const char* name);
float number(const tinygltf::Value& v, const char* key, float fallback);
// A unit vector perpendicular to the unit vector n.
glm::vec3 anyPerpendicular(const glm::vec3& n);

class Converter {
public:
  Converter(const tinygltf::Model& model, std::size_t maxBytes) : m_(model), maxBytes_(maxBytes) {}

  Scene run();

private:
  // The node hierarchy, cameras, lights and particle systems (GltfConverter.cpp).
  void walkScene();
  void visitNode(int index, const tinygltf::Node& node, const glm::mat4& world, const std::string& ptr);
  void addParticleSystem(const tinygltf::Value& e, const glm::mat4& world, const std::string& ptr);
  void addCamera(const tinygltf::Node& node, const glm::mat4& world, const std::string& ptr);
  void addLight(const tinygltf::Value& e, const glm::mat4& world, const std::string& ptr);
  Bounds sceneBounds() const;
  // Textures and materials (GltfMaterials.cpp).
  TextureRef textureRef(int index, int texCoord, float scale, const std::string& ptr, bool srgb);
  TextureRef textureRef(const tinygltf::Value& info, const std::string& ptr, bool srgb = false);
  void convertTextures();
  void convertMaterials();
  void convertVolume(const tinygltf::Value& e, const std::string& at, Material& mat);
  // Mesh primitives (GltfMeshes.cpp).
  void addPrimitive(int nodeIndex, const tinygltf::Node& node, int meshIndex, int primIndex,
                    const glm::mat4& world);

  const tinygltf::Model& m_;
  std::size_t maxBytes_;
  Scene scene_;
  std::vector<bool> textureUsable_;  // per glTF texture: false when dropped with a warning
};

}  // namespace radiant::gltf
