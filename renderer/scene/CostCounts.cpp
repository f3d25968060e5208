#include "renderer/scene/CostCounts.h"

namespace radiant {

api::SceneCounts sceneCostCounts(const Scene& scene, const std::vector<api::ParticleSystem>& media) {
  api::SceneCounts c;
  c.particles = static_cast<double>(mediaFeatures(scene.features, media).particles);
  return c;
}

}  // namespace radiant
