#pragma once
// The one CPU ray-tracing core (ARCHITECTURE.md, "One ray-tracing core, many integrators"): an Embree
// BVH over a Scene, closest-hit and shadow queries that pass through alpha-masked surfaces, and the
// glTF material decoded at a hit into the BSDF of Bsdf.h. The reference path tracer and the photon
// tracer both use it; nothing here knows about GL.
//
// Conventions: emission comes from the front face (counter-clockwise winding) only unless the
// material is doubleSided; surfaces otherwise scatter on both sides. MASK surfaces below the cutoff
// and BLEND surfaces with probability (1 - alpha) are passed through.
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "renderer/raytracing/Bsdf.h"
#include "renderer/raytracing/Sampler.h"
#include "renderer/scene/Scene.h"

namespace radiant::rt {

inline constexpr float kInf = std::numeric_limits<float>::infinity();

struct Ray {
  glm::vec3 org, dir;
  float tnear = 0.f, tfar = kInf;
};

// What a closest hit tells the shader.
struct SurfaceHit {
  int mesh = -1, prim = -1;
  float b0 = 0.f, b1 = 0.f, b2 = 0.f;
  glm::vec3 p{0.f};
  glm::vec3 ng{0.f};  // unit geometric normal of the winding (front face = counter-clockwise)
  float offsetScale = 0.f;
  float distance = 0.f;  // from the original ray origin
};

// The bounce cap every tracer defaults to (the schemas' max_bounces default: reference, photon_gi,
// compare): a safety net far above what Russian roulette (survival at most 0.95 per event) lets a path
// reach, so light transport is unbiased by default (issue 32).
inline constexpr int kDefaultMaxBounces = 1024;

// A tracer thread's tally: rays traced, and paths (or photons) that the bounce cap ended while they
// were still alive (Russian roulette ends the others; a capped path is the truncation bias the cap adds,
// reported in the stats as paths_capped / photons_capped).
struct RayCounter {
  std::uint64_t rays = 0;
  std::uint64_t capped = 0;
};

// The BSDF at a hit, in its shading frame.
struct Shading {
  GltfBsdf bsdf;
  ShadingFrame frame;
  glm::vec3 ngFacing;  // geometric normal on wo's side
};

// An emissive triangle (light index = emissiveOffset[mesh] + prim).
struct TriangleLight {
  int mesh, prim;
  float area;
};

inline float maxAbs(const glm::vec3& v) { return std::max(std::abs(v.x), std::max(std::abs(v.y), std::abs(v.z))); }

class RayScene {
public:
  // Builds the BVH (one triangle geometry per MeshInstance) and the emissive-triangle list. Keeps a
  // pointer to `scene`, which must outlive the RayScene. Throws std::invalid_argument on an index out
  // of range, std::runtime_error on an Embree failure.
  explicit RayScene(const Scene& scene);
  ~RayScene();
  RayScene(const RayScene&) = delete;
  RayScene& operator=(const RayScene&) = delete;

  const Scene& scene() const { return *scene_; }
  const Material& materialOf(int mesh) const { return scene_->material(scene_->meshes[mesh].material); }
  // Its std430 record (toGpuMaterial), packed once: what the shared decoder reads
  // (renderer/scene/MaterialDecode.h).
  const gpu::Material& materialRecordOf(int mesh) const { return materialRecords_[mesh]; }

  // Closest hit, passing through alpha-masked and blended surfaces.
  bool intersect(Ray ray, SurfaceHit& hit, Sampler& sampler, RayCounter& counter) const;
  // Any hit along the ray (with the same alpha rules).
  bool occluded(const Ray& ray, Sampler& sampler, RayCounter& counter) const;

  // Origin for a ray leaving p in direction dir, pushed off the surface to dir's side of ng. The
  // offset is a number of float ulps of the largest coordinate involved, so it follows the scene's
  // scale (millimetres and kilometres both neither self-intersect nor leak).
  static glm::vec3 offsetOrigin(const glm::vec3& p, const glm::vec3& ng, float scale, const glm::vec3& dir);

  // The material at a hit as a BSDF with its shading frame (interpolated, normal-mapped normal).
  Shading shade(const SurfaceHit& hit, const glm::vec3& wo, TransportMode mode = TransportMode::Radiance) const;
  // Emitted radiance towards -dir (zero from the back of a single-sided emitter).
  glm::vec3 emissionAt(const SurfaceHit& hit, const glm::vec3& dir) const;
  // Texture `ref` at the hit: its uv set through its KHR_texture_transform, then the glTF sampler.
  glm::vec4 textureAt(const TextureRef& ref, const SurfaceHit& hit, bool srgb) const;
  // KHR_materials_unlit: the radiance an unlit surface shows (its decoded base colour, from both sides).
  glm::vec3 unlitRadiance(const SurfaceHit& hit) const;

  // A point on triangle `prim` of `mesh` from barycentrics (b0, b1), as a hit.
  SurfaceHit pointOn(int mesh, int prim, glm::vec2 b) const;

  // Emissive triangles with their areas; their sampling is in Lights.h.
  const std::vector<TriangleLight>& triangleLights() const { return triangleLights_; }
  int emissiveOffset(int mesh) const { return emissiveOffset_[mesh]; }

private:
  bool passesThrough(const SurfaceHit& hit, Sampler& sampler) const;
  SurfaceHit makeHit(int mesh, int prim, float u, float v, const glm::vec3& origin) const;

  const Scene* scene_;
  std::vector<gpu::Material> materialRecords_;  // per mesh
  struct Embree;
  std::unique_ptr<Embree> embree_;
  bool anyAlpha_ = false;
  std::vector<int> emissiveOffset_;
  std::vector<TriangleLight> triangleLights_;
};

}  // namespace radiant::rt
