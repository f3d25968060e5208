#include "renderer/techniques/direct/Direct.h"

#include <algorithm>
#include <vector>

#include "renderer/frame/GpuTypes.h"
#include "renderer/frame/PassContext.h"
#include "renderer/techniques/direct/DirectLighting.h"
#include "renderer/techniques/direct/ImageBasedLighting.h"

namespace radiant {
namespace {
struct EnvironmentMapEntry {};  // marks the environment_map texture as holding the keyed map
}  // namespace

const TechniqueInfo& DirectPass::info() const {
  static const TechniqueInfo i{"direct",
                               "Direct lighting from punctual lights (glTF BRDF, PCF shadow maps) plus emission",
                               {"gbuffer_position", "normal", "albedo", "material", "emission", "geometric_normal",
                                "gbuffer_layers", "gbuffer_specular"},
                               {"shadow_maps"},
                               // environment_map: the request's environment, uploaded here for every pass
                               // that shows it (a frame resource, not an AOV).
                               {"direct", "environment_map"},
                               true,
                               true,
                               {"LE", "L(point)DE", "L(sky)GE"}};
  return i;
}

Requirements DirectPass::requirements(const Scene&, const api::RenderRequest&) const {
  // Always runs: even without lights or emitters it writes the sky behind the geometry and
  // initialises beauty. Lights and emission are handled per pixel in the shader.
  return Requirements::ok();
}

void DirectPass::prepare(const Scene&, const Params& params, FrameResources& res) {
  pcfRadius_ = params.get<int>("pcf_radius", 1);
  imageBasedLighting_ = params.get<bool>("image_based_lighting", true);
  const int w = res.view().width, h = res.view().height;
  gl::Framebuffer& fb = res.framebuffer("direct");
  fb.attach(GL_COLOR_ATTACHMENT0, res.texture("direct", GL_TEXTURE_2D, GL_RGBA32F, w, h));
  fb.attach(GL_COLOR_ATTACHMENT1, res.texture("beauty", GL_TEXTURE_2D, GL_RGBA32F, w, h));
  fb.setDrawBuffers({GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1});
  fb.checkComplete("DirectPass::prepare");
  declareDirectLightingResources(res);
  ibl::prepare(res);
  // The environment map, uploaded once per map (a marker entry keyed by its digest); a 1x1 placeholder
  // keeps the sampler complete when there is none.
  const FrameView& view = res.view();
  environmentUpload_ = nullptr;
  if (view.environment) {
    const Image& env = *view.environment;
    gl::Texture& t = res.texture("environment_map", GL_TEXTURE_2D, GL_RGBA32F, env.width, env.height);
    t.setFilter(GL_NEAREST, GL_NEAREST);
    bool built = false;
    res.cached<EnvironmentMapEntry>("environment_map", view.environmentKey + "|" + std::to_string(env.width) + "x" +
                                                           std::to_string(env.height), [&] {
      built = true;
      return std::make_unique<EnvironmentMapEntry>();
    });
    if (built) environmentUpload_ = &env;
  } else if (!res.hasTexture("environment_map")) {
    res.texture("environment_map", GL_TEXTURE_2D, GL_RGBA32F, 1, 1);
  }
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
  res.texture("gbuffer_layers").bindUnit(gpu::kUnitGbufferLayers);
  res.texture("gbuffer_specular").bindUnit(gpu::kUnitGbufferSpecular);
  const gl::Program& prog = ctx.shaders.program({"common/fullscreen.vert", "direct/direct.frag"});
  prog.use();
  bindDirectLighting(prog, res, ctx.gpu, static_cast<int>(ctx.scene.lights.size()), pcfRadius_);
  gl::Texture& environment = res.texture("environment_map");
  if (environmentUpload_) {
    const Image& env = *environmentUpload_;
    std::vector<float> rgba(static_cast<std::size_t>(env.width) * env.height * 4, 0.f);
    for (std::size_t p = 0; p < static_cast<std::size_t>(env.width) * env.height; ++p)
      for (int c = 0; c < 3; ++c) rgba[p * 4 + c] = env.pixels[p * env.channels + std::min(c, env.channels - 1)];
    // Rows in image order (row 0 = up): texel row v * height is image row v * height.
    environment.upload(0, 0, 0, 0, env.width, env.height, 1, GL_RGBA, GL_FLOAT, rgba.data());
  }
  environment.bindUnit(gpu::kUnitEnvironment);
  ibl::bind(res, prog, gpu::kUnitIblDfg, gpu::kUnitIblPrefiltered);
  // The environment's specular lobe (split-sum) is the light path L(sky)GE: added only when this pass
  // owns it (the diffuse lobe, L(sky)DE, is ambient_occlusion's or photon_gi's).
  const bool iblSpecular = imageBasedLighting_ && res.ownsLightPath("direct", "L(sky)GE");
  if (!iblSpecular) prog.set("u_iblMode", ibl::kNone);
  prog.set("u_hasEnvironment", view.environment ? 1 : 0);
  prog.setMat4("u_invViewProj", &view.invViewProj[0][0]);
  prog.set("u_eye", &view.eye[0], 3);
  const glm::vec3 forward = -glm::normalize(glm::vec3(view.camera.world[2]));
  prog.set("u_viewForward", &forward[0], 3);
  prog.set("u_orthographic", view.camera.projection == ProjectionType::Orthographic ? 1 : 0);
  prog.set("u_background", &view.ambient[0], 3);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  ctx.stats.counters["lights"] = static_cast<double>(ctx.scene.lights.size());
  ctx.stats.counters["ibl_mode"] = iblSpecular ? ibl::modeFor(res) : 0;
  res.markWritten("direct");
  res.markWritten("beauty");
}

}  // namespace radiant
