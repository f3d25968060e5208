#include "renderer/techniques/depth_impostors/DepthImpostors.h"
#include "params/depth_impostors_params.h"

#include <algorithm>
#include <limits>
#include <numeric>

#include "renderer/frame/FrameResources.h"
#include "renderer/frame/FrameView.h"
#include "renderer/frame/PassContext.h"
#include "renderer/shading/MediaLayer.h"
#include "renderer/shading/Stretches.h"
#include "renderer/shading/GBufferInputs.h"

namespace radiant {
namespace {
constexpr int kBlocksPerStretch = 256;  // block impostors drawn between two cancel checks (each gathers its slices: heavier than a billboard)
}  // namespace

const TechniqueInfo& DepthImpostorsPass::info() const {
  static const TechniqueInfo i = describedTechnique("depth_impostors");
  return i;
}

Requirements DepthImpostorsPass::requirements(const Scene& scene, const api::RenderRequest& request) const {
  return mediaRequirements(scene, request);
}

GroundTruth DepthImpostorsPass::groundTruth(const Params&, const std::string& aov) const {
  if (aov == "media") return {nlohmann::json{{"aov", "media"}, {"media_mode", "single_scatter"}}};
  return GroundTruth::fromAovTable(aov);
}

std::size_t DepthImpostorsPass::blockCount(const std::vector<api::ParticleSystem>& media, int particlesPerBlock) {
  const std::size_t b = static_cast<std::size_t>(std::max(1, particlesPerBlock));  // as buildBlocks
  std::size_t blocks = 0;
  for (const api::ParticleSystem& s : media) blocks += (mediaParticleCount(s) + b - 1) / b;
  return blocks;
}

impostors::AtlasLayout DepthImpostorsPass::fittedAtlas(std::size_t blocks, int requestedRes) {
  const impostors::AtlasLayout layout =
      impostors::atlasLayout(static_cast<int>(std::min<std::size_t>(blocks, std::numeric_limits<int>::max())), requestedRes);
  if (blocks > 0 && layout.res == 0)
    throw api::ApiError(422, "out-of-range", "Too many blocks",
                        std::to_string(blocks) + " blocks do not fit the impostor atlas (" +
                            std::to_string(impostors::AtlasLayout::kMaxAtlas) + " texels a side, tiles of at least " +
                            std::to_string(impostors::AtlasLayout::kMinRes) + "); raise particles_per_block",
                        "/passes/depth_impostors/particles_per_block");
  return layout;
}

void DepthImpostorsPass::validate(const Scene&, const FrameView& view, const Params& params) const {
  const DepthImpostorsParams p = DepthImpostorsParams::from(params);
  fittedAtlas(blockCount(view.media, p.particles_per_block), p.impostor_resolution);
}

void DepthImpostorsPass::prepare(const Scene& scene, const Params& params, FrameResources& res) {
  const DepthImpostorsParams p = DepthImpostorsParams::from(params);
  const FrameView& view = res.view();
  particlesPerBlock_ = p.particles_per_block;
  requestedRes_ = p.impostor_resolution;
  const int K = p.slices;
  const int sliceRes = p.slice_resolution;
  clipScaling_ = p.clip_scaling == DepthImpostorsParams::ClipScaling::kLinear ? 0 : 1;
  forwardScatter_ = p.forward_scatter ? 1 : 0;
  fourierTerms_ = p.light_transmittance == DepthImpostorsParams::LightTransmittance::kFourier ? p.fourier_terms : 0;
  const glm::vec3 forward = viewForward(view);
  const bool ortho = view.camera.projection == ProjectionType::Orthographic;

  // Blocks: the medium, b and the sky (the blocks' source holds albedo * ambient) only: a sweep over the
  // other knots, the camera or the light reuses them.
  const std::string blockKey = view.mediaKey + "|b=" + std::to_string(particlesPerBlock_) + "|ambient=" +
                               nlohmann::json::array({view.ambient.x, view.ambient.y, view.ambient.z}).dump();
  const impostors::BlockSet& blocks = res.cached<impostors::BlockSet>("depth_impostors.blocks", blockKey, [&] {
    std::vector<int> systemOf;
    const auto particles =
        mediaParticles(view.media, view.ambient, view.eye, forward, ortho, false, &systemOf);
    return std::make_unique<impostors::BlockSet>(impostors::buildBlocks(particles, systemOf, particlesPerBlock_));
  });
  const impostors::AtlasLayout layout = fittedAtlas(blocks.blocks.size(), requestedRes_);

  // The view axis and the shadowed light (the first punctual light).
  viewAxis_ = ortho ? impostors::ImpostorAxis{0, forward} : impostors::ImpostorAxis{1, view.eye};
  hasLight_ = !scene.lights.empty() && !blocks.blocks.empty();
  glm::vec3 lo(1e30f), hi(-1e30f);
  for (const auto& b : blocks.blocks) lo = glm::min(lo, b.center - b.radius), hi = glm::max(hi, b.center + b.radius);
  glm::vec3 sliceAxis(0.f, -1.f, 0.f);
  if (hasLight_) {
    const Light& l = scene.lights.front();
    if (l.type == LightType::Directional) {
      lightAxis_ = {0, glm::normalize(l.direction)};
      sliceAxis = lightAxis_.axis;
    } else {
      lightAxis_ = {1, l.position};
      const glm::vec3 toCenter = 0.5f * (lo + hi) - l.position;
      sliceAxis = glm::length(toCenter) > 0.f ? glm::normalize(toCenter) : glm::vec3(0.f, -1.f, 0.f);
    }
  }
  frame_ = impostors::fitSliceFrame(blocks.blocks, sliceAxis, K);

  // Impostors and slices: everything they are drawn from.
  auto f3 = [](const glm::vec3& v) { return nlohmann::json::array({v.x, v.y, v.z}); };
  const nlohmann::json key = {{"blocks", blockKey},
                              {"res", layout.res},
                              {"slices", K},
                              {"fourier_terms", fourierTerms_},
                              {"slice_res", sliceRes},
                              {"view", {viewAxis_.mode, f3(viewAxis_.axis)}},
                              {"light", hasLight_ ? nlohmann::json{lightAxis_.mode, f3(lightAxis_.axis), f3(sliceAxis)}
                                                  : nlohmann::json(nullptr)}};
  set_ = &res.cached<impostors::ImpostorSet>("depth_impostors.impostors", key.dump(), [&] {
    return std::make_unique<impostors::ImpostorSet>(blocks, layout, K, sliceRes, fourierTerms_);
  });

  // Back to front (a few thousand blocks at most: sorted on the CPU every frame).
  order_.resize(blocks.blocks.size());
  std::iota(order_.begin(), order_.end(), 0);
  std::vector<float> dist(blocks.blocks.size());
  for (std::size_t i = 0; i < dist.size(); ++i)
    dist[i] = ortho ? glm::dot(blocks.blocks[i].center - view.eye, forward) : glm::length(blocks.blocks[i].center - view.eye);
  std::stable_sort(order_.begin(), order_.end(), [&](int a, int b) { return dist[a] > dist[b]; });

  if (vao_.id() == 0) vao_ = gl::VertexArray("depth_impostors.gather");
  declareMediaLayer(res, view.width, view.height);
}

void DepthImpostorsPass::execute(PassContext& ctx) {
  FrameResources& res = ctx.resources;
  const FrameView& view = ctx.view;
  impostors::ImpostorSet& set = *set_;
  const bool rebuilt = !set.built;
  if (rebuilt) set.build(ctx.shaders, viewAxis_, hasLight_ ? &lightAxis_ : nullptr, frame_);
  const int blocks = static_cast<int>(set.blocks().blocks.size());
  if (blocks > 0) set.orderBuffer.upload(order_.data(), order_.size() * sizeof(int));
  const bool hasDepth = gbuffer::written(res, gbuffer::Attachment::Position);

  beginMediaLayer(res.framebuffer("media"), view.width, view.height);
  vao_.bind();
  if (hasDepth) gbuffer::bind(res, {gbuffer::Attachment::Position});
  set.front.bindUnit(1);
  set.back.bindUnit(2);
  set.transmittance.bindUnit(3);
  const int sliceUnits[4] = {4, 5, gpu::kUnitImpostorSlices2, gpu::kUnitImpostorSlices3};
  for (int i = 0; i < 4; ++i) set.sliceTextures[i].bindUnit(sliceUnits[i]);
  set.blockBuffer.bindBase(GL_SHADER_STORAGE_BUFFER, gpu::kBindingImpostorBlocks);
  set.orderBuffer.bindBase(GL_SHADER_STORAGE_BUFFER, gpu::kBindingImpostorOrder);
  ctx.gpu.lights.bindBase(GL_SHADER_STORAGE_BUFFER, gpu::kBindingLights);
  const gl::Program& prog = ctx.shaders.program({"depth_impostors/gather.vert", "depth_impostors/gather.frag"});
  prog.use();
  setMediaCameraUniforms(prog, view, hasDepth, view.width, view.height);
  prog.set("u_axisMode", viewAxis_.mode);
  prog.set("u_axis", &viewAxis_.axis.x, 3);
  prog.set("u_res", set.layout().res);
  prog.set("u_tilesX", set.layout().tilesX);
  prog.set("u_clipScaling", clipScaling_);
  prog.set("u_lightCount", static_cast<int>(ctx.scene.lights.size()));
  prog.set("u_shadowedLight", hasLight_ ? 0 : -1);
  const impostors::SliceFrame& f = set.frame();
  prog.set("u_slices", set.slices());
  prog.set("u_sliceCenter", &f.center.x, 3);
  prog.set("u_sliceAxis", &f.axis.x, 3);
  prog.set("u_sliceU", &f.u.x, 3);
  prog.set("u_sliceV", &f.v.x, 3);
  prog.set("u_sliceHalf", f.halfSize);
  prog.set("u_sliceDmin", f.dmin);
  prog.set("u_sliceDmax", f.dmax);
  prog.set("u_forwardScatter", forwardScatter_);
  prog.set("u_sliceTexel", 1.f / static_cast<float>(set.sliceResolution()));
  prog.set("u_fourierTerms", set.fourierTerms());
  prog.set("u_fourierNear", f.zNear);
  prog.set("u_fourierFar", f.zFar);
  for (int k = 1; k <= set.fourierTerms(); ++k)
    prog.set(("u_fourierDamping[" + std::to_string(k - 1) + "]").c_str(),
             static_cast<float>(impostors::fourierDamping(k, set.fourierTerms())));
  drawInstancedInStretches(prog, GL_TRIANGLES, 6, blocks, kBlocksPerStretch, ctx.cancel, "depth_impostors' gather");
  glDisable(GL_BLEND);
  res.markWritten("media");
  res.markWritten("media_transmittance");
  composeMediaIntoBeauty(ctx);

  ctx.stats.counters["particles"] = static_cast<double>(set.blocks().particles.size());
  ctx.stats.counters["blocks"] = blocks;
  ctx.stats.counters["particles_per_block"] = particlesPerBlock_;
  ctx.stats.counters["impostor_resolution"] = set.layout().res;  // may be below the requested one (atlas limit)
  ctx.stats.counters["slices"] = set.fourierTerms() > 0 ? 0 : set.slices();
  ctx.stats.counters["fourier_terms"] = set.fourierTerms();
  ctx.stats.counters["light_channels"] = set.channels();  // slice-texture channels in use: K or 2M + 1
  ctx.stats.counters["shadowed_lights"] = hasLight_ ? 1 : 0;
  ctx.stats.counters["impostors_rebuilt"] = rebuilt ? 1 : 0;
}

}  // namespace radiant
