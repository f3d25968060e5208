#include "renderer/techniques/depth_impostors/Impostors.h"

#include <algorithm>
#include <cmath>

namespace radiant::impostors {

AtlasLayout atlasLayout(int blocks, int requestedRes) {
  AtlasLayout l;
  if (blocks <= 0) return l;
  l.tilesX = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(blocks))));
  l.tilesY = (blocks + l.tilesX - 1) / l.tilesX;
  l.res = std::min(requestedRes, AtlasLayout::kMaxAtlas / l.tilesX);
  if (l.res < AtlasLayout::kMinRes) l.res = 0;
  return l;
}

ImpostorSet::ImpostorSet(const BlockSet& blocks, const AtlasLayout& layout, int slices, int sliceResolution,
                         int fourierTerms)
    : blocks_(blocks), layout_(layout), slices_(std::clamp(slices, 1, gpu::kMaxImpostorSlices)), sliceRes_(sliceResolution),
      fourierTerms_(std::clamp(fourierTerms, 0, kMaxFourierTerms)) {
  const std::size_t nb = std::max<std::size_t>(1, blocks_.blocks.size());
  const std::size_t np = std::max<std::size_t>(1, blocks_.particles.size());
  particleBuffer = gl::Buffer("depth_impostors.particles", np * sizeof(gpu::MediaParticle));
  if (!blocks_.particles.empty())
    particleBuffer.upload(blocks_.particles.data(), blocks_.particles.size() * sizeof(gpu::MediaParticle));
  blockBuffer = gl::Buffer("depth_impostors.blocks", nb * sizeof(gpu::ImpostorBlock));
  orderBuffer = gl::Buffer("depth_impostors.order", nb * sizeof(int));
  const int w = std::max(1, layout_.width()), h = std::max(1, layout_.height());
  front = gl::Texture("depth_impostors.front", GL_TEXTURE_2D, GL_R32F, w, h);
  back = gl::Texture("depth_impostors.back", GL_TEXTURE_2D, GL_R32F, w, h);
  transmittance = gl::Texture("depth_impostors.transmittance", GL_TEXTURE_2D, GL_R32F, w, h);
  lightTransmittance = gl::Texture("depth_impostors.light_transmittance", GL_TEXTURE_2D, GL_R32F, w, h);
  for (gl::Texture* t : {&front, &back, &transmittance, &lightTransmittance}) t->setFilter(GL_NEAREST, GL_NEAREST);
  viewFb_ = gl::Framebuffer("depth_impostors.view");
  viewFb_.attach(GL_COLOR_ATTACHMENT0, front);
  viewFb_.attach(GL_COLOR_ATTACHMENT1, back);
  viewFb_.attach(GL_COLOR_ATTACHMENT2, transmittance);
  viewFb_.setDrawBuffers({GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2});
  viewFb_.checkComplete("ImpostorSet (view)");
  lightFb_ = gl::Framebuffer("depth_impostors.light");
  lightFb_.attach(GL_COLOR_ATTACHMENT2, lightTransmittance);
  if (fourierTerms_ > 0) {
    lightFront = gl::Texture("depth_impostors.light_front", GL_TEXTURE_2D, GL_R32F, w, h);
    lightBack = gl::Texture("depth_impostors.light_back", GL_TEXTURE_2D, GL_R32F, w, h);
    for (gl::Texture* t : {&lightFront, &lightBack}) t->setFilter(GL_NEAREST, GL_NEAREST);
    lightFb_.attach(GL_COLOR_ATTACHMENT0, lightFront);
    lightFb_.attach(GL_COLOR_ATTACHMENT1, lightBack);
    lightFb_.setDrawBuffers({GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2});
  } else {
    lightFb_.setDrawBuffers({GL_NONE, GL_NONE, GL_COLOR_ATTACHMENT2});
  }
  lightFb_.checkComplete("ImpostorSet (light)");
  sliceFb_ = gl::Framebuffer("depth_impostors.slices");
  for (int i = 0; i < 4; ++i) {
    sliceTextures[i] = gl::Texture("depth_impostors.slices", GL_TEXTURE_2D, GL_RGBA32F, sliceRes_, sliceRes_);
    sliceTextures[i].setFilter(GL_LINEAR, GL_LINEAR);
    sliceTextures[i].setWrap(GL_CLAMP_TO_EDGE);
    sliceFb_.attach(GL_COLOR_ATTACHMENT0 + i, sliceTextures[i]);
  }
  sliceFb_.setDrawBuffers({GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2, GL_COLOR_ATTACHMENT3});
  sliceFb_.checkComplete("ImpostorSet (slices)");
  vao_ = gl::VertexArray("depth_impostors");
}

void ImpostorSet::drawImpostors(gl::ShaderLibrary& shaders, const ImpostorAxis& axis, gl::Framebuffer& fb) {
  fb.bind();
  glViewport(0, 0, layout_.width(), layout_.height());
  const float far[4] = {1e30f, 0.f, 0.f, 0.f}, near[4] = {-1e30f, 0.f, 0.f, 0.f}, one[4] = {1.f, 1.f, 1.f, 1.f};
  if (&fb == &viewFb_ || fourierTerms_ > 0) {
    glClearNamedFramebufferfv(fb.id(), GL_COLOR, 0, far);
    glClearNamedFramebufferfv(fb.id(), GL_COLOR, 1, near);
  }
  glClearNamedFramebufferfv(fb.id(), GL_COLOR, 2, one);
  glEnable(GL_BLEND);
  glBlendEquationi(0, GL_MIN);
  glBlendEquationi(1, GL_MAX);
  glBlendEquationi(2, GL_FUNC_ADD);
  glBlendFunci(2, GL_ZERO, GL_ONE_MINUS_SRC_COLOR);  // T = T (1 - alpha)
  const gl::Program& prog = shaders.program({"depth_impostors/impostor.vert", "depth_impostors/impostor.frag"});
  prog.use();
  prog.set("u_axisMode", axis.mode);
  prog.set("u_axis", &axis.axis.x, 3);
  prog.set("u_res", layout_.res);
  prog.set("u_tilesX", layout_.tilesX);
  const float size[2] = {float(layout_.width()), float(layout_.height())};
  prog.set("u_atlasSize", size, 2);
  if (!blocks_.particles.empty())
    glDrawArraysInstanced(GL_TRIANGLES, 0, 6, static_cast<GLsizei>(blocks_.particles.size()));
  glBlendEquation(GL_FUNC_ADD);
  glBlendFunc(GL_ONE, GL_ZERO);
  glDisable(GL_BLEND);
}

void ImpostorSet::build(gl::ShaderLibrary& shaders, const ImpostorAxis& view, const ImpostorAxis* light,
                        const SliceFrame& frame) {
  frame_ = frame;
  gpuBlocks_.clear();
  for (std::size_t i = 0; i < blocks_.blocks.size(); ++i) {
    const Block& b = blocks_.blocks[i];
    gpuBlocks_.push_back({glm::vec4(b.center, b.radius), glm::vec4(b.source, 0.f), glm::vec4(b.albedo, b.g),
                          glm::ivec4(b.tile >= 0 ? b.tile : static_cast<int>(i), b.phaseModel, frame.group(b.center), b.count)});
  }
  if (!gpuBlocks_.empty()) blockBuffer.upload(gpuBlocks_.data(), gpuBlocks_.size() * sizeof(gpu::ImpostorBlock));
  vao_.bind();
  glDisable(GL_DEPTH_TEST);
  glDepthMask(GL_FALSE);
  glDisable(GL_CULL_FACE);
  particleBuffer.bindBase(GL_SHADER_STORAGE_BUFFER, gpu::kBindingMediaParticles);
  blockBuffer.bindBase(GL_SHADER_STORAGE_BUFFER, gpu::kBindingImpostorBlocks);

  // 1. View impostors: front MIN, back MAX, transmittance multiplied (thesis Fig. 8.1).
  drawImpostors(shaders, view, viewFb_);

  // 2. Light impostors and the slices (cleared to 1; blended dst (1 - src), in any order), or the
  // Fourier coefficients (cleared to 0; added, in any order).
  const bool fourier = fourierTerms_ > 0;
  const float one[4] = {1.f, 1.f, 1.f, 1.f}, zero[4] = {0.f, 0.f, 0.f, 0.f};
  for (int i = 0; i < 4; ++i) glClearNamedFramebufferfv(sliceFb_.id(), GL_COLOR, i, fourier ? zero : one);
  if (light && !gpuBlocks_.empty()) {
    drawImpostors(shaders, *light, lightFb_);
    sliceFb_.bind();
    glViewport(0, 0, sliceRes_, sliceRes_);
    glEnable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
    if (fourier) glBlendFunc(GL_ONE, GL_ONE);
    else glBlendFuncSeparate(GL_ZERO, GL_ONE_MINUS_SRC_COLOR, GL_ZERO, GL_ONE_MINUS_SRC_ALPHA);
    lightTransmittance.bindUnit(0);
    if (fourier) lightFront.bindUnit(1), lightBack.bindUnit(2);
    const gl::Program& prog = shaders.program({"depth_impostors/slices.vert", "depth_impostors/slices.frag"});
    prog.use();
    prog.set("u_sliceCenter", &frame.center.x, 3);
    prog.set("u_sliceU", &frame.u.x, 3);
    prog.set("u_sliceV", &frame.v.x, 3);
    prog.set("u_sliceHalf", frame.halfSize);
    prog.set("u_axisMode", light->mode);
    prog.set("u_axis", &light->axis.x, 3);
    prog.set("u_res", layout_.res);
    prog.set("u_tilesX", layout_.tilesX);
    prog.set("u_slices", slices_);
    prog.set("u_fourierTerms", fourierTerms_);
    prog.set("u_sliceAxis", &frame.axis.x, 3);
    prog.set("u_zNear", frame.zNear);
    prog.set("u_zFar", frame.zFar);
    glDrawArraysInstanced(GL_TRIANGLES, 0, 6, static_cast<GLsizei>(gpuBlocks_.size()));
    glDisable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ZERO);
  }
  glDepthMask(GL_TRUE);
  gl::checkError("ImpostorSet::build");
  built = true;
}

std::vector<float> ImpostorSet::downloadSlices() const {
  const std::size_t n = static_cast<std::size_t>(sliceRes_) * sliceRes_;
  const int channels = this->channels();
  std::vector<float> rgba(n * 4), out(n * channels);
  for (int t = 0; t * 4 < channels; ++t) {
    sliceTextures[t].download(0, GL_RGBA, GL_FLOAT, rgba.data(), rgba.size() * sizeof(float));
    for (int c = 0; c < 4 && t * 4 + c < channels; ++c)
      for (std::size_t p = 0; p < n; ++p) out[(t * 4 + c) * n + p] = rgba[p * 4 + c];
  }
  return out;
}

void ImpostorSet::downloadView(std::vector<float>& f, std::vector<float>& b, std::vector<float>& t) const {
  const std::size_t n = static_cast<std::size_t>(std::max(1, layout_.width())) * std::max(1, layout_.height());
  f.resize(n), b.resize(n), t.resize(n);
  front.download(0, GL_RED, GL_FLOAT, f.data(), n * sizeof(float));
  back.download(0, GL_RED, GL_FLOAT, b.data(), n * sizeof(float));
  transmittance.download(0, GL_RED, GL_FLOAT, t.data(), n * sizeof(float));
}

}  // namespace radiant::impostors
