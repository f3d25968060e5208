#include "renderer/techniques/direct/Direct.h"

#include "renderer/frame/PassContext.h"

namespace radiant {

const TechniqueInfo& DirectPass::info() const {
  static const TechniqueInfo i{"direct",
                               "Direct lighting from punctual lights (glTF BRDF, PCF shadow maps) plus emission",
                               {"gbuffer_position", "normal", "albedo", "material", "emission", "geometric_normal"},
                               {"shadow_maps"},
                               {"direct"},
                               true,
                               true};
  return i;
}

Requirements DirectPass::requirements(const SceneFeatures&, const api::RenderRequest&) const {
  // Always runs: even without lights or emitters it writes the sky behind the geometry and
  // initialises beauty. Lights and emission are handled per pixel in the shader.
  return Requirements::ok();
}

void DirectPass::prepare(const Scene&, const Params& params, FrameResources& res) {
  pcfRadius_ = params.get<int>("pcf_radius", 1);
  const int w = res.view().width, h = res.view().height;
  gl::Framebuffer& fb = res.framebuffer("direct");
  fb.attach(GL_COLOR_ATTACHMENT0, res.texture("direct", GL_TEXTURE_2D, GL_RGBA32F, w, h));
  fb.attach(GL_COLOR_ATTACHMENT1, res.texture("beauty", GL_TEXTURE_2D, GL_RGBA32F, w, h));
  fb.setDrawBuffers({GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1});
  fb.checkComplete("DirectPass::prepare");
  // Shadow samplers must be complete even when the scene has no lights (shadow_maps skipped).
  if (!res.hasTexture("shadow_cube")) {
    res.texture("shadow_cube", GL_TEXTURE_CUBE_MAP_ARRAY, GL_R32F, 1, 1, 6).setFilter(GL_NEAREST, GL_NEAREST);
    res.texture("shadow_2d", GL_TEXTURE_2D_ARRAY, GL_R32F, 1, 1, 1).setFilter(GL_NEAREST, GL_NEAREST);
  }
  if (!res.hasBuffer("shadow_info")) res.buffer("shadow_info", sizeof(gpu::ShadowInfo));
}

void DirectPass::execute(PassContext& ctx) {
  FrameResources& res = ctx.resources;
  const auto& view = ctx.view;
  gl::Framebuffer& fb = res.framebuffer("direct");
  fb.bind();
  glViewport(0, 0, view.width, view.height);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_BLEND);
  glDisable(GL_CULL_FACE);

  const char* inputs[] = {"gbuffer_position", "normal", "albedo", "material", "emission", "geometric_normal"};
  for (GLuint i = 0; i < std::size(inputs); ++i) res.texture(inputs[i]).bindUnit(i);
  res.texture("shadow_cube").bindUnit(6);
  res.texture("shadow_2d").bindUnit(7);
  ctx.gpu.materials.bindBase(GL_SHADER_STORAGE_BUFFER, GpuScene::kMaterialBinding);
  ctx.gpu.lights.bindBase(GL_SHADER_STORAGE_BUFFER, GpuScene::kLightBinding);
  res.buffer("shadow_info").bindBase(GL_SHADER_STORAGE_BUFFER, 2);

  const gl::Program& prog = ctx.shaders.program({"common/fullscreen.vert", "direct/direct.frag"});
  prog.use();
  prog.set("u_lightCount", static_cast<int>(ctx.scene.lights.size()));
  prog.set("u_hasShadows", res.written("shadow_maps") ? 1 : 0);
  prog.set("u_pcfRadius", pcfRadius_);
  prog.set("u_eye", &view.eye[0], 3);
  const glm::vec3 forward = -glm::normalize(glm::vec3(view.camera.world[2]));
  prog.set("u_viewForward", &forward[0], 3);
  prog.set("u_orthographic", view.camera.projection == ProjectionType::Orthographic ? 1 : 0);
  prog.set("u_background", &view.ambient[0], 3);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  ctx.stats.counters["lights"] = static_cast<double>(ctx.scene.lights.size());
  res.markWritten("direct");
  res.markWritten("beauty");
}

}  // namespace radiant
