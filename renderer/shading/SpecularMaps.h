#pragma once
// The layered distance maps that the specular pass publishes for other passes (its output
// "specular_maps", thesis ch. 5): per specular object (specularMeshes() order) `layers` cubes of
// material, geometry, distance and diffuse albedo, the objects' records and the per-cube min/max
// distances. The caustics pass traces its photons through them (thesis ch. 6).
//
// Publishing (specular, execute, once the maps hold what `digest` describes): publishSpecularMaps().
// Reading (a pass that declares "specular_maps" as an input, in execute): publishedSpecularMaps(), on
// the frame's blackboard (FrameResources::product), so no pass looks up specular's own resource names.
#include <string>

#include "renderer/frame/FrameResources.h"
#include "renderer/frame/GpuTypes.h"
#include "renderer/gl/Gl.h"

namespace radiant::gpu {
#include "shaders/specular/shared.h"  // the maps' units and bindings
}  // namespace radiant::gpu

namespace radiant {

// Shared by specular/ldm.glsl's readers: the objects' records and the cubes' min/max distances.
constexpr GLuint kSpecularObjectsBinding = 3, kSpecularMinmaxBinding = 4;

struct SpecularMaps {
  gl::Texture* material = nullptr;  // cube-map arrays, 6 x objects x layers faces each
  gl::Texture* geometry = nullptr;
  gl::Texture* distance = nullptr;
  gl::Texture* albedo = nullptr;
  gl::Buffer* objects = nullptr;
  gl::Buffer* minmax = nullptr;
  int layers = 3;                // cubes per object
  int resolution = 16;           // texels per face side
  std::string digest;            // what the maps hold ("" when nothing was drawn): derived data keys on it

  // Binds the maps to their units (gpu::kUnitLdm*) and the buffers to their bindings.
  void bind() const {
    material->bindUnit(gpu::kUnitLdmMaterial);
    geometry->bindUnit(gpu::kUnitLdmGeometry);
    distance->bindUnit(gpu::kUnitLdmDistance);
    albedo->bindUnit(gpu::kUnitLdmAlbedo);
    objects->bindBase(GL_SHADER_STORAGE_BUFFER, kSpecularObjectsBinding);
    minmax->bindBase(GL_SHADER_STORAGE_BUFFER, kSpecularMinmaxBinding);
  }
};

inline void publishSpecularMaps(FrameResources& res, const SpecularMaps& maps) { res.publish("specular_maps", maps); }

// The maps specular published this frame, or nullptr when it did not run.
inline const SpecularMaps* publishedSpecularMaps(FrameResources& res) {
  return res.product<SpecularMaps>("specular_maps");
}

}  // namespace radiant
