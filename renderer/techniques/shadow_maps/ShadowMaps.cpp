#include "renderer/techniques/shadow_maps/ShadowMaps.h"
#include "params/shadow_maps_params.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "api/Types.h"
#include "renderer/frame/FrameView.h"
#include "renderer/frame/PassContext.h"
#include "renderer/shading/DirectLighting.h"
#include "renderer/shading/CubeFaces.h"
#include "renderer/shading/Stretches.h"

namespace radiant {
namespace {


glm::vec3 anyPerpendicular(const glm::vec3& d) {
  return std::abs(d.y) < 0.99f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
}

// A spot light's map: its cone plus a margin, at most 170 degrees.
float spotFov(const Light& l) { return std::min(2.f * l.outerConeAngle + glm::radians(4.f), glm::radians(170.f)); }

}  // namespace

std::vector<double> ShadowMapsPass::mapCoverage(const Scene& scene, const std::vector<Light>& lights,
                                                const std::set<int>& excluded, const rt::Cancel& cancel) {
  constexpr double kPi = 3.14159265358979323846;
  const double radius = std::max<double>(scene.features.bounds.radius(), 1e-6);
  // Per light: the factor from a triangle's projected area (directional) or solid angle (spot, point)
  // to map areas.
  std::vector<double> factor(lights.size());
  std::vector<glm::dvec3> direction(lights.size()), position(lights.size());
  for (std::size_t li = 0; li < lights.size(); ++li) {
    const Light& l = lights[li];
    direction[li] = glm::normalize(glm::dvec3(l.direction));
    position[li] = glm::dvec3(l.position);
    if (l.type == LightType::Directional) factor[li] = 1.0 / (4.0 * radius * radius);  // the map spans 2r x 2r
    else if (l.type == LightType::Spot) {
      const double t = std::tan(0.5 * spotFov(l));  // the map spans 2t x 2t of the plane at distance 1
      factor[li] = 1.0 / (4.0 * t * t);
    } else factor[li] = 6.0 / (4.0 * kPi);  // six face maps cover the sphere's 4 pi
  }
  std::vector<double> coverage(lights.size(), 0.0);
  for (std::size_t m = 0; m < scene.meshes.size(); ++m) {
    if (excluded.count(static_cast<int>(m))) continue;
    cancel.check("shadow_maps' overdraw estimate, mesh " + std::to_string(m));
    const MeshInstance& mesh = scene.meshes[m];
    for (std::size_t i = 0; i + 2 < mesh.indices.size(); i += 3) {
      const glm::dvec3 p0 = mesh.positions[mesh.indices[i]], p1 = mesh.positions[mesh.indices[i + 1]],
                       p2 = mesh.positions[mesh.indices[i + 2]];
      const glm::dvec3 area = 0.5 * glm::cross(p1 - p0, p2 - p0);  // normal times area
      const glm::dvec3 centre = (p0 + p1 + p2) / 3.0;
      for (std::size_t li = 0; li < lights.size(); ++li) {
        const Light& l = lights[li];
        double a;
        if (l.type == LightType::Directional) {
          a = std::abs(glm::dot(area, direction[li]));
        } else {
          const glm::dvec3 v = centre - position[li];
          if (l.type == LightType::Spot && !(glm::dot(v, direction[li]) > 0.0)) continue;  // behind it
          const double d = glm::length(v);
          a = d > 0.0 ? std::min(std::abs(glm::dot(area, v)) / (d * d * d), 2.0 * kPi) : 2.0 * kPi;
        }
        if (std::isfinite(a)) coverage[li] += a * factor[li];
      }
    }
  }
  return coverage;
}

int ShadowMapsPass::sizeWithinBudget(int size, double coverage) {
  while (size / 2 >= kMinAutoSize && coverage * double(size) * size > kFragmentBudget) size /= 2;
  return size;
}

void ShadowMapsPass::checkFragments(int size, double coverage, std::size_t lights) {
  const double fragments = coverage * double(size) * size;
  if (fragments > kFragmentLimit)
    throw api::ApiError(
        422, "limit-exceeded", "Server limit exceeded",
        "/passes/shadow_maps/shadow_map_size: maps of " + std::to_string(size) + "^2 would rasterise an estimated " +
            std::to_string(static_cast<long long>(fragments / 1e6)) + " million fragments (the scene's triangles " +
            "cover each map about " + std::to_string(static_cast<long long>(coverage / std::max<std::size_t>(1, lights))) +
            " times over), above the limit of " + std::to_string(static_cast<long long>(kFragmentLimit / 1e6)) +
            " million: lower shadow_map_size, or leave it out to let the server choose",
        "/passes/shadow_maps/shadow_map_size");
}

void ShadowMapsPass::checkBytes(int size, int cubes, int maps2d) {
  // The maps' memory is bounded whatever the lights: a 4096^2 map is 64 MiB, and a frame may hold the
  // scene's lights, 8 environment lights and 64 sky lights (direct's environment_lights, sky_lights).
  const double bytes = 4.0 * double(size) * size * (6.0 * cubes + maps2d);
  if (bytes > kMaxBytes)
    throw api::ApiError(422, "limit-exceeded", "Server limit exceeded",
                        "/passes/shadow_maps/shadow_map_size: " + std::to_string(cubes + maps2d) + " shadow maps (" +
                            std::to_string(cubes) + " point-light cubes) of " + std::to_string(size) + "^2 need " +
                            std::to_string(static_cast<long long>(bytes / (1 << 20))) + " MiB, above the limit of " +
                            std::to_string(static_cast<long long>(kMaxBytes / (1 << 20))) +
                            " MiB: lower shadow_map_size, or direct's sky_lights or environment_lights",
                        "/passes/shadow_maps/shadow_map_size");
}

void ShadowMapsPass::validate(const Scene& scene, const FrameView& view, const Params& params) const {
  const ShadowMapsParams p = ShadowMapsParams::from(params);
  if (!p.given.shadow_map_size) return;  // the default is lowered to fit (prepare)
  // Over the scene's own lights, which the request's view has too: every frame has at least these maps
  // and this coverage, so a size refused here is refused by every frame, before the job is queued. The
  // environment's lights join at the frame (the map's split), where prepare() checks them all.
  const std::vector<Light> lights(view.lights.begin(), view.lights.begin() + view.sceneLights);
  if (lights.empty()) return;
  int cubes = 0;
  for (const Light& l : lights) cubes += l.type == LightType::Point ? 1 : 0;
  checkBytes(p.shadow_map_size, cubes, static_cast<int>(lights.size()) - cubes);
  double coverage = 0.0;
  for (double c : mapCoverage(scene, lights, view.shadowMapExclusions)) coverage += c;
  checkFragments(p.shadow_map_size, coverage, lights.size());
}

const TechniqueInfo& ShadowMapsPass::info() const {
  static const TechniqueInfo i = describedTechnique("shadow_maps");
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
  const ShadowMapsParams p = ShadowMapsParams::from(params);
  const std::vector<Light>& lights = res.view().lights;  // the scene's, then the environment's
  size_ = p.shadow_map_size;
  // The maps depend on geometry, lights, size and the meshes left out (Technique::shadowMapExclusions);
  // their overdraw on all but the size.
  excluded_ = res.view().shadowMapExclusions;
  std::string inputs = res.sceneKey();
  if (lights.size() > scene.lights.size()) inputs += "|" + res.view().lightingEnvironmentKey();
  for (int m : excluded_) inputs += "|-" + std::to_string(m);
  estimateMs_ = 0.0;
  if (inputs != coverageKey_) {
    const auto start = std::chrono::steady_clock::now();
    coverageKey_.clear();  // until the estimate is whole (it may be cancelled)
    coverage_ = 0.0;
    for (double c : mapCoverage(scene, lights, excluded_, res.cancel())) coverage_ += c;
    coverageKey_ = inputs;
    estimateMs_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  }
  warning_.clear();
  const double fragments = coverage_ * double(size_) * size_;
  if (p.given.shadow_map_size) {
    checkFragments(size_, coverage_, lights.size());  // with the environment's lights (validate: the scene's)
  } else if (const int lowered = sizeWithinBudget(size_, coverage_); lowered < size_) {
    warning_ = "the default " + std::to_string(size_) + "^2 maps would rasterise an estimated " +
               std::to_string(static_cast<long long>(fragments / 1e6)) + " million fragments (overdraw: the " +
               "scene's triangles cover each map about " +
               std::to_string(static_cast<long long>(coverage_ / std::max<std::size_t>(1, lights.size()))) +
               " times over), above the budget of " + std::to_string(static_cast<long long>(kFragmentBudget / 1e6)) +
               " million: drawn at " + std::to_string(lowered) + "^2 (set shadow_maps.shadow_map_size to choose)";
    size_ = lowered;
  }
  const float bias = static_cast<float>(p.shadow_bias);
  const float normalOffset = static_cast<float>(p.normal_offset);
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
      const float fov = spotFov(l);
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

  checkBytes(size_, cubes, maps2d);  // whatever chose the size: with the environment's lights
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

  std::string digest = inputs + "|" + std::to_string(size_);
  // The maps live in the shared shadow textures: valid only when they hold this digest's maps (another
  // scene may have rendered into them since; FrameResources::refill).
  maps_ = res.refill("shadow_cube", std::move(digest), "shadow_maps");
}

void ShadowMapsPass::execute(PassContext& ctx) {
  FrameResources& res = ctx.resources;
  gl::Buffer& info = res.buffer("shadow_info");
  info.upload(infos_.data(), infos_.size() * sizeof(gpu::ShadowInfo));
  res.publish("shadow_maps", ShadowMapSet{&res.texture("shadow_cube"), &res.texture("shadow_2d"), &info});
  ctx.stats.counters["maps_rendered"] = maps_.hit() ? 0.0 : static_cast<double>(draws_.size());
  ctx.stats.counters["meshes_excluded"] = static_cast<double>(excluded_.size());
  ctx.stats.counters["map_size"] = size_;
  // The overdraw estimate the size was chosen by (kFragmentBudget), in fragments of every map.
  ctx.stats.counters["fragments_estimated"] = coverage_ * double(size_) * size_;
  ctx.stats.counters["overdraw_estimate_ms"] = estimateMs_;  // 0 when the inputs are unchanged
  if (!warning_.empty()) ctx.stats.warnings.push_back(warning_);
  if (maps_.hit()) return;

  gl::Framebuffer& fb = res.framebuffer("shadow");
  gl::Texture& cube = res.texture("shadow_cube");
  gl::Texture& flat = res.texture("shadow_2d");
  gl::Texture& depth = res.texture("shadow_depth");
  fb.attach(GL_DEPTH_ATTACHMENT, depth);
  fb.setDrawBuffers({GL_COLOR_ATTACHMENT0});
  // Opaque materials through a variant without the material read and discard (shadow.frag, OPAQUE),
  // whose depth test may run before the shader; MASK and BLEND ones through the full program.
  const gl::Program& opaqueProg =
      ctx.shaders.program({"shadow_maps/shadow.vert", "shadow_maps/shadow.frag"}, {{"OPAQUE", "1"}});
  const gl::Program& alphaProg = ctx.shaders.program({"shadow_maps/shadow.vert", "shadow_maps/shadow.frag"});
  auto opaque = [&](std::size_t m) {
    const int mat = ctx.scene.meshes[m].material;
    return mat < 0 || mat >= int(ctx.scene.materials.size()) || ctx.scene.materials[mat].alphaMode == AlphaMode::Opaque;
  };
  glViewport(0, 0, size_, size_);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_GREATER);
  glDepthMask(GL_TRUE);
  glDisable(GL_CULL_FACE);  // both faces cast shadows (open meshes, single walls)
  glDisable(GL_BLEND);
  const float far[4] = {1e30f, 0.f, 0.f, 0.f};
  const float depthClear = 0.f;
  std::size_t drawnTriangles = 0, fullTriangles = 0;
  StretchGate gate(ctx.cancel);  // one map (a cube face) is a stretch of GPU work
  for (const Draw& d : draws_) {
    gate.check("shadow_maps, map " + std::to_string(&d - draws_.data() + 1) + " of " + std::to_string(draws_.size()));
    const Light& l = ctx.view.lights[d.light];
    fb.attach(GL_COLOR_ATTACHMENT0, d.cube ? cube : flat, 0, d.layer);
    fb.checkComplete("ShadowMapsPass::execute");
    fb.bind();
    glClearNamedFramebufferfv(fb.id(), GL_COLOR, 0, far);
    glClearNamedFramebufferfv(fb.id(), GL_DEPTH, 0, &depthClear);
    const bool ortho = l.type == LightType::Directional;
    const glm::vec3 origin = ortho ? glm::vec3(0.f) : l.position;
    const glm::vec3 dir = glm::normalize(l.direction);
    // MASK and BLEND materials' coverage comes from the base colour's alpha (shadow.frag), with textures.
    // A point light's cube face draws only the meshes in its 90-degree frustum (sphereInCubeFace).
    // Each mesh at the coarsest level of detail within a quarter of the map's texel where the mesh is
    // nearest the light (GpuScene::drawMeshes; the normal offset and bias are a texel or more).
    const float texel = infos_[d.light].params.z;  // world units (orthographic) or per unit distance
    for (const bool opaquePass : {true, false}) {
      const gl::Program& prog = opaquePass ? opaqueProg : alphaProg;
      prog.use();
      prog.setMat4("u_viewProj", &d.viewProj[0][0]);
      prog.set("u_lightPosition", &origin[0], 3);
      prog.set("u_lightDirection", &dir[0], 3);
      prog.set("u_orthographic", ortho ? 1 : 0);
      drawnTriangles += ctx.gpu.drawMeshes(prog, !opaquePass, [&](std::size_t m) {
        if (excluded_.count(static_cast<int>(m)) || opaque(m) != opaquePass) return false;
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
    gate.issued();
  }
  maps_.written();  // a frame that fails before this leaves them holding nothing
  // The levels of detail drawn (GpuScene::drawMeshes): triangles over all maps, against the full meshes'.
  ctx.stats.counters["triangles_drawn"] = static_cast<double>(drawnTriangles);
  ctx.stats.counters["triangles_full"] = static_cast<double>(fullTriangles);
}

}  // namespace radiant
