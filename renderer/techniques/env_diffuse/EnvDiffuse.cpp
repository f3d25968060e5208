#include "renderer/techniques/env_diffuse/EnvDiffuse.h"
#include "params/env_diffuse_params.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <set>

#include <glm/gtc/type_ptr.hpp>

#include "renderer/frame/Beauty.h"
#include "renderer/frame/FrameView.h"
#include "renderer/frame/PassContext.h"
#include "renderer/shading/DirectLighting.h"
#include "renderer/shading/CubeFaces.h"
#include "renderer/shading/Stretches.h"
#include "renderer/shading/GBufferInputs.h"

namespace radiant {
namespace {

// std430 mirror of EnvQuad in shaders/env_diffuse/gather.glsl.
struct EnvQuad {
  glm::vec4 corner[4];
  glm::vec4 radiance;
  glm::vec4 vplPosition;
  glm::vec4 vplNormalArea;
};
static_assert(sizeof(EnvQuad) == 112, "std430 EnvQuad must be 7 vec4");


constexpr GLuint kQuadBinding = 4;

bool isPowerOfTwoIn(int v, int lo, int hi) { return v >= lo && v <= hi && (v & (v - 1)) == 0; }

[[noreturn]] void badParam(const std::string& key, const std::string& detail) {
  throw api::ApiError(422, "invalid-value", "Invalid env_diffuse parameter", detail, "/passes/env_diffuse/" + key);
}

GLuint groups(int n) { return static_cast<GLuint>((n + 7) / 8); }

}  // namespace

const TechniqueInfo& EnvDiffusePass::info() const {
  static const TechniqueInfo i = describedTechnique("env_diffuse");
  return i;
}

Requirements EnvDiffusePass::requirements(const Scene& scene, const api::RenderRequest& request) const {
  const SceneFeatures& f = scene.features;
  if (f.triangles == 0) return Requirements::skip("the scene has no triangles");
  if (f.lightCount() == 0 && !f.hasEmissive() && request.ambient == glm::vec3(0.f) && request.environment.empty())
    return Requirements::skip("nothing lights the environment: no lights, no emissive surfaces, no ambient");
  // Receivers named in the request are checked in prepare() (an unknown name is a 422 there); by the
  // default rule a scene may have none, and then there is nothing to do.
  auto given = request.passes.find("env_diffuse");
  const bool named = given != request.passes.end() && given->second.is_object() &&
                     !given->second.value("receivers", std::string()).empty();
  if (!named && env_diffuse::selectReceivers(scene, "", "").empty())
    return Requirements::skip("no receivers: no node has extras.radiant_receiver and no object is compact and "
                              "small enough; name them with passes.env_diffuse.receivers");
  return Requirements::ok();
}

void EnvDiffusePass::validate(const Scene& scene, const FrameView&, const Params& params) const {
  const EnvDiffuseParams p = EnvDiffuseParams::from(params);
  const int R = p.cube_resolution, M = p.downsample, bounces = p.bounces;
  if (!isPowerOfTwoIn(R, 16, 1024)) badParam("cube_resolution", "must be a power of two in [16, 1024]");
  if (!isPowerOfTwoIn(M, 1, 16) || M > R) badParam("downsample", "must be 1, 2, 4, 8 or 16 and at most cube_resolution");
  if (bounces < 1 || bounces > 4) badParam("bounces", "must be in [1, 4]");
  // Every named receiver and reference point exists (422 at receivers / reference_points).
  env_diffuse::selectReceivers(scene, p.receivers, p.reference_points);
}

void EnvDiffusePass::prepare(const Scene& scene, const Params& params, FrameResources& res) {
  const EnvDiffuseParams p = EnvDiffuseParams::from(params);
  cubeResolution_ = p.cube_resolution;
  downsample_ = p.downsample;
  bounces_ = p.bounces;
  horizonClip_ = p.horizon_clip;
  // The sky seen by a receiver is direct light from the environment (one scattering event), which
  // ambient_occlusion adds, with occlusion, whenever there is ambient light. The cube maps therefore
  // hold only what surfaces send, so indirect_diffuse is exactly the reference's "indirect" (two or
  // more events) and nothing is counted twice; include_sky puts the sky back for use without AO.
  skyRadiance_ = p.include_sky ? res.view().ambient : glm::vec3(0.f);
  // validate() has checked the parameters and the receivers.
  using FormFactor = EnvDiffuseParams::FormFactor;
  method_ = p.form_factor == FormFactor::kPolygon ? kPolygon : p.form_factor == FormFactor::kPoint ? kPoint : kClassic;

  const std::vector<env_diffuse::Receiver> selected =
      env_diffuse::selectReceivers(scene, p.receivers, p.reference_points);

  const int R = cubeResolution_, M = downsample_, S = std::min(kConvolutionSourceSize, R);
  res.texture("env_diffuse_radiance_hi", GL_TEXTURE_CUBE_MAP, GL_RGBA32F, R, R).setFilter(GL_NEAREST, GL_NEAREST);
  res.texture("env_diffuse_geometry_hi", GL_TEXTURE_CUBE_MAP, GL_RGBA32F, R, R).setFilter(GL_NEAREST, GL_NEAREST);
  res.texture("env_diffuse_depth", GL_TEXTURE_2D, GL_DEPTH_COMPONENT32F, R, R);
  res.texture("env_diffuse_conv_radiance", GL_TEXTURE_CUBE_MAP, GL_RGBA32F, S, S).setFilter(GL_NEAREST, GL_NEAREST);
  res.texture("env_diffuse_conv_geometry", GL_TEXTURE_CUBE_MAP, GL_RGBA32F, S, S).setFilter(GL_NEAREST, GL_NEAREST);
  res.framebuffer("env_diffuse_cube");
  declareDirectLightingResources(res);

  // Everything a receiver's maps depend on: geometry, materials and lights (scene digest and the GPU
  // copy it was uploaded to), the sky, the receiver and its reference point, the cube parameters, and
  // for extra bounces the form of the gathering that feeds them. Not the camera, not the method.
  const glm::vec3 sky = skyRadiance_;
  const std::string& sceneKey = res.sceneKey();
  receivers_.clear();
  for (const env_diffuse::Receiver& r : selected) {
    ReceiverState st;
    st.receiver = r;
    st.prefix = "env_diffuse:" + r.name + ":";
    res.texture(st.prefix + "radiance_lo", GL_TEXTURE_CUBE_MAP, GL_RGBA32F, M, M).setFilter(GL_NEAREST, GL_NEAREST);
    res.texture(st.prefix + "geometry_lo", GL_TEXTURE_CUBE_MAP, GL_RGBA32F, M, M).setFilter(GL_NEAREST, GL_NEAREST);
    res.texture(st.prefix + "irradiance", GL_TEXTURE_CUBE_MAP, GL_RGBA32F, kIrradianceSize, kIrradianceSize)
        .setFilter(GL_LINEAR, GL_LINEAR);
    res.buffer(st.prefix + "quads", static_cast<std::size_t>(6 * M * M) * sizeof(EnvQuad));
    char point[96];
    std::snprintf(point, sizeof point, "%.9g,%.9g,%.9g", r.referencePoint.x, r.referencePoint.y, r.referencePoint.z);
    char skyText[96];
    std::snprintf(skyText, sizeof skyText, "%.9g,%.9g,%.9g", sky.x, sky.y, sky.z);
    std::string digest = sceneKey + "|receiver:" + r.name + "|o:" + point + "|sky:" + skyText +
                         "|R:" + std::to_string(R) + "|M:" + std::to_string(M) + "|bounces:" + std::to_string(bounces_);
    if (bounces_ > 1) digest += std::string("|clip:") + (horizonClip_ ? "1" : "0");
    // The maps live in this receiver's shared textures (FrameResources::refill).
    st.maps = res.refill(st.prefix + "irradiance", std::move(digest), "env_diffuse_cube_maps:" + r.name);
    receivers_.push_back(std::move(st));
  }

  // Its output and beauty: allocated by the Renderer (renderer/frame/FrameAllocation.h).
  gl::Framebuffer& fb = res.framebuffer("env_diffuse");
  gl::Texture& indirect = res.texture("indirect_diffuse");
  indirect.setFilter(GL_NEAREST, GL_NEAREST);
  fb.attach(GL_COLOR_ATTACHMENT0, indirect);
  attachBeauty(res, fb, GL_COLOR_ATTACHMENT1);
  fb.setDrawBuffers({GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1});
  fb.checkComplete("EnvDiffusePass::prepare");
}

void EnvDiffusePass::buildCubeMaps(PassContext& ctx, const ReceiverState& st) {
  FrameResources& res = ctx.resources;
  const env_diffuse::Receiver& r = st.receiver;
  const int R = cubeResolution_, M = downsample_, S = std::min(kConvolutionSourceSize, R);
  const std::set<int> own(r.meshes.begin(), r.meshes.end());
  gl::Texture& radianceHi = res.texture("env_diffuse_radiance_hi");
  gl::Texture& geometryHi = res.texture("env_diffuse_geometry_hi");
  gl::Texture& radianceLo = res.texture(st.prefix + "radiance_lo");
  gl::Texture& geometryLo = res.texture(st.prefix + "geometry_lo");
  gl::Buffer& quads = res.buffer(st.prefix + "quads");
  gl::Framebuffer& fb = res.framebuffer("env_diffuse_cube");
  fb.attach(GL_DEPTH_ATTACHMENT, res.texture("env_diffuse_depth"));
  fb.setDrawBuffers({GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1});

  const gl::Program& cube = ctx.shaders.program({"env_diffuse/cube.vert", "env_diffuse/cube.frag"});
  const gl::Program& down = ctx.shaders.program({"env_diffuse/downsample.comp"});
  const gl::Program& build = ctx.shaders.program({"env_diffuse/quads.comp"});
  const float znear = std::max(ctx.scene.features.bounds.radius(), 1e-6f) * 1e-4f;
  const float sky[4] = {skyRadiance_.x, skyRadiance_.y, skyRadiance_.z, 1.f};
  const float far[4] = {std::numeric_limits<float>::infinity(), 0.f, 0.f, 0.f};
  const float depthClear = 0.f;

  auto downsampleTo = [&](gl::Texture& dstRadiance, gl::Texture& dstGeometry, int size) {
    down.use();
    radianceHi.bindImage(0, GL_READ_ONLY, 0, true);
    geometryHi.bindImage(1, GL_READ_ONLY, 0, true);
    dstRadiance.bindImage(2, GL_WRITE_ONLY, 0, true);
    dstGeometry.bindImage(3, GL_WRITE_ONLY, 0, true);
    down.set("u_srcSize", R);
    down.set("u_dstSize", size);
    glDispatchCompute(groups(size), groups(size), 6);
    glMemoryBarrier(GL_ALL_BARRIER_BITS);
  };

  // The faces are stretches of GPU work, each waited for before the next check (StretchGate): without the
  // wait llvmpipe queued every face and the check passed before the flag (a stop 0.8-4.7 s after it).
  StretchGate gate(ctx.cancel);
  for (int bounce = 1; bounce <= bounces_; ++bounce) {
    // 1. The six faces at full resolution: radiance toward o and distance from o (thesis 3.1).
    cube.use();
    bindDirectLighting(cube, res, ctx.gpu, static_cast<int>(ctx.scene.lights.size()), 1);
    quads.bindBase(GL_SHADER_STORAGE_BUFFER, kQuadBinding);
    cube.set("u_origin", glm::value_ptr(r.referencePoint), 3);
    cube.set("u_gatherPrevious", bounce > 1 ? 1 : 0);
    cube.set("u_quadCount", bounce > 1 ? 6 * M * M : 0);
    cube.set("u_horizonClip", horizonClip_ ? 1 : 0);
    glViewport(0, 0, R, R);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);
    glDepthMask(GL_TRUE);
    glDisable(GL_CULL_FACE);  // single-sided back faces are discarded in the shader (glTF semantics)
    glDisable(GL_BLEND);
    for (int face = 0; face < 6; ++face) {
      // A face (its meshes gathering the previous bounce's 6 M^2 quads) is one stretch of GPU work.
      gate.check("env_diffuse's cube maps, bounce " + std::to_string(bounce) + " face " + std::to_string(face));
      fb.attach(GL_COLOR_ATTACHMENT0, radianceHi, 0, face);
      fb.attach(GL_COLOR_ATTACHMENT1, geometryHi, 0, face);
      fb.checkComplete("EnvDiffusePass::buildCubeMaps");
      fb.bind();
      glClearNamedFramebufferfv(fb.id(), GL_COLOR, 0, sky);
      glClearNamedFramebufferfv(fb.id(), GL_COLOR, 1, far);
      glClearNamedFramebufferfv(fb.id(), GL_DEPTH, 0, &depthClear);
      const glm::mat4 viewProj = cubeFaceViewProj(r.referencePoint, face, znear);
      cube.setMat4("u_viewProj", glm::value_ptr(viewProj));
      ctx.gpu.drawMeshes(cube, true, [&](std::size_t i) {  // the meshes in this face's frustum only
        const Bounds& b = ctx.scene.meshes[i].bounds;
        return own.count(static_cast<int>(i)) == 0 && sphereInCubeFace(r.referencePoint, face, b.center(), b.radius());
      });
      gate.issued();
    }
    glMemoryBarrier(GL_ALL_BARRIER_BITS);
    // 2. Box filter to M x M (radiance and distance averaged).
    downsampleTo(radianceLo, geometryLo, M);
    // 3. One area light per low-resolution texel.
    build.use();
    radianceLo.bindImage(0, GL_READ_ONLY, 0, true);
    geometryLo.bindImage(1, GL_READ_ONLY, 0, true);
    geometryLo.bindUnit(0);
    quads.bindBase(GL_SHADER_STORAGE_BUFFER, kQuadBinding);
    build.set("u_size", M);
    build.set("u_origin", glm::value_ptr(r.referencePoint), 3);
    glDispatchCompute(groups(M), groups(M), 6);
    glMemoryBarrier(GL_ALL_BARRIER_BITS);
  }
  // 4. Classic: irradiance at o for every normal, from the last bounce's map at S x S.
  downsampleTo(res.texture("env_diffuse_conv_radiance"), res.texture("env_diffuse_conv_geometry"), S);
  const gl::Program& conv = ctx.shaders.program({"env_diffuse/irradiance.comp"});
  conv.use();
  res.texture("env_diffuse_conv_radiance").bindImage(0, GL_READ_ONLY, 0, true);
  res.texture(st.prefix + "irradiance").bindImage(2, GL_WRITE_ONLY, 0, true);
  conv.set("u_sourceSize", S);
  conv.set("u_size", kIrradianceSize);
  glDispatchCompute(groups(kIrradianceSize), groups(kIrradianceSize), 6);
  glMemoryBarrier(GL_ALL_BARRIER_BITS);
}

void EnvDiffusePass::execute(PassContext& ctx) {
  FrameResources& res = ctx.resources;
  int built = 0;
  for (ReceiverState& r : receivers_)
    if (!r.maps.hit()) {
      buildCubeMaps(ctx, r);
      r.maps.written();
      ++built;
    }

  // Final gathering on the receivers' visible fragments.
  const FrameView& view = ctx.view;
  gl::Framebuffer& fb = res.framebuffer("env_diffuse");
  fb.bind();
  glViewport(0, 0, view.width, view.height);
  const float zero[4] = {0.f, 0.f, 0.f, 0.f};
  glClearNamedFramebufferfv(fb.id(), GL_COLOR, 0, zero);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  // The receivers add into the cleared AOV and into beauty.
  glEnablei(GL_BLEND, 0);
  glBlendEquationi(0, GL_FUNC_ADD);
  glBlendFunci(0, GL_ONE, GL_ONE);
  BeautyWrite beauty = BeautyWrite::drawBuffer(res, 1);
  using gbuffer::Attachment;
  gbuffer::bind(res, {Attachment::Position, Attachment::Normal, Attachment::Albedo, Attachment::Material});
  const gl::Program& prog = ctx.shaders.program({"env_diffuse/cube.vert", "env_diffuse/receiver.frag"});
  prog.use();
  prog.setMat4("u_viewProj", glm::value_ptr(view.viewProj));
  prog.set("u_method", static_cast<int>(method_));
  prog.set("u_horizonClip", horizonClip_ ? 1 : 0);
  prog.set("u_quadCount", 6 * downsample_ * downsample_);
  for (const ReceiverState& r : receivers_) {
    ctx.cancel.check("env_diffuse's final gathering");
    res.buffer(r.prefix + "quads").bindBase(GL_SHADER_STORAGE_BUFFER, kQuadBinding);
    res.texture(r.prefix + "irradiance").bindUnit(5);
    const std::set<int> own(r.receiver.meshes.begin(), r.receiver.meshes.end());
    ctx.gpu.drawMeshes(prog, false, [&](std::size_t i) { return own.count(static_cast<int>(i)) != 0; });
  }
  glDisablei(GL_BLEND, 0);
  glBlendFunci(0, GL_ONE, GL_ZERO);
  beauty.commit();
  res.markWritten("indirect_diffuse");

  ctx.stats.counters["receivers"] = static_cast<double>(receivers_.size());
  ctx.stats.counters["cube_maps_built"] = static_cast<double>(built);
  ctx.stats.counters["cube_faces_rendered"] = static_cast<double>(built * 6 * bounces_);
  ctx.stats.counters["area_lights_per_receiver"] = static_cast<double>(6 * downsample_ * downsample_);
  ctx.stats.counters["cube_resolution"] = cubeResolution_;
  ctx.stats.counters["downsample"] = downsample_;
  ctx.stats.counters["bounces"] = bounces_;
}

GroundTruth EnvDiffusePass::groundTruth(const Params& params, const std::string& aov) const {
  const EnvDiffuseParams p = EnvDiffuseParams::from(params);
  GroundTruth truth = GroundTruth::fromAovTable(aov);
  if (aov == "indirect_diffuse" && truth.exists()) truth.reference["max_bounces"] = 1 + p.bounces;
  return truth;
}

}  // namespace radiant
