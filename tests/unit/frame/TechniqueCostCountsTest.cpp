// The cost models' scene variables each technique counts beside its own code (Technique::
// addCostCounts, assembled by FramePlanner's costCounts with the frame's particles): light_volumes'
// beams (per light, one per triangle of a narrow-lobe scatterer, two on a transmissive one) and the
// specular pass's objects, exactly, and on the built-in scenes the counts bench/presets.py fitted
// the preset table against.
#include <gtest/gtest.h>

#include "api/Presets.h"
#include "renderer/frame/FramePlanner.h"
#include "renderer/scene/BuiltinScenes.h"
#include "renderer/techniques/Registry.h"

namespace radiant {
namespace {

MeshInstance triangles(int n, int material) {
  MeshInstance m;
  m.material = material;
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) {
      m.positions.push_back(glm::vec3(float(i), float(k == 1), float(k == 2)));
      m.indices.push_back(static_cast<std::uint32_t>(3 * i + k));
    }
  return m;
}

api::SceneCounts counted(const Scene& scene, const std::vector<api::ParticleSystem>& media = {}) {
  const auto registry = createTechniques();
  std::vector<Technique*> all;
  for (const auto& t : registry) all.push_back(t.get());
  return costCounts(all, scene, media);
}

TEST(TechniqueCostCounts, BeamsOfNarrowLobeScatterersAndSpecularObjects) {
  Scene scene;
  Material mirror, glass, rough, diffuse;
  mirror.metallicFactor = 1.f, mirror.roughnessFactor = 0.f;
  glass.metallicFactor = 0.f, glass.roughnessFactor = 0.1f, glass.transmissionFactor = 1.f;
  rough.metallicFactor = 1.f, rough.roughnessFactor = 0.8f;  // above kNarrowLobeRoughness: no beams
  diffuse.metallicFactor = 0.f, diffuse.roughnessFactor = 1.f;
  scene.materials = {mirror, glass, rough, diffuse};
  scene.meshes = {triangles(4, 0), triangles(3, 1), triangles(5, 2), triangles(10, 3), triangles(2, -1)};
  scene.lights.resize(2);
  api::ParticleSystem media;
  media.particles.resize(5);
  scene.media = {media};
  scene.features = computeFeatures(scene);

  const api::SceneCounts c = counted(scene, {media});
  EXPECT_EQ(c.particles, 10.0);          // the scene's and the request's (sceneCostCounts)
  EXPECT_EQ(c.beams, 2.0 * (4 + 2 * 3));  // 2 lights x (4 mirror + 3 glass reflected and refracted)
  EXPECT_EQ(c.specularObjects, 2.0);      // the mirror and the glass mesh (roughness 0.8 metal is no mirror)
  scene.lights.clear();
  EXPECT_EQ(counted(scene).beams, 0.0);  // no light, no beam
}

// The built-in scenes the preset table's sweeps use: the counts bench/presets.py fitted against.
TEST(TechniqueCostCounts, TheBuiltinScenesCounts) {
  EXPECT_EQ(counted(loadBuiltinScene("cornell_glass")).beams, 1920.0);  // 960-triangle glass sphere
  EXPECT_EQ(counted(loadBuiltinScene("cornell_mirror")).beams, 960.0);
  EXPECT_EQ(counted(loadBuiltinScene("cornell_glossy")).beams, 12.0);
  EXPECT_EQ(counted(loadBuiltinScene("cornell_glass")).specularObjects, 1.0);  // specular's canonical scene
  EXPECT_EQ(counted(loadBuiltinScene("cornell_mirror")).specularObjects, 1.0);
  EXPECT_EQ(counted(loadBuiltinScene("cornell_box")).specularObjects, 0.0);
}

}  // namespace
}  // namespace radiant
