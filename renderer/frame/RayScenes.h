#pragma once
// The CPU ray-tracing core's BVH as frame-level derived data: one per scene digest, shared by every
// pass with a CPU side (the reference, photon tracing), cached and reported as "ray_scene" in the
// stats like every derived datum.
#include "renderer/frame/FrameResources.h"
#include "renderer/raytracing/RayScene.h"

namespace radiant {

// The entry owns a copy of the scene: it must not dangle when the caller's Scene goes away.
struct SharedRayScene {
  Scene scene;
  rt::RayScene rays;
  explicit SharedRayScene(const Scene& s) : scene(s), rays(scene) {}
};

inline const rt::RayScene& sharedRayScene(FrameResources& res, const Scene& scene) {
  return res.cached<SharedRayScene>("ray_scene", res.sceneKey(), [&] { return std::make_unique<SharedRayScene>(scene); })
      .rays;
}

}  // namespace radiant
