#pragma once
// The CPU ray-tracing core's BVH as frame-level derived data: one per scene digest, shared by every
// pass with a CPU side (the reference, photon tracing), cached and reported as "ray_scene" in the
// stats like every derived datum.
#include "renderer/frame/FrameResources.h"
#include "renderer/frame/FrameView.h"
#include "renderer/raytracing/Lights.h"
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

// The frame environment map's importance-sampling distribution (rt::EnvironmentDistribution), built
// once per environment digest and size and reported as "environment_distribution"; null when the
// frame has no map (a uniform sky needs none).
struct SharedEnvironmentDistribution {
  std::shared_ptr<const rt::EnvironmentDistribution> distribution;
};
inline std::shared_ptr<const rt::EnvironmentDistribution> environmentDistribution(FrameResources& res,
                                                                                  const FrameView& view) {
  if (!view.environment) return nullptr;
  const Image& env = *view.environment;
  const std::string key = view.environmentKey + "|" + std::to_string(env.width) + "x" + std::to_string(env.height) +
                          "x" + std::to_string(env.channels);
  return res.cached<SharedEnvironmentDistribution>("environment_distribution", key, [&] {
              return std::make_unique<SharedEnvironmentDistribution>(
                  SharedEnvironmentDistribution{rt::EnvironmentDistribution::build(env, nullptr, res.cancel())});
            })
      .distribution;
}

}  // namespace radiant
