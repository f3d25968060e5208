#include "renderer/shading/Denoiser.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "renderer/gl/ShaderLibrary.h"
#include "renderer/shading/GBufferInputs.h"

namespace radiant::denoise {

void declareResources(FrameResources& res) {
  const int w = res.view().width, h = res.view().height;
  for (const char* name : {"denoise_a", "denoise_b"})
    res.texture(name, GL_TEXTURE_2D, GL_RGBA32F, w, h).setFilter(GL_NEAREST, GL_NEAREST);
}

gl::Texture& run(FrameResources& res, gl::ShaderLibrary& shaders, const FrameView& view, const gl::Texture& in,
                 const Settings& s) {
  gl::Texture* ping = &res.texture("denoise_a");
  gl::Texture* pong = &res.texture("denoise_b");
  const gl::Program& prog = shaders.program({"common/denoise_atrous.comp"});
  prog.use();
  const int size[2] = {view.width, view.height};
  glUniform2iv(glGetUniformLocation(prog.id(), "u_size"), 1, size);
  // The world size of a pixel: at view depth 1 (perspective) or everywhere (orthographic).
  const bool ortho = view.camera.projection == ProjectionType::Orthographic;
  prog.set("u_pixelAngle", ortho ? 0.f : 2.f * std::tan(0.5f * view.camera.yfov) / static_cast<float>(view.height));
  prog.set("u_orthoPixel", ortho ? 2.f * view.camera.ymag / static_cast<float>(view.height) : 0.f);
  prog.set("u_sigmaLuminance", s.sigmaLuminance * s.relativeNoise);
  prog.set("u_sigmaNormal", s.sigmaNormal);
  prog.set("u_sigmaPlane", s.sigmaPlane);
  prog.set("u_minAlbedo", kMinAlbedo);
  // Unit 0 is each pass's input: the guides one unit up (denoise_atrous.comp).
  gbuffer::bindAt(res, gbuffer::Attachment::Position, 1);
  gbuffer::bindAt(res, gbuffer::Attachment::Normal, 2);
  gbuffer::bindAt(res, gbuffer::Attachment::Albedo, 3);
  in.bindUnit(4);  // the noisy radiance: the first pass demodulates it; every pass keeps it as a fallback
  const int iterations = std::max(1, s.iterations);
  const gl::Texture* src = &in;
  for (int i = 0; i < iterations; ++i) {
    src->bindUnit(0);
    ping->bindImage(0, GL_WRITE_ONLY);
    prog.set("u_step", std::max(1, s.baseStep) << i);
    prog.set("u_first", i == 0 ? 1 : 0);
    prog.set("u_last", i + 1 == iterations ? 1 : 0);
    glDispatchCompute((view.width + 7) / 8, (view.height + 7) / 8, 1);
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    src = ping;
    std::swap(ping, pong);
  }
  return *pong;  // the last one written
}

}  // namespace radiant::denoise
