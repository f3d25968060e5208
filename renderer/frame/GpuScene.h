#pragma once
// A Scene uploaded to the GPU: one vertex array per MeshInstance, the materials and lights as std430
// storage buffers, and the textures (sRGB views for colour). Built once per scene digest and reused
// by every pass and every frame while the scene is unchanged.
#include <array>
#include <functional>
#include <map>
#include <vector>

#include "renderer/frame/GpuTypes.h"
#include "renderer/gl/Gl.h"
#include "renderer/raytracing/Cancel.h"
#include "renderer/scene/MaterialDecode.h"
#include "renderer/scene/Scene.h"

namespace radiant {

struct GpuMesh {
  gl::Buffer positions, normals, uv0, uv1, tangents, indices;
  gl::VertexArray vao;
  GLsizei indexCount = 0;
  // Levels of detail (renderer/scene/MeshLod.h), finest first: the same vertices, fewer triangles.
  struct Lod {
    gl::Buffer indices;
    gl::VertexArray vao;
    GLsizei indexCount = 0;
    float error = 0.f;  // bound on the distance to the full surface (world units)
  };
  std::vector<Lod> lods;
  int material = -1;  // index into the materials buffer (the default material is appended last)
  std::array<int, gpu::kSlotCount> textures = noTextures();  // index into GpuScene::textures, -1 = none
  static std::array<int, gpu::kSlotCount> noTextures() {
    std::array<int, gpu::kSlotCount> t;
    t.fill(-1);
    return t;
  }
};

// The std430 record of a scene light (shaders/common/shared.h; a material's: toGpuMaterial in
// renderer/scene/MaterialDecode.h). Exposed so the GPU/CPU parity test feeds the GPU exactly what a
// render does.
gpu::Light toGpuLight(const Light& light);

class GpuScene {
public:
  // `cancel` is polled between meshes (each uploads its buffers and first-used textures): a cancelled
  // upload throws rt::Cancelled and the half-built object is destroyed, never cached.
  explicit GpuScene(const Scene& scene, const rt::Cancel& cancel = {});
  // What the upload will allocate, before making it (the memory accountant's admission): every
  // texture once with its mip chain, every vertex with all five attributes, the indices and their
  // levels of detail (at most as many again).
  static std::size_t estimateBytes(const Scene& scene);
  // Identity of what was uploaded, for keys of derived data: "<digest>#<upload generation>". The
  // generation is unique per upload, so a key never outlives the scene it was built from (an address
  // could be reused by the next scene).
  const std::string sceneKey;
  std::vector<GpuMesh> meshes;
  std::vector<gl::Texture> textures;  // one per (scene texture, colour space) actually used
  gl::Buffer materials;               // gpu::Material[], binding kMaterialBinding
  gl::Buffer lights;                  // gpu::Light[], binding kLightBinding
  gl::Buffer sheenAlbedo;             // rt::sheenAlbedoTable(), binding gpu::kBindingSheenAlbedo
  std::vector<gpu::Light> lightData;  // CPU copy of `lights` (at least one entry: zero-size SSBOs are invalid)
  std::size_t triangles = 0;
  float lodBaseError = 0.f;  // the finest level's bound (MeshLod.h lodBaseError)

  static constexpr GLuint kMaterialBinding = gpu::kBindingMaterials;
  static constexpr GLuint kLightBinding = gpu::kBindingLights;

  // Binds the materials, lights and sheen-albedo buffers at their shared.h bindings.
  void bindSceneBuffers() const;
  // The materials and sheen-albedo buffers alone (what draw() and drawMeshes() bind).
  void bindMaterialBuffers() const;
  // Binds mesh `meshIndex`'s material textures to units gpu::materialTextureUnit(slot) (what draw() does per mesh).
  void bindMaterialTextures(std::size_t meshIndex) const;

  // Binds the materials buffer and, per draw, the mesh's textures; issues one draw per mesh.
  // The program must declare `uniform int u_material;`.
  void draw(const gl::Program& program, bool withTextures) const;
  // Same, for the meshes whose index `select` accepts; `select` runs just before each mesh's draw, so
  // it may also set per-mesh uniforms (the specular pass draws per-object layers with it).
  // With `allowance`: each mesh drawn at its coarsest level of detail whose error bound is within
  // allowance(mesh) (world units; 0 or below: the full mesh), for passes that render the scene many
  // times into texels far coarser than the screen's (shadow maps, the specular pass's maps). Returns
  // the triangles drawn.
  std::size_t drawMeshes(const gl::Program& program, bool withTextures,
                         const std::function<bool(std::size_t meshIndex)>& select,
                         const std::function<float(std::size_t meshIndex)>& allowance = {}) const;
};

}  // namespace radiant
