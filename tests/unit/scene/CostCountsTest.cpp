// The preset table's scene variables (api::SceneCounts) as renderer/scene/CostCounts.cpp computes them
// for the budget chooser: the particles of the scene's systems plus the request's, light_volumes'
// beams (per light, one per triangle of a narrow-lobe scatterer, two on a transmissive one) and the
// specular pass's objects, exactly.
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

TEST(CostCounts, ParticlesOfSceneAndRequestAndBeamsOfNarrowLobeScatterers) {
  Scene scene;
  Material mirror, glass, rough, diffuse;
  mirror.metallicFactor = 1.f, mirror.roughnessFactor = 0.f;
  glass.metallicFactor = 0.f, glass.roughnessFactor = 0.1f, glass.transmissionFactor = 1.f;
  rough.metallicFactor = 1.f, rough.roughnessFactor = 0.8f;  // above kNarrowLobeRoughness: no beams
  diffuse.metallicFactor = 0.f, diffuse.roughnessFactor = 1.f;
  scene.materials = {mirror, glass, rough, diffuse};
  scene.meshes = {triangles(4, 0), triangles(3, 1), triangles(5, 2), triangles(10, 3), triangles(2, -1)};
  scene.lights.resize(2);
  scene.media = {system(5)};
  scene.features = computeFeatures(scene);

  const api::SceneCounts bare = sceneCostCounts(scene, {});
  EXPECT_EQ(bare.particles, 5.0);
  EXPECT_EQ(bare.beams, 2.0 * (4 + 2 * 3));  // 2 lights x (4 mirror + 3 glass reflected and refracted)
  EXPECT_EQ(bare.specularObjects, 2.0);      // the mirror and the glass mesh (roughness 0.8 metal is no mirror)
  const api::SceneCounts withMedia = sceneCostCounts(scene, {system(7), system(0)});
  EXPECT_EQ(withMedia.particles, 12.0);
  EXPECT_EQ(withMedia.beams, bare.beams);
  scene.lights.clear();
  EXPECT_EQ(sceneCostCounts(scene, {}).beams, 0.0);  // no light, no beam
}

// The built-in scenes the preset table's sweeps use: the counts bench/presets.py fitted against.
TEST(CostCounts, TheBuiltinScenesCounts) {
  EXPECT_EQ(sceneCostCounts(loadBuiltinScene("explosion"), {}).particles, 115.0 + 28 + 16);
  EXPECT_EQ(sceneCostCounts(loadBuiltinScene("cornell_glass"), {}).beams, 1920.0);  // 960-triangle glass sphere
  EXPECT_EQ(sceneCostCounts(loadBuiltinScene("cornell_mirror"), {}).beams, 960.0);
  EXPECT_EQ(sceneCostCounts(loadBuiltinScene("cornell_glossy"), {}).beams, 12.0);
  EXPECT_EQ(sceneCostCounts(loadBuiltinScene("cornell_glass"), {}).specularObjects, 1.0);  // specular's canonical scene
  EXPECT_EQ(sceneCostCounts(loadBuiltinScene("cornell_mirror"), {}).specularObjects, 1.0);
  EXPECT_EQ(sceneCostCounts(loadBuiltinScene("cornell_box"), {}).specularObjects, 0.0);
}

}  // namespace radiant
