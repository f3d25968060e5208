#include "renderer/scene/CostCounts.h"

#include "renderer/shading/SpecularObjects.h"

namespace radiant {

api::SceneCounts sceneCostCounts(const Scene& scene, const std::vector<api::ParticleSystem>& media) {
  api::SceneCounts c;
  c.particles = static_cast<double>(mediaFeatures(scene.features, media).particles);
  // light_volumes' buildBeams (renderer/techniques/light_volumes/Beams.cpp): per light and narrow-lobe
  // scatterer triangle a reflected beam, and on a transmissive one a refracted beam as well.
  double scatterers = 0;
  for (const auto& m : scene.meshes) {
    const Material& mat = scene.material(m.material);
    if (mat.scattersNarrowLobe()) scatterers += double(m.triangleCount()) * (mat.isTransmissive() ? 2.0 : 1.0);
  }
  c.beams = scatterers * double(scene.lights.size());
  c.specularObjects = static_cast<double>(specularMeshes(scene).size());
  return c;
}

}  // namespace radiant
