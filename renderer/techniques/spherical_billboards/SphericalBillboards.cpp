#include "renderer/techniques/spherical_billboards/SphericalBillboards.h"
#include "params/spherical_billboards_params.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "renderer/frame/PassContext.h"
#include "renderer/raytracing/Media.h"
#include "renderer/shading/MediaLayer.h"
#include "renderer/shading/Stretches.h"
#include "renderer/shading/GBufferInputs.h"

namespace radiant {
namespace {
constexpr int kParticlesPerStretch = 4096;  // billboards drawn between two cancel checks
}  // namespace

const TechniqueInfo& SphericalBillboardsPass::info() const {
  static const TechniqueInfo i = describedTechnique("spherical_billboards");
  return i;
}

Requirements SphericalBillboardsPass::requirements(const Scene& scene, const api::RenderRequest& request) const {
  return mediaRequirements(scene, request);
}

void SphericalBillboardsPass::prepare(const Scene&, const Params& params, FrameResources& res) {
  const SphericalBillboardsParams p = SphericalBillboardsParams::from(params);
  const FrameView& view = res.view();
  using Method = SphericalBillboardsParams::Method;
  method_ = p.method == Method::kPlanar ? 1 : p.method == Method::kSoft ? 2 : 0;
  chord_ = p.chord == SphericalBillboardsParams::Chord::kScreenParallel ? 1 : 0;
  ratio_ = static_cast<float>(p.resolution_ratio);
  softScale_ = static_cast<float>(p.soft_scale);
  depthAware_ = p.upsampling == SphericalBillboardsParams::Upsampling::kDepthAware;
  const glm::vec3 forward = viewForward(view);
  const bool ortho = view.camera.projection == ProjectionType::Orthographic;
  particles_ = mediaParticles(view.media, view.ambient, view.eye, forward, ortho, p.sort);

  // Overdraw estimate: covered pixels of every particle's disc over the image (the cost driver, 7.3).
  const float pixelsPerUnit = ortho ? 0.5f * view.height / view.camera.ymag
                                    : 0.5f * view.height / std::tan(0.5f * view.camera.yfov);
  double covered = 0.0;
  for (const auto& p : particles_) {
    const float r = p.centerRadius.w;
    const float z = ortho ? 1.f : glm::dot(glm::vec3(p.centerRadius) - view.eye, forward);
    const double rp = z > r ? r * pixelsPerUnit / std::sqrt(z * z - r * r) : 1e30;
    covered += std::min(3.14159265 * rp * rp, double(view.width) * view.height);
  }
  overdraw_ = covered / (double(view.width) * view.height);

  if (vao_.id() == 0) vao_ = gl::VertexArray("spherical_billboards");
  const int w = view.width, h = view.height;
  declareMediaLayer(res, w, h);
  lowWidth_ = std::max(1, static_cast<int>(std::ceil(w * ratio_)));
  lowHeight_ = std::max(1, static_cast<int>(std::ceil(h * ratio_)));
  if (ratio_ < 1.f) {
    gl::Texture& low = res.texture("media_layer", GL_TEXTURE_2D, GL_RGBA32F, lowWidth_, lowHeight_);
    low.setFilter(GL_NEAREST, GL_NEAREST);
    gl::Framebuffer& lfb = res.framebuffer("media_layer");
    lfb.attach(GL_COLOR_ATTACHMENT0, low);
    lfb.setDrawBuffers({GL_COLOR_ATTACHMENT0});
    lfb.checkComplete("SphericalBillboardsPass::prepare (layer)");
  }
  // Capacity in powers of two, so a sweep over particle counts rarely reallocates.
  std::size_t capacity = 64;
  while (capacity < particles_.size()) capacity *= 2;
  res.buffer("media_particles", capacity * sizeof(gpu::MediaParticle));
}

void SphericalBillboardsPass::execute(PassContext& ctx) {
  FrameResources& res = ctx.resources;
  const FrameView& view = ctx.view;
  gl::Buffer& buffer = res.buffer("media_particles");
  if (!particles_.empty()) buffer.upload(particles_.data(), particles_.size() * sizeof(gpu::MediaParticle));
  const bool hasDepth = gbuffer::written(res, gbuffer::Attachment::Position);
  const bool layered = ratio_ < 1.f;
  vao_.bind();

  // 1. Particles, back to front, into the layer (or the full-resolution target at ratio 1).
  const int tw = layered ? lowWidth_ : view.width, th = layered ? lowHeight_ : view.height;
  beginMediaLayer(res.framebuffer(layered ? "media_layer" : "media"), tw, th);
  if (hasDepth) gbuffer::bind(res, {gbuffer::Attachment::Position});
  buffer.bindBase(GL_SHADER_STORAGE_BUFFER, gpu::kBindingMediaParticles);
  ctx.gpu.lights.bindBase(GL_SHADER_STORAGE_BUFFER, gpu::kBindingLights);
  const gl::Program& prog = ctx.shaders.program({"spherical_billboards/particle.vert", "spherical_billboards/particle.frag"});
  prog.use();
  setMediaCameraUniforms(prog, view, hasDepth, tw, th);
  prog.set("u_method", method_);
  prog.set("u_chord", chord_);
  prog.set("u_softScale", softScale_);
  prog.set("u_lightCount", static_cast<int>(ctx.scene.lights.size()));
  drawInstancedInStretches(prog, GL_TRIANGLES, 6, static_cast<int>(particles_.size()), kParticlesPerStretch,
                           ctx.cancel, "spherical_billboards' particles");
  glDisable(GL_BLEND);

  // 2. The layer to full resolution.
  if (layered) {
    gl::Framebuffer& fb = res.framebuffer("media");
    fb.bind();
    glViewport(0, 0, view.width, view.height);
    res.texture("media_layer").bindUnit(0);
    if (hasDepth) gbuffer::bindAt(res, gbuffer::Attachment::Position, 1);
    const gl::Program& up = ctx.shaders.program({"common/fullscreen.vert", "spherical_billboards/upsample.frag"});
    up.use();
    up.set("u_hasDepth", hasDepth ? 1 : 0);
    up.set("u_depthAware", depthAware_ ? 1 : 0);
    glProgramUniform2i(up.id(), up.uniformLocation("u_lowSize"), lowWidth_, lowHeight_);
    glProgramUniform2i(up.id(), up.uniformLocation("u_fullSize"), view.width, view.height);
    glDrawArrays(GL_TRIANGLES, 0, 3);
  }
  res.markWritten("media");
  res.markWritten("media_transmittance");

  // 3. beauty = beauty * T + C.
  composeMediaIntoBeauty(ctx);

  ctx.stats.counters["particles"] = static_cast<double>(particles_.size());
  ctx.stats.counters["overdraw_estimate"] = overdraw_;
  ctx.stats.counters["layer_width"] = lowWidth_;
  ctx.stats.counters["layer_height"] = lowHeight_;
}

}  // namespace radiant
