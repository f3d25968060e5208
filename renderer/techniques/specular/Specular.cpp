#include "renderer/techniques/specular/Specular.h"
#include "params/specular_params.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>

#include "api/Presets.h"
#include "api/Types.h"
#include "renderer/frame/Beauty.h"
#include "renderer/frame/GpuTypes.h"
#include "renderer/frame/PassContext.h"
#include "renderer/shading/CubeFaces.h"
#include "renderer/shading/DirectLighting.h"
#include "renderer/shading/ImageBasedLighting.h"
#include "renderer/shading/PhotonGrid.h"
#include "renderer/shading/SpecularMaps.h"
#include "renderer/shading/SpecularObjects.h"
#include "renderer/shading/Stretches.h"
#include "renderer/shading/GBufferInputs.h"

namespace radiant {
namespace {


// Branches of the reflection/refraction tree whose path weight drops below this are not traced: each
// dropped branch changes the pixel by less than 1e-3 times the radiance it would have fetched, and
// it keeps a glass object's 2^(max_depth+1) rays down to the few that matter.
constexpr float kMinBranchWeight = 1e-3f;

constexpr int kMapTextureUnitPeel = gpu::kUnitPeel;
// Indirect light in the maps (shaders/specular/map_indirect.comp): one photon gather per block of
// `map_indirect_block` texels per side (at least 8 blocks per face side), spread over the block's
// texels on the same surface (the rest gather themselves). photon_gi's estimate is smooth over its
// kernel radius; a gather at every texel of a 256 x 256 face cost 13 s per photon set on llvmpipe
// (docs/PERFORMANCE.md), and with 36 glass spheres the gathers at 4 x 4 blocks were 14 of the specular
// pass's 22 s at 256 x 256 (issue 31).
int mapIndirectBlock(int resolution, int block) { return std::clamp(block, 1, std::max(1, resolution / 8)); }
// The second level's blocks (map_indirect.comp, u_fixupOnly in modes 1 and 2): the texels no sample of
// the first level fits share one gather per 2 x 2 where they lie on one surface.
constexpr int kFineBlock = 2;
constexpr float kEmptyDistance = 3.0e38f;  // shaders/specular/ldm.glsl

}  // namespace

double projectedDiameterPixels(const FrameView& view, const Bounds& bounds) {
  if (bounds.empty()) return 0.0;
  const double r = bounds.radius();
  const glm::vec4 clip = view.viewProj * glm::vec4(bounds.center(), 1.f);
  const double scale = double(view.proj[1][1]) * view.height;  // pixels per unit of r / w
  if (view.proj[3][3] != 0.f) return r * scale;                 // orthographic: w = 1
  if (clip.w <= -r) return 0.0;                                 // wholly behind the camera
  if (clip.w <= r) return std::numeric_limits<double>::infinity();  // around the camera
  return r * scale / clip.w;
}

int mapResolution(double objectPixels, double texelsPerPixel, int maxResolution) {
  const double wanted = std::min(objectPixels * texelsPerPixel, double(maxResolution));
  int r = 16;
  while (r < wanted && r < maxResolution) r *= 2;
  return std::min(r, maxResolution);
}

MapResolution chooseMapResolution(const Scene& scene, const FrameView& view, const Params& params, bool causticsOwnsLSDE) {
  const SpecularParams p = SpecularParams::from(params);
  MapResolution r;
  r.texels = p.cube_resolution;
  // A cube_resolution the request gives is run as asked, unless it gives map_texels_per_pixel too.
  r.adaptive = !p.given.cube_resolution || p.given.map_texels_per_pixel;
  const double texelsPerPixel = r.adaptive ? p.map_texels_per_pixel : 0.0;
  if (texelsPerPixel <= 0.0) return r;
  for (std::size_t i : specularMeshes(scene))
    r.largestObjectPixels = std::max(r.largestObjectPixels, projectedDiameterPixels(view, scene.meshes[i].bounds));
  // The caustics pass traces its photons from the lights through these maps: what they need does
  // not depend on the camera (a generator a few pixels wide on screen can focus a caustic across the
  // floor; at 128 texels a glass slab lost 4% of its caustic photons at its edges against 256), so
  // with caustics in the frame the maps stay at cube_resolution.
  r.keptForCaustics = causticsOwnsLSDE;
  if (!r.keptForCaustics) r.texels = mapResolution(r.largestObjectPixels, texelsPerPixel, r.texels);
  return r;
}

// Declared in specular.json: rays that leave the scene see the environment map; photon_grid is
// photon_gi's splat grid, which lights the maps' diffuse texels with indirect light (L D+ D S+ E) when
// photon_gi is planned; specular_maps (a resource) are the layered distance maps, read by caustics.
const TechniqueInfo& SpecularPass::info() const {
  static const TechniqueInfo i = describedTechnique("specular");
  return i;
}

// It renders layered distance maps per object (specularMeshes: every mirror-like or transmissive mesh).
void SpecularPass::addCostCounts(const Scene& scene, api::SceneCounts& counts) const {
  counts.specularObjects = static_cast<double>(specularMeshes(scene).size());
}

Requirements SpecularPass::requirements(const Scene& scene, const api::RenderRequest&) const {
  const SceneFeatures& f = scene.features;
  if (f.specularMaterials == 0 && f.transmissiveMaterials == 0)
    return Requirements::skip("the scene has no specular or transmissive material");
  return Requirements::ok();
}

SpecularPass::FittedMaps SpecularPass::fitMaps(int objects, int layers, int resolution, bool adaptive,
                                               bool keptForCaustics) {
  if (mapBytes(objects, layers, resolution) <= kMaxBytes) return {resolution, ""};
  const auto mib = [](double b) { return std::to_string(static_cast<long long>(b / (1 << 20))); };
  int lowered = resolution;
  while (lowered > 16 && mapBytes(objects, layers, lowered) > kMaxBytes) lowered = std::max(16, lowered / 2);
  const std::string need = std::to_string(objects) + " specular objects x " + std::to_string(layers) +
                           " layers of 6 faces at " + std::to_string(resolution) + "^2 texels need " +
                           mib(mapBytes(objects, layers, resolution)) + " MiB of maps, above the limit of " +
                           mib(kMaxBytes) + " MiB";
  if (!adaptive)
    throw api::ApiError(422, "limit-exceeded", "Server limit exceeded",
                        "/passes/specular/cube_resolution: " + need + ": lower cube_resolution or layers",
                        "/passes/specular/cube_resolution");
  if (mapBytes(objects, layers, lowered) > kMaxBytes)
    throw api::ApiError(422, "limit-exceeded", "Server limit exceeded",
                        "/passes/specular: " + need + ", and " + mib(mapBytes(objects, layers, lowered)) +
                            " MiB even at 16 texels: turn the pass off (passes.specular = false) or give the "
                            "scene fewer mirror-like and transmissive meshes",
                        "/passes/specular");
  return {lowered, need + ": drawn at " + std::to_string(lowered) + "^2" +
                       (keptForCaustics ? " (the caustics' photons see coarser maps)" : "")};
}

// A resolution the pass chooses from the view only lowers the maps, and 16 texels is its floor: the
// floor decides whether an adaptive choice fits.
void SpecularPass::validate(const Scene& scene, const FrameView& view, const Params& params) const {
  const MapResolution chosen = chooseMapResolution(scene, view, params, false);
  const int objects = static_cast<int>(specularMeshes(scene).size());
  fitMaps(objects, SpecularParams::from(params).layers, chosen.adaptive ? 16 : chosen.texels, chosen.adaptive, false);
}

void SpecularPass::prepare(const Scene& scene, const Params& params, FrameResources& res) {
  const SpecularParams p = SpecularParams::from(params);
  // Every default and range is the descriptor's (specular.json): Params has no fallback, and holds only
  // values api::techniqueParams checked against the schema (no clamp here repeats a range).
  maxDepth_ = p.max_depth;
  linearSteps_ = p.linear_steps;
  secantSteps_ = p.secant_steps;
  layers_ = p.layers;
  indirectBlock_ = p.map_indirect_block;
  minmax_ = p.minmax;

  const Bounds& sb = scene.features.bounds;
  objects_.clear();
  objectOfMesh_.assign(scene.meshes.size(), -1);
  for (std::size_t i : specularMeshes(scene)) {
    const MeshInstance& m = scene.meshes[i];
    Object o;
    o.mesh = i;
    const glm::vec3 ref = referencePoint(m);
    float extent = 0.f;
    for (int c = 0; c < 8; ++c) {
      const glm::vec3 corner((c & 1) ? sb.max.x : sb.min.x, (c & 2) ? sb.max.y : sb.min.y, (c & 4) ? sb.max.z : sb.min.z);
      extent = std::max(extent, glm::length(corner - ref));
    }
    o.gpu.referenceRadius = glm::vec4(ref, std::max(m.bounds.radius(), 1e-6f));
    // KHR_materials_volume: the object's medium, which the traced rays inside it cross (trace.glsl).
    const glm::vec3 sigmaT = scene.material(m.material).attenuationCoefficient();
    o.gpu.extent = glm::vec4(extent * 1.01f + 1e-6f, sigmaT);
    const Material& mat = scene.material(m.material);
    o.partlyDiffuse = !(mat.transmissionFactor >= 0.5f || mat.metallicFactor >= 0.5f) ||
                      (mat.isTransmissive() && mat.transmissionTexture.valid()) || mat.metallicRoughnessTexture.valid();
    objectOfMesh_[i] = static_cast<int>(objects_.size());
    objects_.push_back(o);
  }

  // The maps' resolution follows what the camera sees of the specular objects (issue 31): a map's face
  // needs about as many texels across as the largest object covers pixels (mapResolution), not a fixed
  // 256 whatever its size on screen; at most cube_resolution (chooseMapResolution).
  const MapResolution chosen = chooseMapResolution(scene, res.view(), params, res.owns("caustics", api::kPathLSDE));
  resolution_ = chosen.texels;
  largestObjectPixels_ = chosen.largestObjectPixels;
  causticsKeepMaps_ = chosen.keptForCaustics;
  const bool adaptive = chosen.adaptive;  // else a 422 above the memory bound below

  // The maps' memory (kMaxBytes), checked before anything is allocated.
  const int objectCount = static_cast<int>(objects_.size());
  const FittedMaps fitted = fitMaps(objectCount, layers_, resolution_, adaptive, causticsKeepMaps_);
  resolution_ = fitted.resolution;
  warning_ = fitted.warning;

  const int w = res.view().width, h = res.view().height;
  const int cubes = std::max<int>(1, objectCount * layers_);
  // The memory accountant (FrameResources::makeRoom) before the maps are allocated.
  const std::size_t mapAllocation =
      res.textureAllocation("specular_ldm_material", GL_TEXTURE_CUBE_MAP_ARRAY, GL_RGBA16F, resolution_, resolution_,
                            6 * cubes) +
      res.textureAllocation("specular_ldm_geometry", GL_TEXTURE_CUBE_MAP_ARRAY, GL_RGBA32F, resolution_, resolution_,
                            6 * cubes);
  res.makeRoom(mapAllocation);
  res.admit(mapAllocation, "/passes/specular/cube_resolution");
  gl::Texture& material = res.texture("specular_ldm_material", GL_TEXTURE_CUBE_MAP_ARRAY, GL_RGBA16F, resolution_,
                                      resolution_, 6 * cubes);
  gl::Texture& geometry = res.texture("specular_ldm_geometry", GL_TEXTURE_CUBE_MAP_ARRAY, GL_RGBA32F, resolution_,
                                      resolution_, 6 * cubes);
  // Material and geometry: nearest texels (a texel is one surface point; blending normals, F0/ior or
  // object indices across a silhouette is meaningless). The search reads a linearly filtered copy of
  // the distance (empty texels hold a huge value, so blends with them stay "empty").
  material.setFilter(GL_NEAREST, GL_NEAREST);
  geometry.setFilter(GL_NEAREST, GL_NEAREST);
  gl::Texture& distance = res.texture("specular_ldm_distance", GL_TEXTURE_CUBE_MAP_ARRAY, GL_R32F, resolution_,
                                      resolution_, 6 * cubes);
  res.texture("specular_ldm_albedo", GL_TEXTURE_CUBE_MAP_ARRAY, GL_RGBA8, resolution_, resolution_, 6 * cubes)
      .setFilter(GL_NEAREST, GL_NEAREST);
  distance.setFilter(GL_LINEAR, GL_LINEAR);
  res.texture("specular_ldm_depth", GL_TEXTURE_2D, GL_DEPTH_COMPONENT32F, resolution_, resolution_);
  res.texture("specular_ldm_face_diffuse", GL_TEXTURE_2D, GL_RGBA8, resolution_, resolution_)
      .setFilter(GL_NEAREST, GL_NEAREST);
  gl::Texture& peel = res.texture("specular_ldm_peel", GL_TEXTURE_2D, GL_RGBA32F, resolution_, resolution_);
  peel.setFilter(GL_NEAREST, GL_NEAREST);
  res.framebuffer("specular_ldm");
  // One face's photon sums over the gather's slices (shaders/specular/map_indirect.comp).
  res.texture("specular_ldm_indirect", GL_TEXTURE_2D, GL_RGBA32F, resolution_, resolution_)
      .setFilter(GL_NEAREST, GL_NEAREST);
  const int blocks = (resolution_ + mapIndirectBlock(resolution_, indirectBlock_) - 1) / mapIndirectBlock(resolution_, indirectBlock_);
  res.texture("specular_ldm_indirect_blocks", GL_TEXTURE_2D, GL_RGBA32F, blocks, blocks)
      .setFilter(GL_NEAREST, GL_NEAREST);
  res.texture("specular_ldm_indirect_fine", GL_TEXTURE_2D, GL_RGBA32F, (resolution_ + kFineBlock - 1) / kFineBlock,
              (resolution_ + kFineBlock - 1) / kFineBlock)
      .setFilter(GL_NEAREST, GL_NEAREST);
  res.texture("specular_ldm_indirect_fixup", GL_TEXTURE_2D, GL_R32F, resolution_, resolution_)
      .setFilter(GL_NEAREST, GL_NEAREST);
  res.buffer("specular_gather_counts", 3 * sizeof(std::uint32_t));
  res.buffer("specular_objects", std::max<std::size_t>(1, objects_.size()) * sizeof(GpuObject));
  res.buffer("specular_minmax", static_cast<std::size_t>(cubes) * 2 * sizeof(std::uint32_t));

  gl::Texture& specular = res.texture("specular");
  gl::Texture& depth = res.texture("specular_depth", GL_TEXTURE_2D, GL_DEPTH_COMPONENT32F, w, h);
  gl::Framebuffer& fb = res.framebuffer("specular");
  fb.attach(GL_COLOR_ATTACHMENT0, specular);
  fb.attach(GL_DEPTH_ATTACHMENT, depth);
  fb.setDrawBuffers({GL_COLOR_ATTACHMENT0});
  fb.checkComplete("SpecularPass::prepare");
  gl::Framebuffer& compose = res.framebuffer("specular_compose");
  attachBeauty(res, compose, GL_COLOR_ATTACHMENT0);
  compose.setDrawBuffers({GL_COLOR_ATTACHMENT0});
  compose.checkComplete("SpecularPass::prepare");
  declareDirectLightingResources(res);

  // The maps depend on the geometry, materials and lights (the uploaded scene's key) and on the map
  // shape, and on the photons that light their diffuse texels (execute(): photon_gi publishes its grid
  // in its prepare, after this one). Not on the tracing knobs (steps, depth, minmax): a sweep over
  // those reuses them.
  // And on the environment: its lights shade the texels and its residual their glossy lobe (the photon
  // set's digest covers it only when photon_gi runs).
  ibl::prepare(res);
  mapsIbl_ = res.owns("direct", api::kPathSkyGE) && ibl::modeFor(res) != ibl::kNone;
  const FrameView& v = res.view();
  digest_ = res.sceneKey() + "|res=" + std::to_string(resolution_) + "|layers=" + std::to_string(layers_) +
            "|objects=" + std::to_string(objects_.size()) + "|indirect_block=" + std::to_string(indirectBlock_) +
            "|env=" + v.lightingEnvironmentKey() + "|ambient=" + std::to_string(v.ambient.x) + "," +
            std::to_string(v.ambient.y) + "," + std::to_string(v.ambient.z) + "|ibl=" + (mapsIbl_ ? "1" : "0");
}

void SpecularPass::execute(PassContext& ctx) {
  FrameResources& res = ctx.resources;
  const FrameView& view = ctx.view;
  const int objectCount = static_cast<int>(objects_.size());
  std::vector<GpuObject> gpuObjects;
  for (const Object& o : objects_) gpuObjects.push_back(o.gpu);
  if (gpuObjects.empty()) gpuObjects.push_back(GpuObject{});
  gl::Buffer& objectBuffer = res.buffer("specular_objects");
  objectBuffer.upload(gpuObjects.data(), gpuObjects.size() * sizeof(GpuObject));
  gl::Buffer& minmax = res.buffer("specular_minmax");
  gl::Texture& material = res.texture("specular_ldm_material");
  gl::Texture& geometry = res.texture("specular_ldm_geometry");
  gl::Texture& distance = res.texture("specular_ldm_distance");
  gl::Texture& albedo = res.texture("specular_ldm_albedo");

  ctx.stats.counters["objects"] = objectCount;
  ctx.stats.counters["maps_rendered"] = 0;
  // Indirect light on the maps' diffuse texels: photon_gi's photons when it is planned (its grid is
  // uploaded by now), else none (the maps then hold emission and direct light only).
  const PhotonGrid* photons = publishedPhotonGrid(res);
  ctx.stats.counters["maps_indirect"] = photons ? 1 : 0;
  const std::string digest = digest_ + "|photons=" + (photons ? photons->digest : std::string("none"));
  // The maps live in the shared specular_ldm_* textures (FrameResources::refill).
  FrameResources::Refill maps = res.refill("specular_ldm_distance", digest, "specular_maps");
  if (!maps.hit() && objectCount > 0) {
    // Layered distance maps (thesis 5.1.1): per object and face, its front faces, its back faces, the
    // environment (everything else, closest surface) and depth-peeled environment layers.
    gl::Framebuffer& fb = res.framebuffer("specular_ldm");
    gl::Texture& depth = res.texture("specular_ldm_depth");
    gl::Texture& peel = res.texture("specular_ldm_peel");
    fb.attach(GL_DEPTH_ATTACHMENT, depth);
    const gl::Program& prog = ctx.shaders.program({"specular/map.vert", "specular/map.frag"});
    prog.use();
    bindDirectLighting(prog, res, ctx.gpu, static_cast<int>(ctx.view.lights.size()), 1);
    // The sky's glossy reflection on the maps' non-specular texels: the split-sum `direct` adds on
    // screen, under the same rule (direct owns L(sky)GE; otherwise photon_gi's glossy splats carry it
    // on screen and nothing in the maps).
    ibl::bind(res, prog, gpu::kUnitIblDfg, gpu::kUnitIblPrefiltered);
    if (!mapsIbl_) prog.set("u_iblMode", ibl::kNone);
    peel.bindUnit(kMapTextureUnitPeel);
    // The sky lights per texel after each face (shaders/specular/map_sky.comp), on the Lambertian albedo
    // map.frag writes to the face's scratch target.
    gl::Texture& faceDiffuse = res.texture("specular_ldm_face_diffuse");
    const gl::Program& sky = ctx.shaders.program({"specular/map_sky.comp"});
    const bool skyLights = ctx.view.skyLights() > 0;
    if (skyLights) bindDirectLighting(sky, res, ctx.gpu, static_cast<int>(ctx.view.lights.size()), 1);
    glViewport(0, 0, resolution_, resolution_);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);  // reversed-Z
    glDepthMask(GL_TRUE);
    glDisable(GL_CULL_FACE);  // front/back selection is done per fragment from the reference point
    glDisable(GL_BLEND);
    const float zero[4] = {0.f, 0.f, 0.f, 0.f};
    const float empty[4] = {kEmptyDistance, 0.f, 0.f, 0.f};
    const float depthClear = 0.f;
    const float sceneRadius = std::max(ctx.scene.features.bounds.radius(), 1e-6f);
    const GLint codeLoc = prog.uniformLocation("u_objectCode");
    int draws = 0;
    // One face of one layer of one object's maps is a stretch of GPU work (TransmissionTest's maps ran
    // minutes, deaf to the cancel flag).
    StretchGate gate(ctx.cancel);
    std::size_t drawnTriangles = 0, fullTriangles = 0;
    for (int k = 0; k < objectCount; ++k) {
      const Object& o = objects_[k];
      const glm::vec3 ref(o.gpu.referenceRadius);
      const float znear = sceneRadius * 1e-5f;
      prog.set("u_reference", &ref[0], 3);
      for (int l = 0; l < layers_; ++l)
        for (int f = 0; f < 6; ++f) {
          const int layerFace = (k * layers_ + l) * 6 + f;
          gate.check("specular's distance maps, object " + std::to_string(k) + " layer " + std::to_string(l));
          if (l >= 3) {
            // Depth peeling reads the previous layer of this face; copy it out first, since sampling a
            // texture that is also attached is a feedback loop.
            glCopyImageSubData(geometry.id(), GL_TEXTURE_CUBE_MAP_ARRAY, 0, 0, 0, layerFace - 6, peel.id(),
                               GL_TEXTURE_2D, 0, 0, 0, 0, resolution_, resolution_, 1);
          }
          fb.attach(GL_COLOR_ATTACHMENT0, material, 0, layerFace);
          fb.attach(GL_COLOR_ATTACHMENT1, geometry, 0, layerFace);
          fb.attach(GL_COLOR_ATTACHMENT2, distance, 0, layerFace);
          fb.attach(GL_COLOR_ATTACHMENT3, albedo, 0, layerFace);
          fb.attach(GL_COLOR_ATTACHMENT4, faceDiffuse);
          fb.setDrawBuffers({GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2, GL_COLOR_ATTACHMENT3,
                             GL_COLOR_ATTACHMENT4});
          fb.checkComplete("SpecularPass::execute (maps)");
          fb.bind();
          glClearNamedFramebufferfv(fb.id(), GL_COLOR, 0, zero);
          glClearNamedFramebufferfv(fb.id(), GL_COLOR, 1, zero);
          glClearNamedFramebufferfv(fb.id(), GL_COLOR, 2, empty);
          glClearNamedFramebufferfv(fb.id(), GL_COLOR, 3, zero);
          glClearNamedFramebufferfv(fb.id(), GL_COLOR, 4, zero);
          glClearNamedFramebufferfv(fb.id(), GL_DEPTH, 0, &depthClear);
          const glm::mat4 vp = cubeFaceViewProj(ref, f, znear);
          prog.setMat4("u_viewProj", &vp[0][0]);
          prog.set("u_faceMode", l == 0 ? 0 : l == 1 ? 1 : 2);
          prog.set("u_peel", l >= 3 ? 1 : 0);
          drawnTriangles += ctx.gpu.drawMeshes(prog, true, [&](std::size_t mesh) {
            const bool own = mesh == o.mesh;
            if ((l < 2) != own) return false;
            // Only what this face can see: a face spans 90 degrees (on MetalRoughSpheres, 12 objects x
            // 18 faces drew every sphere into every face: 9 s of maps at 64 texels).
            const Bounds& mb = ctx.scene.meshes[mesh].bounds;
            if (!own && !sphereInCubeFace(ref, f, mb.center(), mb.radius())) return false;
            glProgramUniform1i(prog.id(), codeLoc, objectOfMesh_[mesh] + 1);
            fullTriangles += ctx.scene.meshes[mesh].triangleCount();
            return true;
          }, [&](std::size_t mesh) {
            // The coarsest level of detail within a quarter of the face's texel (2 / resolution per unit
            // distance at the face's centre, larger towards its edges) where the mesh is nearest the
            // reference point. The object itself in full: its surface may pass through the reference
            // point (a flat mirror's centre).
            if (mesh == o.mesh) return 0.f;
            const Bounds& mb = ctx.scene.meshes[mesh].bounds;
            return 0.25f * (2.f / resolution_) * std::max(glm::length(mb.center() - ref) - mb.radius(), 0.f);
          });
          if (skyLights) {
            glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
            sky.use();
            sky.set("u_reference", &ref[0], 3);
            sky.set("u_layerFace", layerFace);
            sky.set("u_face", f);
            sky.set("u_size", resolution_);
            geometry.bindImage(0, GL_READ_ONLY, 0, true, 0);
            faceDiffuse.bindImage(1, GL_READ_ONLY);
            material.bindImage(2, GL_READ_WRITE, 0, true, 0);
            glDispatchCompute((resolution_ + 7) / 8, (resolution_ + 7) / 8, 1);
            glMemoryBarrier(GL_FRAMEBUFFER_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
            prog.use();
          }
          gate.issued();
          ++draws;
        }
    }
    if (photons && photons->count > 0) {
      // L D+ D S+ E: photon_gi's estimate at every diffuse texel of the environment layers (layer >= 2;
      // layers 0 and 1 hold the object itself, gathered too where some of its texels are diffuse:
      // Object::partlyDiffuse), one face at a time, in slices (llvmpipe's loop limit).
      glMemoryBarrier(GL_ALL_BARRIER_BITS);
      const gl::Program& gather = ctx.shaders.program({"specular/map_indirect.comp"});
      gather.use();
      photons->bind();
      geometry.bindImage(0, GL_READ_ONLY, 0, true, 0);
      albedo.bindImage(1, GL_READ_ONLY, 0, true, 0);
      material.bindImage(2, GL_READ_WRITE, 0, true, 0);
      res.texture("specular_ldm_indirect").bindImage(3, GL_READ_WRITE);
      gl::Texture& blockSamples = res.texture("specular_ldm_indirect_blocks");
      gl::Texture& fineSamples = res.texture("specular_ldm_indirect_fine");
      res.texture("specular_ldm_indirect_fixup").bindImage(5, GL_READ_WRITE);
      gl::Buffer& gatherCounts = res.buffer("specular_gather_counts");
      const std::uint32_t noGathers[3] = {0, 0, 0};
      gatherCounts.upload(noGathers, sizeof(noGathers));
      gatherCounts.bindBase(GL_SHADER_STORAGE_BUFFER, gpu::kBindingMapGatherCounts);
      const int block = mapIndirectBlock(resolution_, indirectBlock_);
      const int blocks = (resolution_ + block - 1) / block;
      const int fineBlocks = (resolution_ + kFineBlock - 1) / kFineBlock;
      gather.set("u_kernel", photons->kernel);
      gather.set("u_planeTolerance", kPhotonPlaneTolerance);
      gather.set("u_normalCosine", kPhotonNormalCosine);
      gather.set("u_renormalize", photons->renormalize ? 1 : 0);
      gather.set("u_minKernelMass", kPhotonMinKernelMass);
      gather.set("u_hMin", photons->minRadius);
      gather.set("u_size", resolution_);
      gather.set("u_gridOrigin", &photons->origin[0], 3);
      gather.set("u_cellSize", photons->cellSize);
      gather.set("u_walkReach", std::min(photons->walkReach, 1e30f));
      const int dims[3] = {photons->dims.x, photons->dims.y, photons->dims.z};
      glProgramUniform3iv(gather.id(), gather.uniformLocation("u_gridDims"), 1, dims);
      glProgramUniform1ui(gather.id(), gather.uniformLocation("u_sliceLength"), kPhotonGatherSlice);
      const std::uint32_t slices =
          std::max<std::uint32_t>(1, (photons->maxPerCell + kPhotonGatherSlice - 1) / kPhotonGatherSlice);
      int dispatches = 0;
      for (int k = 0; k < objectCount; ++k) {
        const glm::vec3 ref(objects_[k].gpu.referenceRadius);
        gather.set("u_reference", &ref[0], 3);
        for (int l = objects_[k].partlyDiffuse ? 0 : 2; l < layers_; ++l)
          for (int f = 0; f < 6; ++f) {
            gate.check("specular's indirect light in the maps, object " + std::to_string(k));
            gather.set("u_layerFace", (k * layers_ + l) * 6 + f);
            gather.set("u_face", f);
            // mode 1 (blocks > 1): the block samples; 2: spread them, mark the texels none fits; 0: gather
            // at every texel (blocks of 1) or at the marked ones.
            auto gatherSlices = [&](int mode, int fixupOnly, int size) {
              gather.set("u_mode", mode);
              gather.set("u_fixupOnly", fixupOnly);
              for (std::uint32_t sl = 0; sl < slices; ++sl) {
                glProgramUniform1ui(gather.id(), gather.uniformLocation("u_sliceBegin"), sl * kPhotonGatherSlice);
                gather.set("u_first", sl == 0 ? 1 : 0);
                gather.set("u_last", sl + 1 == slices ? 1 : 0);
                glDispatchCompute((size + 7) / 8, (size + 7) / 8, 1);
                glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
                ++dispatches;
              }
            };
            // One level of block samples (mode 1) and their spread (mode 2); the second level (fixupOnly
            // 1: blocks of 2) works on the texels the first left marked (map_indirect.comp).
            auto blockLevel = [&](int size, int count, gl::Texture& samples, int fixupOnly) {
              gather.set("u_block", size);
              samples.bindImage(4, GL_READ_WRITE);
              gatherSlices(1, fixupOnly, count);
              gather.set("u_mode", 2);
              glDispatchCompute((resolution_ + 7) / 8, (resolution_ + 7) / 8, 1);
              glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
            };
            if (block > 1) {
              blockLevel(block, blocks, blockSamples, 0);
              if (block > kFineBlock) blockLevel(kFineBlock, fineBlocks, fineSamples, 1);
              gatherSlices(0, 1, resolution_);
            } else {
              gatherSlices(0, 0, resolution_);
            }
            gate.issued();
          }
      }
      ctx.stats.counters["maps_indirect_dispatches"] = dispatches;
      ctx.stats.counters["maps_indirect_block"] = block;
      // The gathers per kind (read once per build of the maps: their texels are what the blocks save).
      std::uint32_t gathers[3];
      glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
      gatherCounts.download(gathers, sizeof(gathers));
      ctx.stats.counters["maps_indirect_block_gathers"] = gathers[0];
      ctx.stats.counters["maps_indirect_fine_gathers"] = gathers[1];
      ctx.stats.counters["maps_indirect_texel_gathers"] = gathers[2];
    }
    // Min-max distance per layer (thesis Fig. 5.3).
    std::vector<std::uint32_t> init(static_cast<std::size_t>(objectCount) * layers_ * 2);
    for (std::size_t i = 0; i < init.size(); i += 2) {
      const float big = std::numeric_limits<float>::max();
      std::memcpy(&init[i], &big, sizeof(float));
      init[i + 1] = 0u;
    }
    minmax.upload(init.data(), init.size() * sizeof(std::uint32_t));
    glMemoryBarrier(GL_ALL_BARRIER_BITS);
    const gl::Program& reduce = ctx.shaders.program({"specular/minmax.comp"});
    reduce.use();
    geometry.bindImage(0, GL_READ_ONLY, 0, true, 0);
    minmax.bindBase(GL_SHADER_STORAGE_BUFFER, kSpecularMinmaxBinding);
    reduce.set("u_size", resolution_);
    for (int c = 0; c < objectCount * layers_; ++c) {
      reduce.set("u_cube", c);
      glDispatchCompute((resolution_ + 7) / 8, (resolution_ + 7) / 8, 6);
    }
    glMemoryBarrier(GL_ALL_BARRIER_BITS);
    ctx.stats.counters["maps_rendered"] = draws;
    // The levels of detail drawn (GpuScene::drawMeshes): triangles over all faces, against the full meshes'.
    ctx.stats.counters["triangles_drawn"] = static_cast<double>(drawnTriangles);
    ctx.stats.counters["triangles_full"] = static_cast<double>(fullTriangles);
    maps.written();
  }
  SpecularMaps published;
  published.material = &material;
  published.geometry = &geometry;
  published.distance = &distance;
  published.albedo = &albedo;
  published.objects = &objectBuffer;
  published.minmax = &minmax;
  published.layers = layers_;
  published.resolution = resolution_;
  published.digest = res.heldDigest("specular_ldm_distance");
  publishSpecularMaps(res, published);
  ctx.stats.counters["cube_resolution"] = resolution_;
  ctx.stats.counters["map_bytes"] = mapBytes(static_cast<int>(objects_.size()), layers_, resolution_);
  if (!warning_.empty()) ctx.stats.warnings.push_back(warning_);
  ctx.stats.counters["largest_object_pixels"] = std::isfinite(largestObjectPixels_) ? largestObjectPixels_ : -1.0;
  ctx.stats.counters["maps_kept_for_caustics"] = causticsKeepMaps_ ? 1 : 0;
  ctx.stats.counters["layers"] = layers_;

  // Trace from the rasterised first hits of the specular objects.
  gl::Framebuffer& fb = res.framebuffer("specular");
  fb.bind();
  glViewport(0, 0, view.width, view.height);
  const float zero[4] = {0.f, 0.f, 0.f, 0.f};
  const float depthClear = 0.f;
  glClearNamedFramebufferfv(fb.id(), GL_COLOR, 0, zero);
  glClearNamedFramebufferfv(fb.id(), GL_DEPTH, 0, &depthClear);
  if (objectCount > 0) {
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);
    glDepthMask(GL_TRUE);
    glDisable(GL_CULL_FACE);
    glDisable(GL_BLEND);
    using gbuffer::Attachment;
    gbuffer::bind(res, {Attachment::Position, Attachment::Normal, Attachment::Albedo, Attachment::Material,
                        Attachment::Emission});
    published.bind();  // the maps, and the albedo for mirrors' F0 (specular/ldm.glsl, mapSpecularTexel)
    const gl::Program& prog = ctx.shaders.program({"specular/map.vert", "specular/specular.frag"});
    prog.use();
    prog.setMat4("u_viewProj", &view.viewProj[0][0]);
    // The direct pass uploads the environment map (declared: direct's output, this pass's optional input).
    const bool environment = view.environment && res.hasTexture("environment_map");
    if (environment) res.texture("environment_map").bindUnit(gpu::kUnitEnvironment);
    prog.set("u_hasEnvironment", environment ? 1 : 0);
    prog.set("u_maxDepth", maxDepth_);
    prog.set("u_minWeight", kMinBranchWeight);
    prog.set("u_layers", layers_);
    prog.set("u_linearSteps", linearSteps_);
    prog.set("u_secantSteps", secantSteps_);
    prog.set("u_minmax", minmax_ ? 1 : 0);
    prog.set("u_cubeResolution", static_cast<float>(resolution_));
    const GLint objectLoc = prog.uniformLocation("u_object");
    ctx.gpu.drawMeshes(prog, false, [&](std::size_t mesh) {
      if (objectOfMesh_[mesh] < 0) return false;
      glProgramUniform1i(prog.id(), objectLoc, objectOfMesh_[mesh]);
      return true;
    });
  }
  res.markWritten("specular");

  // beauty += specular.
  gl::Framebuffer& compose = res.framebuffer("specular_compose");
  compose.bind();
  glDisable(GL_DEPTH_TEST);
  BeautyWrite beauty = BeautyWrite::drawBuffer(res, 0);
  res.texture("specular").bindUnit(0);
  const gl::Program& composeProg = ctx.shaders.program({"common/fullscreen.vert", "specular/compose.frag"});
  composeProg.use();
  glDrawArrays(GL_TRIANGLES, 0, 3);
  beauty.commit();
  ctx.stats.counters["max_depth"] = maxDepth_;
  ctx.stats.counters["linear_steps"] = linearSteps_;
  ctx.stats.counters["secant_steps"] = secantSteps_;
}

}  // namespace radiant
