#include "renderer/techniques/shadow_maps/ShadowMaps.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "api/Types.h"
#include "renderer/frame/FrameView.h"
#include "renderer/frame/PassContext.h"
#include "renderer/shading/CubeFaces.h"

namespace radiant {
namespace {


glm::vec3 anyPerpendicular(const glm::vec3& d) {
  return std::abs(d.y) < 0.99f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
}

}  // namespace

const TechniqueInfo& ShadowMapsPass::info() const {
  static const TechniqueInfo i{"shadow_maps",
                               "Shadow maps: cube maps for point lights, 2D maps for spot and directional lights",
                               {},
                               {},
                               {"shadow_maps"},
                               false,
                               false};
  return i;
}

Requirements ShadowMapsPass::requirements(const Scene& scene, const api::RenderRequest& request) const {
  const SceneFeatures& f = scene.features;
  // An environment map's compact bright regions are lights of the frame too (FrameView::lights).
  if (f.lightCount() == 0 && request.environment.empty())
    return Requirements::skip("the scene has no punctual lights and the frame no environment map");
  if (f.triangles == 0) return Requirements::skip("the scene has no triangles to cast shadows");
  return Requirements::ok();
}

void ShadowMapsPass::prepare(const Scene& scene, const Params& params, FrameResources& res) {
  const std::vector<Light>& lights = res.view().lights;  // the scene's, then the environment's
  size_ = params.get<int>("shadow_map_size", 1024);
  const float bias = params.get<float>("shadow_bias", 1.0f);
  const float normalOffset = params.get<float>("normal_offset", 1.5f);
  const Bounds& b = scene.features.bounds;
  const float radius = std::max(b.radius(), 1e-6f);
  const glm::vec3 center = b.center();
  const float znear = radius * 1e-4f;

  int cubes = 0, maps2d = 0;
  infos_.assign(std::max<std::size_t>(1, lights.size()), gpu::ShadowInfo{});
  draws_.clear();
  for (std::size_t li = 0; li < lights.size(); ++li) {
    const Light& l = lights[li];
    gpu::ShadowInfo& si = infos_[li];
    const glm::vec3 dir = glm::normalize(l.direction);
    if (l.type == LightType::Point) {
      // A 90 degree face spans tan(45) = 1 on each side: one texel is 2/size per unit distance.
      si.params = glm::vec4(gpu::kShadowCube, static_cast<float>(cubes), 2.f / size_, normalOffset);
      si.params2 = glm::vec4(0.f, bias, 0.f, 0.f);
      for (int f = 0; f < 6; ++f) draws_.push_back({static_cast<int>(li), cubes * 6 + f, true, cubeFaceViewProj(l.position, f, znear)});
      ++cubes;
    } else if (l.type == LightType::Spot) {
      const float fov = std::min(2.f * l.outerConeAngle + glm::radians(4.f), glm::radians(170.f));
      si.viewProj = reversedZPerspective(fov, 1.f, znear) * glm::lookAt(l.position, l.position + dir, anyPerpendicular(dir));
      si.params = glm::vec4(gpu::kShadow2D, static_cast<float>(maps2d), 2.f * std::tan(0.5f * fov) / size_, normalOffset);
      si.params2 = glm::vec4(0.f, bias, 0.f, 0.f);
      draws_.push_back({static_cast<int>(li), maps2d, false, si.viewProj});
      ++maps2d;
    } else {
      // Orthographic, fitted to the bounding sphere of the scene; the map stores dot(p, dir).
      const glm::vec3 eye = center - dir * (2.f * radius);
      si.viewProj = reversedZOrthographic(radius, radius, 0.f, 4.f * radius) * glm::lookAt(eye, center, anyPerpendicular(dir));
      si.params = glm::vec4(gpu::kShadow2D, static_cast<float>(maps2d), 2.f * radius / size_, normalOffset);
      si.params2 = glm::vec4(1.f, bias, 0.f, 0.f);
      draws_.push_back({static_cast<int>(li), maps2d, false, si.viewProj});
      ++maps2d;
    }
  }

  // The maps' memory is bounded whatever the lights: a 4096^2 map is 64 MiB, and a frame may hold the
  // scene's lights, 8 environment lights and 64 sky lights (direct's environment_lights, sky_lights).
  const double bytes = 4.0 * double(size_) * size_ * (6.0 * cubes + maps2d);
  if (bytes > kMaxBytes)
    throw api::ApiError(422, "limit-exceeded", "Server limit exceeded",
                        "/passes/shadow_maps/shadow_map_size: " + std::to_string(cubes + maps2d) + " shadow maps (" +
                            std::to_string(cubes) + " point-light cubes) of " + std::to_string(size_) + "^2 need " +
                            std::to_string(static_cast<long long>(bytes / (1 << 20))) + " MiB, above the limit of " +
                            std::to_string(static_cast<long long>(kMaxBytes / (1 << 20))) +
                            " MiB: lower shadow_map_size, or direct's sky_lights or environment_lights",
                        "/passes/shadow_maps/shadow_map_size");
  // Both arrays always exist (samplers must be complete even when unused); an unused one is 1 x 1.
  const int cubeSize = cubes > 0 ? size_ : 1, flatSize = maps2d > 0 ? size_ : 1;
  gl::Texture& cube = res.texture("shadow_cube", GL_TEXTURE_CUBE_MAP_ARRAY, GL_R32F, cubeSize, cubeSize, 6 * std::max(1, cubes));
  gl::Texture& flat = res.texture("shadow_2d", GL_TEXTURE_2D_ARRAY, GL_R32F, flatSize, flatSize, std::max(1, maps2d));
  cube.setFilter(GL_NEAREST, GL_NEAREST);
  flat.setFilter(GL_NEAREST, GL_NEAREST);
  flat.setWrap(GL_CLAMP_TO_EDGE);
  res.texture("shadow_depth", GL_TEXTURE_2D, GL_DEPTH_COMPONENT32F, size_, size_);
  res.framebuffer("shadow");
  res.buffer("shadow_info", infos_.size() * sizeof(gpu::ShadowInfo));

  // The maps depend on geometry, lights, size and the meshes left out (Technique::shadowMapExclusions).
  excluded_ = res.shadowMapExclusions();
  std::string digest = res.sceneKey() + "|" + std::to_string(size_);
  if (lights.size() > scene.lights.size()) digest += "|" + res.view().lightingEnvironmentKey();
  for (int m : excluded_) digest += "|-" + std::to_string(m);
  // The maps live in the shared shadow textures: valid only when they hold this digest's maps (another
  // scene may have rendered into them since; FrameResources::holds).
  mapsValid_ = res.holds("shadow_cube", digest, "shadow_maps");
  digest_ = std::move(digest);
}

void ShadowMapsPass::execute(PassContext& ctx) {
  FrameResources& res = ctx.resources;
  res.buffer("shadow_info").upload(infos_.data(), infos_.size() * sizeof(gpu::ShadowInfo));
  res.markWritten("shadow_maps");
  ctx.stats.counters["maps_rendered"] = mapsValid_ ? 0.0 : static_cast<double>(draws_.size());
  ctx.stats.counters["meshes_excluded"] = static_cast<double>(excluded_.size());
  if (mapsValid_) return;

  gl::Framebuffer& fb = res.framebuffer("shadow");
  gl::Texture& cube = res.texture("shadow_cube");
  gl::Texture& flat = res.texture("shadow_2d");
  gl::Texture& depth = res.texture("shadow_depth");
  fb.attach(GL_DEPTH_ATTACHMENT, depth);
  fb.setDrawBuffers({GL_COLOR_ATTACHMENT0});
  const gl::Program& prog = ctx.shaders.program({"shadow_maps/shadow.vert", "shadow_maps/shadow.frag"});
  prog.use();
  glViewport(0, 0, size_, size_);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_GREATER);
  glDepthMask(GL_TRUE);
  glDisable(GL_CULL_FACE);  // both faces cast shadows (open meshes, single walls)
  glDisable(GL_BLEND);
  const float far[4] = {1e30f, 0.f, 0.f, 0.f};
  const float depthClear = 0.f;
  std::size_t drawnTriangles = 0, fullTriangles = 0;
  for (const Draw& d : draws_) {
    const Light& l = ctx.view.lights[d.light];
    fb.attach(GL_COLOR_ATTACHMENT0, d.cube ? cube : flat, 0, d.layer);
    fb.checkComplete("ShadowMapsPass::execute");
    fb.bind();
    glClearNamedFramebufferfv(fb.id(), GL_COLOR, 0, far);
    glClearNamedFramebufferfv(fb.id(), GL_DEPTH, 0, &depthClear);
    const bool ortho = l.type == LightType::Directional;
    const glm::vec3 origin = ortho ? glm::vec3(0.f) : l.position;
    const glm::vec3 dir = glm::normalize(l.direction);
    prog.setMat4("u_viewProj", &d.viewProj[0][0]);
    prog.set("u_lightPosition", &origin[0], 3);
    prog.set("u_lightDirection", &dir[0], 3);
    prog.set("u_orthographic", ortho ? 1 : 0);
    // With textures: MASK and BLEND materials' coverage comes from the base colour's alpha (shadow.frag).
    // A point light's cube face draws only the meshes in its 90-degree frustum (sphereInCubeFace).
    // Each mesh at the coarsest level of detail within a quarter of the map's texel where the mesh is
    // nearest the light (GpuScene::drawMeshes; the normal offset and bias are a texel or more).
    const float texel = infos_[d.light].params.z;  // world units (orthographic) or per unit distance
    drawnTriangles += ctx.gpu.drawMeshes(prog, true, [&](std::size_t m) {
      if (excluded_.count(static_cast<int>(m))) return false;
      const Bounds& b = ctx.scene.meshes[m].bounds;
      if (d.cube && !sphereInCubeFace(l.position, d.layer % 6, b.center(), b.radius())) return false;
      fullTriangles += ctx.scene.meshes[m].triangleCount();
      return true;
    }, [&](std::size_t m) {
      if (ortho) return 0.25f * texel;
      const Bounds& b = ctx.scene.meshes[m].bounds;
      return 0.25f * texel * std::max(glm::length(b.center() - l.position) - b.radius(), 0.f);
    });
  }
  res.setHolds("shadow_cube", digest_);  // after writing: a frame that fails before leaves them invalid
  ctx.stats.counters["map_size"] = size_;
  // The levels of detail drawn (GpuScene::drawMeshes): triangles over all maps, against the full meshes'.
  ctx.stats.counters["triangles_drawn"] = static_cast<double>(drawnTriangles);
  ctx.stats.counters["triangles_full"] = static_cast<double>(fullTriangles);
}

}  // namespace radiant
