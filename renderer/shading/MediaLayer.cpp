#include "renderer/shading/MediaLayer.h"

#include <algorithm>
#include <numeric>

#include "renderer/raytracing/Media.h"

#include "renderer/frame/Beauty.h"
#include "renderer/frame/FrameView.h"

namespace radiant {

Requirements mediaRequirements(const Scene& scene, const api::RenderRequest& request) {
  const SceneFeatures f = mediaFeatures(scene.features, request.media);
  return f.hasMedia() ? Requirements::ok()
                      : Requirements::skip("the frame has no participating media (no RADIANT_particle_system "
                                           "node in the scene, no media in the request)");
}

void beginMediaLayer(const gl::Framebuffer& target, int w, int h) {
  target.bind();
  glViewport(0, 0, w, h);
  const float clear[4] = {0.f, 0.f, 0.f, 1.f};  // no light, transmittance 1
  glClearNamedFramebufferfv(target.id(), GL_COLOR, 0, clear);
  glDisable(GL_DEPTH_TEST);
  glDepthMask(GL_FALSE);
  glDisable(GL_CULL_FACE);
  glEnable(GL_BLEND);
  glBlendEquation(GL_FUNC_ADD);
  glBlendFuncSeparate(GL_ONE, GL_ONE_MINUS_SRC_ALPHA, GL_ZERO, GL_ONE_MINUS_SRC_ALPHA);
}

void setMediaCameraUniforms(const gl::Program& prog, const FrameView& view, bool hasDepth, int targetW, int targetH) {
  prog.set("u_znear", view.camera.znear);
  prog.set("u_hasDepth", hasDepth ? 1 : 0);
  const float targetSize[2] = {static_cast<float>(targetW), static_cast<float>(targetH)};
  prog.set("u_targetSize", targetSize, 2);
  glProgramUniform2i(prog.id(), prog.uniformLocation("u_fullSize"), view.width, view.height);
}

void declareMediaLayer(FrameResources& res, int w, int h) {
  gl::Texture& media = res.texture("media");
  media.setFilter(GL_NEAREST, GL_NEAREST);
  gl::Framebuffer& fb = res.framebuffer("media");
  fb.attach(GL_COLOR_ATTACHMENT0, media);
  fb.setDrawBuffers({GL_COLOR_ATTACHMENT0});
  fb.checkComplete("declareMediaLayer");
  gl::Framebuffer& compose = res.framebuffer("media_compose");
  attachBeauty(res, compose, GL_COLOR_ATTACHMENT0);
  compose.setDrawBuffers({GL_COLOR_ATTACHMENT0});
  compose.checkComplete("declareMediaLayer (compose)");
}

void composeMediaIntoBeauty(PassContext& ctx) {
  FrameResources& res = ctx.resources;
  const FrameView& view = ctx.view;
  gl::Framebuffer& compose = res.framebuffer("media_compose");
  compose.bind();
  glViewport(0, 0, view.width, view.height);
  if (res.compositions(kBeauty).empty()) {
    const float sky[4] = {view.ambient.x, view.ambient.y, view.ambient.z, 1.f};
    glClearNamedFramebufferfv(compose.id(), GL_COLOR, 0, sky);
  }
  // Its declared blend, transmit: rgb = C + T beauty (the layer's rgb and transmittance), alpha kept.
  BeautyWrite beauty = BeautyWrite::drawBuffer(res, 0);
  res.texture("media").bindUnit(0);
  const gl::Program& comp = ctx.shaders.program({"common/fullscreen.vert", "common/media_compose.frag"});
  comp.use();
  glDrawArrays(GL_TRIANGLES, 0, 3);
  beauty.commit();
  glDepthMask(GL_TRUE);
}

namespace {
// A particle without optical depth is no medium: no shader sees it.
bool drawn(const api::Particle& p) { return p.tau > 0.f; }
}  // namespace

std::size_t mediaParticleCount(const api::ParticleSystem& system) {
  return static_cast<std::size_t>(std::count_if(system.particles.begin(), system.particles.end(), drawn));
}

std::size_t mediaParticleCount(const std::vector<api::ParticleSystem>& media) {
  std::size_t n = 0;
  for (const api::ParticleSystem& s : media) n += mediaParticleCount(s);
  return n;
}

std::vector<gpu::MediaParticle> mediaParticles(const std::vector<api::ParticleSystem>& media, glm::vec3 ambient,
                                               glm::vec3 eye, glm::vec3 forward, bool orthographic, bool sort,
                                               std::vector<int>* systemOf) {
  std::vector<gpu::MediaParticle> out;
  std::vector<float> key;
  if (systemOf) systemOf->clear();
  for (const api::ParticleSystem& s : media) {
    const int profile = s.profile == api::DensityProfile::Thesis        ? gpu::kProfileThesis
                        : s.profile == api::DensityProfile::LinearExact ? gpu::kProfileLinearExact
                                                                        : gpu::kProfileConstant;
    const int phase = s.phase == api::PhaseModel::HenyeyGreenstein ? gpu::kPhaseHenyeyGreenstein
                      : s.phase == api::PhaseModel::CornetteShanks ? gpu::kPhaseCornetteShanks
                                                                   : gpu::kPhaseIsotropic;
    for (const api::Particle& p : s.particles) {
      if (!drawn(p)) continue;
      // (1 - a) L_e + a L_ambient: a uniform sky integrates the phase function to 1.
      const glm::vec3 emitted = s.emits() ? s.emissionScale * rt::blackbodyRgb(p.temperature) : glm::vec3(0.f);
      const glm::vec3 source = (1.f - p.albedo) * emitted + p.albedo * ambient;
      out.push_back({glm::vec4(p.position, p.radius), glm::vec4(source, p.tau), glm::vec4(p.albedo, s.g),
                     glm::ivec4(profile, phase, 0, 0)});
      key.push_back(orthographic ? glm::dot(p.position - eye, forward) : glm::length(p.position - eye));
      if (systemOf) systemOf->push_back(static_cast<int>(&s - media.data()));
    }
  }
  if (!sort || systemOf) return out;  // systemOf: unsorted, so that it stays parallel
  std::vector<std::size_t> order(out.size());
  std::iota(order.begin(), order.end(), std::size_t(0));
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return key[a] > key[b]; });
  std::vector<gpu::MediaParticle> sorted(out.size());
  for (std::size_t i = 0; i < order.size(); ++i) sorted[i] = out[order[i]];
  return sorted;
}

}  // namespace radiant
