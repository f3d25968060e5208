#include "renderer/shading/DirectLighting.h"

namespace radiant {

void declareDirectLightingResources(FrameResources& res) {
  if (!res.hasTexture("shadow_cube")) {
    res.texture("shadow_cube", GL_TEXTURE_CUBE_MAP_ARRAY, GL_R32F, 1, 1, 6).setFilter(GL_NEAREST, GL_NEAREST);
    res.texture("shadow_2d", GL_TEXTURE_2D_ARRAY, GL_R32F, 1, 1, 1).setFilter(GL_NEAREST, GL_NEAREST);
  }
  if (!res.hasBuffer("shadow_info")) res.buffer("shadow_info", sizeof(gpu::ShadowInfo));
}

void bindDirectLighting(const gl::Program& program, FrameResources& res, const GpuScene& gpu, int lightCount,
                        int pcfRadius) {
  res.texture("shadow_cube").bindUnit(gpu::kUnitShadowCube);
  res.texture("shadow_2d").bindUnit(gpu::kUnitShadow2D);
  gpu.bindSceneBuffers();
  res.buffer("shadow_info").bindBase(GL_SHADER_STORAGE_BUFFER, 2);
  program.set("u_lightCount", lightCount);
  program.set("u_hasShadows", res.written("shadow_maps") ? 1 : 0);
  program.set("u_pcfRadius", pcfRadius);
}

}  // namespace radiant
