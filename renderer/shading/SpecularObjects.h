#pragma once
// The specular objects of a scene (thesis ch. 5), as the specular pass builds its layered distance maps
// of them and the caustics pass uses them as caustic generators.
#include <cstddef>
#include <vector>

#include <glm/glm.hpp>

#include "renderer/scene/Scene.h"

namespace radiant {

// The reference point of an object (thesis 5.1: the centre of its cube maps): its bounds' centre.
inline glm::vec3 specularReferencePoint(const MeshInstance& mesh) { return mesh.bounds.center(); }

// The specular objects in map order (object k's cubes are k * layers + l of the specular pass's cube
// arrays): every mesh with triangles whose material isSpecular(), in mesh order.
inline std::vector<std::size_t> specularMeshes(const Scene& scene) {
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < scene.meshes.size(); ++i)
    if (scene.material(scene.meshes[i].material).isSpecular() && scene.meshes[i].triangleCount() > 0) out.push_back(i);
  return out;
}

}  // namespace radiant
