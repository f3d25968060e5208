#include "renderer/techniques/gbuffer/GBuffer.h"

#include "renderer/frame/PassContext.h"
#include "renderer/shading/GBufferInputs.h"

namespace radiant {

const TechniqueInfo& GBufferPass::info() const {
  static const TechniqueInfo i = describedTechnique("gbuffer");
  return i;
}

Requirements GBufferPass::requirements(const Scene& scene, const api::RenderRequest&) const {
  const SceneFeatures& f = scene.features;
  return f.triangles > 0 ? Requirements::ok() : Requirements::skip("the scene has no triangles");
}

void GBufferPass::prepare(const Scene&, const Params&, FrameResources& res) {
  const int w = res.view().width, h = res.view().height;
  gl::Framebuffer& fb = res.framebuffer("gbuffer");
  fb.attach(GL_DEPTH_ATTACHMENT, res.texture("depth_buffer", GL_TEXTURE_2D, GL_DEPTH_COMPONENT32F, w, h));
  // The attachments in gbuffer::Attachment order, the colour attachments of shaders/gbuffer/gbuffer.frag.
  for (std::size_t i = 0; i < std::size(gbuffer::kAttachments); ++i) {
    const gbuffer::Attachment a = gbuffer::kAttachments[i];
    gl::Texture& t = res.texture(gbuffer::name(a), GL_TEXTURE_2D, gbuffer::format(a), w, h);
    t.setFilter(GL_NEAREST, GL_NEAREST);
    fb.attach(GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(i), t);
  }
  fb.setDrawBuffers({GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2, GL_COLOR_ATTACHMENT3,
                     GL_COLOR_ATTACHMENT4, GL_COLOR_ATTACHMENT5, GL_COLOR_ATTACHMENT6, GL_COLOR_ATTACHMENT7});
  fb.checkComplete("GBufferPass::prepare");
}

void GBufferPass::execute(PassContext& ctx) {
  const auto& view = ctx.view;
  gl::Framebuffer& fb = ctx.resources.framebuffer("gbuffer");
  fb.bind();
  glViewport(0, 0, view.width, view.height);
  const float zero[4] = {0.f, 0.f, 0.f, 0.f};
  const GLuint zeroU[4] = {0u, 0u, 0u, 0u};
  for (int i = 0; i < static_cast<int>(std::size(gbuffer::kAttachments)); ++i) {
    // The layers target is an integer one (cleared with the integer clear).
    if (gbuffer::kAttachments[i] == gbuffer::Attachment::Layers) glClearNamedFramebufferuiv(fb.id(), GL_COLOR, i, zeroU);
    else glClearNamedFramebufferfv(fb.id(), GL_COLOR, i, zero);
  }
  const float depthClear = 0.f;  // reversed-Z: 0 is infinitely far
  glClearNamedFramebufferfv(fb.id(), GL_DEPTH, 0, &depthClear);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_GREATER);
  glDepthMask(GL_TRUE);
  glDisable(GL_BLEND);

  // Three groups: opaque single-sided materials through the shader variant that cannot discard, with
  // back faces culled (glTF: they are not rendered; culling and gl_FrontFacing decide facing alike);
  // opaque double-sided ones through the same variant; MASK and BLEND ones through the full shader,
  // which discards their cut-out texels, BLEND surfaces (the transparency pass's) and single-sided back
  // faces. A shader that can discard loses the early depth test, and llvmpipe then shades every layer.
  const gl::Program& opaqueProg =
      ctx.shaders.program({"gbuffer/gbuffer.vert", "gbuffer/gbuffer.frag"}, {{"OPAQUE", "1"}});
  const gl::Program& fullProg = ctx.shaders.program({"gbuffer/gbuffer.vert", "gbuffer/gbuffer.frag"});
  auto material = [&](std::size_t m) -> const Material& { return ctx.scene.material(ctx.scene.meshes[m].material); };
  enum Group { kSingleSided, kDoubleSided, kAlpha };
  auto groupOf = [&](std::size_t m) {
    const Material& mat = material(m);
    if (mat.alphaMode != AlphaMode::Opaque) return kAlpha;
    return mat.doubleSided ? kDoubleSided : kSingleSided;
  };
  for (const Group g : {kSingleSided, kDoubleSided, kAlpha}) {
    const gl::Program& prog = g == kAlpha ? fullProg : opaqueProg;
    prog.use();
    if (g == kSingleSided) {
      glEnable(GL_CULL_FACE);
      glCullFace(GL_BACK);
    } else {
      glDisable(GL_CULL_FACE);
    }
    ctx.gpu.drawMeshes(prog, true, [&](std::size_t m) { return groupOf(m) == g; });
  }
  glDisable(GL_CULL_FACE);
  ctx.stats.counters["triangles"] = static_cast<double>(ctx.gpu.triangles);
  for (const auto& out : info().outputs) ctx.resources.markWritten(out);
}

}  // namespace radiant
