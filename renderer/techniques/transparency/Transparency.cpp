#include "renderer/techniques/transparency/Transparency.h"
#include "params/transparency_params.h"

#include <algorithm>
#include <numeric>

#include "renderer/frame/Beauty.h"
#include "renderer/frame/GpuTypes.h"
#include "renderer/frame/PassContext.h"
#include "renderer/shading/DirectLighting.h"
#include "renderer/shading/ImageBasedLighting.h"

namespace radiant {

const TechniqueInfo& TransparencyPass::info() const {
  static const TechniqueInfo i = describedTechnique("transparency");
  return i;
}

Requirements TransparencyPass::requirements(const Scene& scene, const api::RenderRequest&) const {
  for (const MeshInstance& m : scene.meshes)
    if (scene.material(m.material).alphaMode == AlphaMode::Blend) return Requirements::ok();
  return Requirements::skip("no alphaMode BLEND material");
}

void TransparencyPass::prepare(const Scene&, const Params& params, FrameResources& res) {
  const TransparencyParams p = TransparencyParams::from(params);
  pcfRadius_ = p.pcf_radius;
  const int w = res.view().width, h = res.view().height;
  gl::Framebuffer& fb = res.framebuffer("transparency");
  attachBeauty(res, fb, GL_COLOR_ATTACHMENT0);
  fb.attach(GL_DEPTH_ATTACHMENT, res.texture("depth_buffer", GL_TEXTURE_2D, GL_DEPTH_COMPONENT32F, w, h));
  fb.setDrawBuffers({GL_COLOR_ATTACHMENT0});
  fb.checkComplete("TransparencyPass::prepare");
  declareDirectLightingResources(res);
  ibl::prepare(res);
}

void TransparencyPass::execute(PassContext& ctx) {
  FrameResources& res = ctx.resources;
  const auto& view = ctx.view;
  const GpuScene& gpu = ctx.gpu;
  // Back to front: the view depth of each BLEND primitive's bounding-box centre (the over operator is
  // not commutative). Primitives that interpenetrate, and triangles within one primitive, are not
  // sorted among themselves (docs/TECHNIQUES.md).
  const glm::vec3 forward = viewForward(view);
  std::vector<std::size_t> order;
  std::vector<float> depth(ctx.scene.meshes.size(), 0.f);
  for (std::size_t i = 0; i < ctx.scene.meshes.size() && i < gpu.meshes.size(); ++i) {
    const MeshInstance& m = ctx.scene.meshes[i];
    if (ctx.scene.material(m.material).alphaMode != AlphaMode::Blend) continue;
    depth[i] = glm::dot(m.bounds.center() - view.eye, forward);
    order.push_back(i);
  }
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return depth[a] > depth[b]; });

  gl::Framebuffer& fb = res.framebuffer("transparency");
  fb.bind();
  glViewport(0, 0, view.width, view.height);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_GREATER);  // reversed-Z: in front of the opaque surface
  glDepthMask(GL_FALSE);
  glDisable(GL_CULL_FACE);  // single-sided back faces are discarded in the shader (glTF semantics)
  // Its declared blend, over: rgb = a Ls + (1 - a) beauty; beauty's alpha stays as the opaque passes left it.
  BeautyWrite beauty = BeautyWrite::drawBuffer(res, 0);

  const gl::Program& prog = ctx.shaders.program({"gbuffer/gbuffer.vert", "transparency/transparency.frag"});
  prog.use();
  bindDirectLighting(prog, res, gpu, static_cast<int>(ctx.view.lights.size()), pcfRadius_);
  ibl::bind(res, prog, gpu::kUnitIblDfg, gpu::kUnitIblPrefiltered);
  prog.set("u_diffuseIbl", 1);
  const GLint materialLoc = prog.uniformLocation("u_material");
  for (std::size_t i : order) {
    const GpuMesh& m = gpu.meshes[i];
    glProgramUniform1i(prog.id(), materialLoc, m.material);
    gpu.bindMaterialTextures(i);
    m.vao.bind();
    glDrawElements(GL_TRIANGLES, m.indexCount, GL_UNSIGNED_INT, nullptr);
  }
  beauty.commit();
  glDepthMask(GL_TRUE);
  glDisable(GL_DEPTH_TEST);
  ctx.stats.counters["blended_primitives"] = static_cast<double>(order.size());
}

}  // namespace radiant
