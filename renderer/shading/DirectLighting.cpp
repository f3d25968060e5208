#include "renderer/shading/DirectLighting.h"

#include <algorithm>

#include "renderer/frame/FrameView.h"

namespace radiant {

void declareDirectLightingResources(FrameResources& res) {
  res.texture("no_shadow_cube", GL_TEXTURE_CUBE_MAP_ARRAY, GL_R32F, 1, 1, 6).setFilter(GL_NEAREST, GL_NEAREST);
  res.texture("no_shadow_2d", GL_TEXTURE_2D_ARRAY, GL_R32F, 1, 1, 1).setFilter(GL_NEAREST, GL_NEAREST);
  if (!res.hasBuffer("no_shadow_info")) res.buffer("no_shadow_info", sizeof(gpu::ShadowInfo));
}

void declareFrameLights(FrameResources& res, const FrameView& view) {
  std::vector<gpu::Light> lights;
  for (const Light& l : view.lights) lights.push_back(toGpuLight(l));
  if (lights.empty()) lights.push_back(gpu::Light{});  // a zero-size SSBO is not bindable
  gl::Buffer& b = res.buffer("frame_lights", lights.size() * sizeof(gpu::Light));
  b.upload(lights.data(), lights.size() * sizeof(gpu::Light));
}

void bindDirectLighting(const gl::Program& program, FrameResources& res, const GpuScene& gpu, int lightCount,
                        int pcfRadius) {
  const ShadowMapSet* shadows = res.product<ShadowMapSet>("shadow_maps");
  (shadows ? *shadows->cube : res.texture("no_shadow_cube")).bindUnit(gpu::kUnitShadowCube);
  (shadows ? *shadows->flat : res.texture("no_shadow_2d")).bindUnit(gpu::kUnitShadow2D);
  gpu.bindSceneBuffers();
  if (res.hasBuffer("frame_lights")) res.buffer("frame_lights").bindBase(GL_SHADER_STORAGE_BUFFER, GpuScene::kLightBinding);
  program.set("u_sceneLightCount", std::min(lightCount, res.view().sceneLights));
  const int lights = static_cast<int>(res.view().lights.size());
  program.set("u_diffuseOnlyFrom", std::min(lightCount, lights - res.view().skyLights()));
  (shadows ? *shadows->info : res.buffer("no_shadow_info")).bindBase(GL_SHADER_STORAGE_BUFFER, 2);
  program.set("u_lightCount", lightCount);
  program.set("u_hasShadows", shadows ? 1 : 0);
  program.set("u_pcfRadius", pcfRadius);
}

}  // namespace radiant
