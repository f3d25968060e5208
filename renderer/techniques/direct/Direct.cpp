#include "renderer/techniques/direct/Direct.h"

#include "renderer/frame/PassContext.h"
#include "renderer/techniques/direct/DirectLighting.h"

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
  declareDirectLightingResources(res);
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
  const gl::Program& prog = ctx.shaders.program({"common/fullscreen.vert", "direct/direct.frag"});
  prog.use();
  bindDirectLighting(prog, res, ctx.gpu, static_cast<int>(ctx.scene.lights.size()), pcfRadius_);
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
