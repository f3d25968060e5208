#include "renderer/techniques/direct/Direct.h"
#include "params/direct_params.h"

#include <algorithm>
#include <vector>

#include "renderer/frame/Beauty.h"
#include "renderer/frame/FramePlanner.h"
#include "renderer/frame/GpuTypes.h"
#include "renderer/frame/PassContext.h"
#include "renderer/shading/DirectLighting.h"
#include "renderer/shading/ImageBasedLighting.h"
#include "renderer/shading/GBufferInputs.h"

namespace radiant {

// Declared in direct.json; environment_map (an optional input) is the request's environment, a frame
// resource the Renderer uploads (renderer/frame/FrameAllocation.h).
const TechniqueInfo& DirectPass::info() const {
  static const TechniqueInfo i = describedTechnique("direct");
  return i;
}

Requirements DirectPass::requirements(const Scene&, const api::RenderRequest&) const {
  // Always runs: even without lights or emitters it writes the sky behind the geometry. Lights and
  // emission are handled per pixel in the shader.
  return Requirements::ok();
}

void DirectPass::prepare(const Scene&, const Params& params, FrameResources& res) {
  const DirectParams p = DirectParams::from(params);
  pcfRadius_ = p.pcf_radius;
  imageBasedLighting_ = p.image_based_lighting;
  gl::Framebuffer& fb = res.framebuffer("direct");
  fb.attach(GL_COLOR_ATTACHMENT0, res.texture("direct"));  // declared outputs: allocated by the Renderer
  attachBeauty(res, fb, GL_COLOR_ATTACHMENT1);
  fb.setDrawBuffers({GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1});
  fb.checkComplete("DirectPass::prepare");
  declareDirectLightingResources(res);
  ibl::prepare(res);
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
  // direct overwrites its AOV and adds into beauty (its declared blend).
  BeautyWrite beauty = BeautyWrite::drawBuffer(res, 1);

  using gbuffer::Attachment;
  gbuffer::bind(res, {Attachment::Position, Attachment::Normal, Attachment::Albedo, Attachment::Material,
                      Attachment::Emission, Attachment::GeometricNormal, Attachment::Layers, Attachment::Specular});
  const gl::Program& prog = ctx.shaders.program({"common/fullscreen.vert", "direct/direct.frag"});
  prog.use();
  bindDirectLighting(prog, res, ctx.gpu, static_cast<int>(ctx.view.lights.size()), pcfRadius_);
  res.texture(kEnvironmentMap).bindUnit(gpu::kUnitEnvironment);
  ibl::bind(res, prog, gpu::kUnitIblDfg, gpu::kUnitIblPrefiltered);
  // The environment's specular lobe (split-sum) is the light path L(sky)GE: added only when this pass
  // owns it (the diffuse lobe, L(sky)DE, is ambient_occlusion's or photon_gi's).
  const bool iblSpecular = imageBasedLighting_ && res.owns("direct", api::kPathSkyGE);
  if (!iblSpecular) prog.set("u_iblMode", ibl::kNone);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  beauty.commit();
  ctx.stats.counters["lights"] = static_cast<double>(ctx.scene.lights.size());
  // The environment's compact bright regions this pass lit as shadowed lights, and their share of the
  // map's power (renderer/shading/EnvironmentLights.h; the rest is image-based lighting's).
  const auto& split = view.environmentLights;
  ctx.stats.counters["environment_lights"] = split ? static_cast<double>(split->lights.size()) : 0.0;
  ctx.stats.counters["environment_light_share"] = split ? split->fraction : 0.0;
  ctx.stats.counters["sky_lights"] = static_cast<double>(view.skyLights());
  ctx.stats.counters["ibl_mode"] = iblSpecular ? ibl::modeFor(res) : 0;
  res.markWritten("direct");
}

}  // namespace radiant
