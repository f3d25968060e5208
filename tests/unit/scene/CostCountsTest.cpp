// The preset table's scene variable the frame itself holds (api::SceneCounts), as renderer/scene/
// CostCounts.cpp computes it for the budget chooser: the particles of the scene's systems plus the
// request's, exactly. The techniques' own variables (beams, specular objects) are tested with them
// (tests/unit/frame/TechniqueCostCountsTest.cpp).
#include <gtest/gtest.h>

#include "renderer/scene/BuiltinScenes.h"
#include "renderer/scene/CostCounts.h"

namespace radiant {
namespace {

MeshInstance triangles(int n, int material) {
  MeshInstance m;
  m.material = material;
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) {
      m.positions.push_back(glm::vec3(float(i), float(k == 1), float(k == 2)));
      m.indices.push_back(static_cast<std::uint32_t>(3 * i + k));
    }
  }
  return m;
}

api::ParticleSystem system(int n) {
  api::ParticleSystem s;
  s.particles.resize(static_cast<std::size_t>(n));
  return s;
}

}  // namespace

TEST(CostCounts, ParticlesOfSceneAndRequest) {
  Scene scene;
  scene.materials = {Material{}};
  scene.meshes = {triangles(4, 0)};
  scene.media = {system(5)};
  scene.features = computeFeatures(scene);
  EXPECT_EQ(sceneCostCounts(scene, {}).particles, 5.0);
  EXPECT_EQ(sceneCostCounts(scene, {system(7), system(0)}).particles, 12.0);
  // The built-in explosion, the media techniques' canonical scene: what bench/presets.py fitted against.
  EXPECT_EQ(sceneCostCounts(loadBuiltinScene("explosion"), {}).particles, 115.0 + 28 + 16);
}

}  // namespace radiant
