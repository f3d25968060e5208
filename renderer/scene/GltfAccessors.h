#pragma once
// glTF accessors read into vectors, every index, offset, stride and count checked against the buffers
// first (a SceneError naming the accessor otherwise); JSON pointers into the document.
// Part of the glTF loader (GltfLoader.h: what is supported; its modules: docs/DEVELOPMENT.md).
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

namespace tinygltf {
class Model;
}

namespace radiant::gltf {

// "/base/index" and "/meshes/m/primitives/p".
std::string pointer(std::string_view base, std::size_t index);
std::string primitivePointer(int mesh, int prim);

// All elements of an accessor as floats (count * components), with glTF's normalisation rules and
// sparse substitution applied; `expectedType` is a TINYGLTF_TYPE_*; at most `maxBytes` of floats.
std::vector<float> readFloats(const tinygltf::Model& model, int index, int expectedType, const std::string& what,
                              std::size_t maxBytes);
// An index accessor (unsigned byte, short or int; not sparse) as 32-bit indices.
std::vector<std::uint32_t> readIndices(const tinygltf::Model& model, int index, const std::string& what,
                                       std::size_t maxBytes);

std::vector<glm::vec2> asVec2(const std::vector<float>& f);
std::vector<glm::vec3> asVec3(const std::vector<float>& f);
std::vector<glm::vec4> asVec4(const std::vector<float>& f);

}  // namespace radiant::gltf
