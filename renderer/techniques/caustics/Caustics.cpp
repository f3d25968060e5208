#include "renderer/techniques/caustics/Caustics.h"
#include "params/caustics_params.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include <glm/gtc/matrix_transform.hpp>

#include "api/Types.h"
#include "renderer/frame/Beauty.h"
#include "renderer/frame/GpuTypes.h"
#include "renderer/frame/PassContext.h"
#include "renderer/shading/DirectLighting.h"
#include "renderer/shading/CubeFaces.h"
#include "renderer/shading/SpecularMaps.h"
#include "renderer/shading/SpecularObjects.h"
#include "renderer/shading/GBufferInputs.h"

namespace radiant::gpu {
#include "shaders/caustics/shared.h"  // the caustic cubes' unit
}  // namespace radiant::gpu

namespace radiant {
namespace {

glm::vec3 anyPerpendicular(const glm::vec3& d) {
  return std::abs(d.y) < 0.99f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
}

// Does the light reach the sphere (centre, radius) at all: inside its range and, for a spot, its cone?
bool lightReaches(const Light& l, const glm::vec3& centre, float radius) {
  if (l.type == LightType::Directional) return true;
  const glm::vec3 toC = centre - l.position;
  const float d = glm::length(toC);
  if (d <= radius) return true;
  if (l.range > 0.f && d - radius > l.range) return false;
  if (l.type == LightType::Spot) {
    const float angle = std::acos(std::clamp(glm::dot(glm::normalize(l.direction), toC / d), -1.f, 1.f));
    if (angle - std::asin(std::min(1.f, radius / d)) > l.outerConeAngle) return false;
  }
  return true;
}

// Some corner of `b` lies inside the side planes of the camera's clip volume, or the box straddles
// them (a conservative frustum test: false only when all eight corners are outside one plane).
bool boundsMayBeVisible(const Bounds& b, const glm::mat4& viewProj) {
  bool out[5] = {true, true, true, true, true};
  for (int c = 0; c < 8; ++c) {
    const glm::vec3 p((c & 1) ? b.max.x : b.min.x, (c & 2) ? b.max.y : b.min.y, (c & 4) ? b.max.z : b.min.z);
    const glm::vec4 q = viewProj * glm::vec4(p, 1.f);
    out[0] = out[0] && q.x < -q.w;
    out[1] = out[1] && q.x > q.w;
    out[2] = out[2] && q.y < -q.w;
    out[3] = out[3] && q.y > q.w;
    out[4] = out[4] && q.w <= 0.f;
  }
  return !(out[0] || out[1] || out[2] || out[3] || out[4]);
}

constexpr int kGroup = 8;
constexpr int kRowsPerStretch = 32;  // photon grid rows drawn between two cancel checks
// The secondary lookup's tree drops branches below this path weight (the specular pass's bound).
constexpr float kMinBranchWeight = 1e-3f;
constexpr float kMaxLightTan = 11.4f;  // tan(85 degrees)  // work-group side of area.comp and energy.comp

}  // namespace

const TechniqueInfo& CausticsPass::info() const {
  static const TechniqueInfo i = describedTechnique("caustics");
  return i;
}

bool CausticsPass::lightCamera(const Light& light, const Bounds& bounds, LightCamera& out) {
  const glm::vec3 centre = bounds.center();
  const float radius = std::max(bounds.radius(), 1e-6f);
  if (light.type == LightType::Directional) {
    const glm::vec3 dir = glm::normalize(light.direction);
    const glm::vec3 eye = centre - dir * (2.f * radius);
    out.orthographic = true;
    out.halfExtent = radius;
    out.viewProj = reversedZOrthographic(radius, radius, 0.f, 4.f * radius) * glm::lookAt(eye, centre, anyPerpendicular(dir));
    return true;
  }
  // A square frustum from the light around the axis to the centre, wide enough for the eight corners
  // of the generator's bounds (tighter than its bounding sphere for flat mirrors, and defined when the
  // light is inside that sphere but in front of the mirror).
  const glm::vec3 toC = centre - light.position;
  const float d = glm::length(toC);
  if (!(d > 1e-6f * radius)) return false;
  const glm::vec3 axis = toC / d;
  float maxTan = 0.f, minDepth = std::numeric_limits<float>::max();
  for (int c = 0; c < 8; ++c) {
    const glm::vec3 p((c & 1) ? bounds.max.x : bounds.min.x, (c & 2) ? bounds.max.y : bounds.min.y,
                      (c & 4) ? bounds.max.z : bounds.min.z);
    const glm::vec3 v = p - light.position;
    const float depth = glm::dot(v, axis);
    if (!(depth > 1e-4f * radius)) return false;  // a corner beside or behind the light
    maxTan = std::max(maxTan, glm::length(v - depth * axis) / depth);
    minDepth = std::min(minDepth, depth);
  }
  if (!(maxTan < kMaxLightTan)) return false;  // wider than ~170 degrees: the light is too close
  maxTan = std::max(maxTan * 1.01f, 1e-6f);
  out.orthographic = false;
  out.halfExtent = maxTan;
  out.viewProj = reversedZPerspective(2.f * std::atan(maxTan), 1.f, 0.5f * minDepth) *
                 glm::lookAt(light.position, centre, anyPerpendicular(axis));
  return true;
}

std::string CausticsPass::skipReason(const Scene& scene) {
  if (scene.features.lightCount() == 0) return "no point, spot or directional light";
  const std::vector<std::size_t> generators = specularMeshes(scene);
  if (generators.empty()) return "no specular material (mirror or refractor) in the scene";
  bool seen = false;
  for (const Light& l : scene.lights)
    for (std::size_t g : generators)
      seen = seen || lightReaches(l, specularReferencePoint(scene.meshes[g]), scene.meshes[g].bounds.radius());
  if (!seen) return "no specular material in view of a light";
  return "";
}

Requirements CausticsPass::requirements(const Scene& scene, const api::RenderRequest& request) const {
  std::string why = skipReason(scene);
  if (!why.empty()) return Requirements::skip(why);
  // The camera must see a receiver (a mesh that is neither specular nor unlit inside the view
  // frustum), or a mirror or refractor that may show one (the secondary lookup).
  const FrameView view = makeFrameView(scene, request);
  bool receiver = false;
  for (const MeshInstance& m : scene.meshes) {
    const Material& mat = scene.material(m.material);
    if (mat.unlit || m.triangleCount() == 0) continue;
    receiver = receiver || boundsMayBeVisible(m.bounds, view.viewProj);
  }
  if (!receiver) return Requirements::skip("the camera sees no diffuse or glossy receiver, nor a mirror or refractor");
  return Requirements::ok();
}

CausticsPass::FittedCubes CausticsPass::fitCubes(int generators, int resolution, bool given) {
  if (cubeBytes(generators, resolution) <= kMaxBytes) return {resolution, ""};
  const auto mib = [](double b) { return std::to_string(static_cast<long long>(b / (1 << 20))); };
  int lowered = resolution;
  while (lowered > 16 && cubeBytes(generators, lowered) > kMaxBytes) lowered = std::max(16, lowered / 2);
  const std::string need = std::to_string(generators) + " generators' caustic cubes at " + std::to_string(resolution) +
                           "^2 texels need " + mib(cubeBytes(generators, resolution)) + " MiB, above the limit of " +
                           mib(kMaxBytes) + " MiB";
  if (given)
    throw api::ApiError(422, "limit-exceeded", "Server limit exceeded",
                        "/passes/caustics/cube_resolution: " + need + ": lower cube_resolution",
                        "/passes/caustics/cube_resolution");
  if (cubeBytes(generators, lowered) > kMaxBytes)
    throw api::ApiError(422, "limit-exceeded", "Server limit exceeded",
                        "/passes/caustics: " + need + ", and " + mib(cubeBytes(generators, lowered)) +
                            " MiB even at 16 texels: turn the pass off (passes.caustics = false)",
                        "/passes/caustics");
  return {lowered, need + ": drawn at " + std::to_string(lowered) + "^2"};
}

// Every specular mesh is a generator with a cube (prepare()), lit or not.
void CausticsPass::validate(const Scene& scene, const FrameView&, const Params& params) const {
  const CausticsParams p = CausticsParams::from(params);
  fitCubes(static_cast<int>(specularMeshes(scene).size()), p.cube_resolution, p.given.cube_resolution);
}

void CausticsPass::prepare(const Scene& scene, const Params& params, FrameResources& res) {
  const CausticsParams p = CausticsParams::from(params);
  // Every default and range is the descriptor's (caustics.json): Params has no fallback, and holds only
  // values api::techniqueParams checked against the schema (no clamp here repeats a range).
  method_ = p.method == CausticsParams::Method::kSplat ? Method::Splat : Method::Triangles;
  photonResolution_ = p.photon_resolution;
  cubeResolution_ = p.cube_resolution;
  areaWeight_ = static_cast<float>(p.area_weight);
  visibilityTolerance_ = static_cast<float>(p.visibility_tolerance);
  maxDepth_ = p.max_depth;
  secondaryMaxDepth_ = p.secondary_max_depth;
  linearSteps_ = p.linear_steps;
  secantSteps_ = p.secant_steps;
  splatRadius_ = static_cast<float>(p.splat_radius);
  energyCheck_ = p.energy_check;
  fresnelReflection_ = p.fresnel_reflection;
  footprintFilter_ = p.footprint_filter;
  specularLookup_ = p.specular_lookup;

  generators_ = specularMeshes(scene);
  pairs_.clear();
  skippedPairs_ = 0;
  for (std::size_t li = 0; li < scene.lights.size(); ++li)
    for (std::size_t g = 0; g < generators_.size(); ++g) {
      const MeshInstance& m = scene.meshes[generators_[g]];
      const glm::vec3 c = specularReferencePoint(m);
      if (!lightReaches(scene.lights[li], c, m.bounds.radius())) continue;
      Pair p{static_cast<int>(li), static_cast<int>(g), {}};
      if (!lightCamera(scene.lights[li], m.bounds, p.camera)) {
        ++skippedPairs_;
        continue;
      }
      pairs_.push_back(p);
      if (fresnelReflection_ && scene.material(m.material).isTransmissive()) {
        p.reflectFirst = true;
        pairs_.push_back(p);
      }
    }

  const int P = photonResolution_;
  const char* hitTargets[] = {"caustics_hit", "caustics_power", "caustics_hit_normal"};
  gl::Framebuffer& photonFb = res.framebuffer("caustics_photons");
  for (int i = 0; i < 3; ++i) {
    gl::Texture& t = res.texture(hitTargets[i], GL_TEXTURE_2D, GL_RGBA32F, P, P);
    t.setFilter(GL_NEAREST, GL_NEAREST);
    photonFb.attach(GL_COLOR_ATTACHMENT0 + i, t);
  }
  photonFb.attach(GL_DEPTH_ATTACHMENT, res.texture("caustics_photon_depth", GL_TEXTURE_2D, GL_DEPTH_COMPONENT32F, P, P));
  photonFb.setDrawBuffers({GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2});
  photonFb.checkComplete("CausticsPass::prepare (photons)");
  res.texture("caustics_vertex", GL_TEXTURE_2D, GL_RGBA32F, P, P).setFilter(GL_NEAREST, GL_NEAREST);
  const int groups = ((P + kGroup - 1) / kGroup) * ((P + kGroup - 1) / kGroup);
  res.buffer("caustics_power_sums", static_cast<std::size_t>(groups) * 2 * sizeof(glm::vec4));

  // The caustic cubes' memory (kMaxBytes), before anything is allocated.
  const int cubes = std::max<int>(1, static_cast<int>(generators_.size()));
  const FittedCubes fitted = fitCubes(static_cast<int>(generators_.size()), cubeResolution_, p.given.cube_resolution);
  cubeResolution_ = fitted.resolution;
  warning_ = fitted.warning;
  const int C = cubeResolution_;
  int levels = 1;
  while ((C >> levels) > 0) ++levels;  // down to 1 x 1
  const std::size_t cubeAllocation =
      res.textureAllocation("caustics_cube", GL_TEXTURE_CUBE_MAP_ARRAY, GL_RGBA32F, C, C, 6 * cubes, levels);
  res.makeRoom(cubeAllocation);
  res.admit(cubeAllocation, "/passes/caustics/cube_resolution");
  gl::Texture& cube = res.texture("caustics_cube", GL_TEXTURE_CUBE_MAP_ARRAY, GL_RGBA32F, C, C, 6 * cubes, levels);
  cube.setFilter(GL_LINEAR_MIPMAP_LINEAR, GL_LINEAR);
  gl::Framebuffer& cubeFb = res.framebuffer("caustics_cube");
  cubeFb.attach(GL_COLOR_ATTACHMENT0, cube);  // layered: the geometry shaders pick gl_Layer
  cubeFb.setDrawBuffers({GL_COLOR_ATTACHMENT0});
  cubeFb.checkComplete("CausticsPass::prepare (cube)");
  const int cubeGroups = ((C + kGroup - 1) / kGroup) * ((C + kGroup - 1) / kGroup) * 6;
  res.buffer("caustics_deposit_sums", static_cast<std::size_t>(cubeGroups) * sizeof(glm::vec4));

  // Its output and beauty: allocated by the Renderer (renderer/frame/FrameAllocation.h).
  gl::Framebuffer& fb = res.framebuffer("caustics");
  fb.attach(GL_COLOR_ATTACHMENT0, res.texture("caustics"));
  attachBeauty(res, fb, GL_COLOR_ATTACHMENT1);
  fb.setDrawBuffers({GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1});
  fb.checkComplete("CausticsPass::prepare");
  gl::Framebuffer& secondary = res.framebuffer("caustics_secondary");
  attachBeauty(res, secondary, GL_COLOR_ATTACHMENT0);
  secondary.setDrawBuffers({GL_COLOR_ATTACHMENT0});
  secondary.checkComplete("CausticsPass::prepare (secondary)");
  declareDirectLightingResources(res);
}

void CausticsPass::execute(PassContext& ctx) {
  FrameResources& res = ctx.resources;
  auto& counters = ctx.stats.counters;
  const int P = photonResolution_, C = cubeResolution_;
  const int G = static_cast<int>(generators_.size());
  // The specular pass's maps (its product "specular_maps", an input: this pass runs after it).
  const SpecularMaps* maps = publishedSpecularMaps(res);
  if (!maps) throw std::logic_error("CausticsPass: specular published no maps this frame");
  auto bindMaps = [&](const gl::Program& prog) {
    maps->bind();
    prog.set("u_layers", maps->layers);
    prog.set("u_linearSteps", linearSteps_);
    prog.set("u_secantSteps", secantSteps_);
    prog.set("u_minmax", 1);
    prog.set("u_cubeResolution", static_cast<float>(maps->resolution));
  };

  gl::Texture& cube = res.texture("caustics_cube");
  gl::Framebuffer& cubeFb = res.framebuffer("caustics_cube");
  const float zero[4] = {0.f, 0.f, 0.f, 0.f};
  // Steps (1) to (3) and the cube's mip chain do not depend on the camera: they are functions of the
  // specular maps (which hold the scene's geometry, materials and lights, and their own shape) and of
  // the knobs below. The cubes are kept in caustics_cube and redrawn only when one of those changed; a
  // frame from another camera runs the camera passes (4) and (5) alone. energy_check recomputes (its
  // sums are counters of the drawing).
  std::string cubeDigest;
  if (!maps->digest.empty() && !energyCheck_) {
    std::ostringstream key;
    key << maps->digest << "|caustics method=" << static_cast<int>(method_) << " P=" << P << " C=" << C
        << " w=" << areaWeight_ << " depth=" << maxDepth_ << " steps=" << linearSteps_ << "," << secantSteps_
        << " r=" << splatRadius_ << " fresnel=" << fresnelReflection_ << " mips=" << footprintFilter_
        << " pairs=" << pairs_.size();
    cubeDigest = key.str();
  }
  // The cubes live in the shared caustics_cube texture (FrameResources::refill); a frame that draws them
  // without a digest (energy_check) leaves it holding nothing, whatever scene it held before.
  FrameResources::Refill cubes = res.refill("caustics_cube", cubeDigest, "caustics_cube");
  counters["cube_cached"] = cubes.hit() ? 1.0 : 0.0;
  if (!cubes.hit()) {
    glClearNamedFramebufferfv(cubeFb.id(), GL_COLOR, 0, zero);

    // Face transforms around the origin: hit positions are relative to the reference point.
    std::vector<glm::mat4> faces(6);
    const float sceneRadius = std::max(ctx.scene.features.bounds.radius(), 1e-6f);
    for (int f = 0; f < 6; ++f) faces[f] = cubeFaceViewProj(glm::vec3(0.f), f, sceneRadius * 1e-6f);

    gl::Framebuffer& photonFb = res.framebuffer("caustics_photons");
    gl::Texture& hit = res.texture("caustics_hit");
    gl::Texture& power = res.texture("caustics_power");
    gl::Texture& hitNormal = res.texture("caustics_hit_normal");
    gl::Texture& vertex = res.texture("caustics_vertex");
    gl::Buffer& powerSums = res.buffer("caustics_power_sums");
    const int groupsX = (P + kGroup - 1) / kGroup;
    std::vector<glm::vec4> sums(static_cast<std::size_t>(groupsX) * groupsX * 2);
    double photonPower = 0.0, lostPower = 0.0;
    double validPhotons = 0.0;

    const gl::Program& photonProg = ctx.shaders.program({"specular/map.vert", "caustics/photon.frag"});
    const gl::Program& areaProg = ctx.shaders.program({"caustics/area.comp"});
    const gl::Program& drawProg = method_ == Method::Triangles
                                      ? ctx.shaders.program({"caustics/grid.vert", "caustics/triangles.geom", "caustics/deposit.frag"})
                                      : ctx.shaders.program({"caustics/grid.vert", "caustics/splat.geom", "caustics/deposit.frag"});
    int pairsDrawn = 0;
    for (const Pair& pair : pairs_) {
      ctx.cancel.check("caustics' photon pass, pair " + std::to_string(pairsDrawn + 1) + " of " +
                       std::to_string(pairs_.size()));
      ctx.progress(0.9 * pairsDrawn++ / double(pairs_.size()));
      // (1) Photon tracing pass: the generator seen from the light, negative power where it is not.
      photonFb.bind();
      glViewport(0, 0, P, P);
      const float invalid[4] = {0.f, 0.f, 0.f, -1.f};
      const float depthClear = 0.f;
      for (int i = 0; i < 3; ++i) glClearNamedFramebufferfv(photonFb.id(), GL_COLOR, i, i == 1 ? invalid : zero);
      glClearNamedFramebufferfv(photonFb.id(), GL_DEPTH, 0, &depthClear);
      glEnable(GL_DEPTH_TEST);
      glDepthFunc(GL_GREATER);  // reversed-Z: the surface nearest the light
      glDepthMask(GL_TRUE);
      glDisable(GL_CULL_FACE);
      glDisable(GL_BLEND);
      photonProg.use();
      bindDirectLighting(photonProg, res, ctx.gpu, static_cast<int>(ctx.scene.lights.size()), 0);
      bindMaps(photonProg);
      photonProg.setMat4("u_viewProj", &pair.camera.viewProj[0][0]);
      photonProg.set("u_object", pair.generator);
      photonProg.set("u_light", pair.light);
      photonProg.set("u_orthographic", pair.camera.orthographic ? 1 : 0);
      photonProg.set("u_halfExtent", pair.camera.halfExtent);
      photonProg.set("u_maxDepth", maxDepth_);
      photonProg.set("u_reflectFirst", pair.reflectFirst ? 1 : 0);
      photonProg.set("u_photonResolution", P);
      const std::size_t mesh = generators_[pair.generator];
      ctx.gpu.drawMeshes(photonProg, true, [&](std::size_t m) { return m == mesh; });
      glDisable(GL_DEPTH_TEST);
      glMemoryBarrier(GL_ALL_BARRIER_BITS);

      // (2) Vertex areas and irradiance.
      areaProg.use();
      hit.bindUnit(0);
      power.bindUnit(1);
      hitNormal.bindUnit(2);
      vertex.bindImage(0, GL_WRITE_ONLY);
      powerSums.bindBase(GL_SHADER_STORAGE_BUFFER, 5);
      areaProg.set("u_photonResolution", P);
      areaProg.set("u_areaWeight", areaWeight_);
      glDispatchCompute(groupsX, groupsX, 1);
      glMemoryBarrier(GL_ALL_BARRIER_BITS);
      if (energyCheck_) {
        powerSums.download(sums.data(), sums.size() * sizeof(glm::vec4));
        for (std::size_t g = 0; g < sums.size(); g += 2) {
          photonPower += 0.2126 * sums[g].x + 0.7152 * sums[g].y + 0.0722 * sums[g].z;
          validPhotons += sums[g].w;
          lostPower += 0.2126 * sums[g + 1].x + 0.7152 * sums[g + 1].y + 0.0722 * sums[g + 1].z;
        }
      }

      // (3) Reconstruction into the generator's caustic cube, additively.
      cubeFb.bind();
      glViewport(0, 0, C, C);
      glEnable(GL_BLEND);
      glBlendEquation(GL_FUNC_ADD);
      glBlendFunc(GL_ONE, GL_ONE);
      drawProg.use();
      hit.bindUnit(0);
      power.bindUnit(1);
      hitNormal.bindUnit(2);
      vertex.bindUnit(3);
      drawProg.set("u_photonResolution", P);
      drawProg.set("u_gridResolution", P);
      drawProg.set("u_areaWeight", areaWeight_);
      drawProg.set("u_cubeLayer", 6 * pair.generator);
      drawProg.set("u_causticResolution", static_cast<float>(C));
      drawProg.set("u_splatRadius", splatRadius_);
      glProgramUniformMatrix4fv(drawProg.id(), drawProg.uniformLocation("u_faceViewProj"), 6, GL_FALSE, &faces[0][0][0]);
      // In stretches of kRowsPerStretch grid rows (gl_VertexID counts from `first`, so the stretches
      // draw exactly the one draw's primitives), with a cancel check between them.
      drawProg.set("u_gridMode", method_ == Method::Triangles ? 0 : 1);
      const int rows = method_ == Method::Triangles ? P - 1 : P;
      const int perRow = method_ == Method::Triangles ? 6 * (P - 1) : P;
      for (int row = 0; row < rows; row += kRowsPerStretch) {
        if (row > 0) ctx.cancel.check("caustics' drawing");
        glDrawArrays(method_ == Method::Triangles ? GL_TRIANGLES : GL_POINTS, row * perRow,
                     std::min(kRowsPerStretch, rows - row) * perRow);
      }
      glDisable(GL_BLEND);
      glMemoryBarrier(GL_ALL_BARRIER_BITS);
    }

    double deposited = 0.0;
    if (energyCheck_ && !pairs_.empty()) {
      const gl::Program& energyProg = ctx.shaders.program({"caustics/energy.comp"});
      energyProg.use();
      bindMaps(energyProg);
      cube.bindImage(1, GL_READ_ONLY, 0, true, 0);
      gl::Buffer& depositSums = res.buffer("caustics_deposit_sums");
      depositSums.bindBase(GL_SHADER_STORAGE_BUFFER, 5);
      energyProg.set("u_causticResolution", static_cast<float>(C));
      const int cg = (C + kGroup - 1) / kGroup;
      std::vector<glm::vec4> dep(static_cast<std::size_t>(cg) * cg * 6);
      for (int g = 0; g < G; ++g) {
        energyProg.set("u_generator", g);
        glDispatchCompute(cg, cg, 6);
        glMemoryBarrier(GL_ALL_BARRIER_BITS);
        depositSums.download(dep.data(), dep.size() * sizeof(glm::vec4));
        for (const glm::vec4& d : dep) deposited += 0.2126 * d.x + 0.7152 * d.y + 0.0722 * d.z;
      }
      counters["photon_power"] = photonPower;
      counters["valid_photons"] = validPhotons;
      counters["lost_power"] = lostPower;
      counters["deposited_power"] = deposited;
    }

    // The mip chain for the camera pass's footprint filter: box-filtered levels keep each region's power
    // (irradiance and the alpha depth weight average alike, so the mean deposit depth stays a ratio).
    if (footprintFilter_ && !pairs_.empty()) cube.generateMipmaps();
    cubes.written();
  }  // !cubes.hit()

  // (4) Camera pass: caustics AOV, and beauty += caustics when this pass owns LS+DE (a request that
  // names light_volumes gives the class to it: then the AOV is written but not added, counted once).
  const bool owns = res.owns("caustics", api::kPathLSDE);
  const float pixelArea = 4.f / (ctx.view.proj[0][0] * ctx.view.proj[1][1] * ctx.view.width * ctx.view.height);
  const float maxLod = footprintFilter_ ? static_cast<float>(cube.levels() - 1) : 0.f;
  auto setLookup = [&](const gl::Program& prog) {
    prog.set("u_generators", G);
    prog.set("u_visibilityTolerance", visibilityTolerance_);
    prog.set("u_causticResolution", static_cast<float>(C));
    prog.set("u_maxLod", maxLod);
    // A pixel's area on the plane at unit view depth (perspective) or its area (orthographic):
    // (2 / (P00 W)) (2 / (P11 H)) for either projection.
    prog.set("u_pixelArea", pixelArea);
  };
  gl::Framebuffer& fb = res.framebuffer("caustics");
  fb.bind();
  glViewport(0, 0, ctx.view.width, ctx.view.height);
  glClearNamedFramebufferfv(fb.id(), GL_COLOR, 0, zero);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_BLEND);  // the AOV is overwritten
  BeautyWrite beauty = BeautyWrite::drawBuffer(res, 1, owns);
  if (!pairs_.empty()) {
    using gbuffer::Attachment;
    gbuffer::bind(res, {Attachment::Position, Attachment::Normal, Attachment::Albedo, Attachment::Material,
                        Attachment::Emission, Attachment::GeometricNormal});
    cube.bindUnit(gpu::kUnitCausticCube);
    const gl::Program& prog = ctx.shaders.program({"common/fullscreen.vert", "caustics/camera.frag"});
    prog.use();
    bindMaps(prog);
    setLookup(prog);
    glDrawArrays(GL_TRIANGLES, 0, 3);
  }
  beauty.commit();
  res.markWritten("caustics");
  counters["adds_to_beauty"] = owns ? 1.0 : 0.0;

  // (5) The caustics seen in mirrors and through glass (LS+DS+E): the specular objects rasterised from
  // the camera, their trees traced through the maps, the cubes looked up at the non-specular hits;
  // into beauty only (the caustics AOV stays exactly LS+DE, the reference's caustics class).
  const bool secondary = specularLookup_ && !pairs_.empty() && res.owns("caustics", api::kPathLSDSE);
  if (secondary) {
    res.framebuffer("caustics_secondary").bind();
    glViewport(0, 0, ctx.view.width, ctx.view.height);
    glDisable(GL_DEPTH_TEST);  // the G-buffer test keeps one fragment per pixel (secondary.frag)
    glDisable(GL_CULL_FACE);
    BeautyWrite beautyThroughSpecular = BeautyWrite::drawBuffer(res, 0);
    using gbuffer::Attachment;
    gbuffer::bind(res, {Attachment::Position, Attachment::Normal, Attachment::Albedo, Attachment::Material,
                        Attachment::Emission});
    cube.bindUnit(gpu::kUnitCausticCube);
    const gl::Program& prog = ctx.shaders.program({"specular/map.vert", "caustics/secondary.frag"});
    prog.use();
    bindMaps(prog);
    setLookup(prog);
    prog.setMat4("u_viewProj", &ctx.view.viewProj[0][0]);
    prog.set("u_maxDepth", secondaryMaxDepth_);
    prog.set("u_minWeight", kMinBranchWeight);
    const GLint objectLoc = prog.uniformLocation("u_object");
    ctx.gpu.drawMeshes(prog, false, [&](std::size_t mesh) {
      const auto it = std::find(generators_.begin(), generators_.end(), mesh);
      if (it == generators_.end()) return false;
      glProgramUniform1i(prog.id(), objectLoc, static_cast<int>(it - generators_.begin()));
      return true;
    });
    beautyThroughSpecular.commit();
  }
  counters["specular_lookup"] = secondary ? 1.0 : 0.0;
  counters["secondary_max_depth"] = secondaryMaxDepth_;

  counters["generators"] = G;
  counters["pairs"] = static_cast<double>(pairs_.size());  // (light, generator, branch) hit images
  counters["pairs_light_inside_generator"] = skippedPairs_;
  counters["photon_resolution"] = P;
  counters["cube_resolution"] = C;
  counters["cube_bytes"] = cubeBytes(G, C);
  if (!warning_.empty()) ctx.stats.warnings.push_back(warning_);
  counters["triangles"] = method_ == Method::Triangles ? 2.0 * (P - 1) * (P - 1) * pairs_.size() : 0.0;
  counters["splats"] = method_ == Method::Splat ? double(P) * P * pairs_.size() : 0.0;
  counters["area_weight"] = areaWeight_;
  counters["footprint_filter"] = footprintFilter_ ? 1.0 : 0.0;
}

}  // namespace radiant
