#include <gtest/gtest.h>

#include <filesystem>

#include "renderer/scene/BuiltinScenes.h"
#include "renderer/scene/GltfLoader.h"

namespace radiant {
namespace {

TEST(BuiltinScenes, NamesAreTheShippedScenes) {
  EXPECT_EQ(builtinSceneNames(),
            (std::vector<std::string>{"ao_creases", "cornell_box", "cornell_glass", "cornell_glossy", "cornell_mirror", "explosion"}));
}

TEST(BuiltinScenes, UnknownNameIsASceneError) {
  EXPECT_THROW(builtinSceneSource("nope"), SceneError);
  EXPECT_THROW(builtinScenePath("nope"), SceneError);
  EXPECT_THROW(loadBuiltinScene("../cornell_box"), SceneError);
}

TEST(BuiltinScenes, EmbeddedTextMatchesTheFileOnDisk) {
  for (const auto& name : builtinSceneNames()) {
    const std::string path = builtinScenePath(name);
    ASSERT_TRUE(std::filesystem::exists(path)) << path;
    EXPECT_EQ(std::filesystem::path(path).parent_path(), std::filesystem::path(RADIANT_SCENES_DIR));
    const Scene fromFile = loadScene(path);
    const Scene embedded = loadBuiltinScene(name);
    EXPECT_EQ(fromFile.digest, embedded.digest) << name;
    EXPECT_EQ(embedded.name, name);
    EXPECT_LT(builtinSceneSource(name).size(), 200u * 1024u) << name;
  }
}

TEST(BuiltinScenes, EveryOneHasOnePointLightACameraAndGeometry) {
  for (const auto& name : builtinSceneNames()) {
    if (name == "explosion") continue;  // the media scene: two lights, no sphere (ExplosionIsThesisChapter7s)
    const Scene s = loadBuiltinScene(name);
    EXPECT_EQ(s.features.pointLights, 1) << name;
    EXPECT_EQ(s.features.lightCount(), 1) << name;
    EXPECT_TRUE(s.features.hasCamera) << name;
    EXPECT_GT(s.features.triangles, 960u) << name;  // the sphere alone is 32 x 16 x 2 - 64 = 960 triangles
    EXPECT_EQ(s.features.emissiveTriangles, 0) << name;
    EXPECT_EQ(s.digest.substr(0, 7), "sha256:") << name;
    // The light is inside the scene's bounds (under the ceiling / above the floor).
    const glm::vec3 p = s.lights[0].position;
    EXPECT_GT(p.y, s.features.bounds.min.y) << name;
    EXPECT_LT(p.y, s.features.bounds.max.y + 1.f) << name;
  }
}

TEST(BuiltinScenes, ExplosionIsThesisChapter7s) {
  // Thesis 7.3: 115 fire, 28 smoke and 16 dust particles, in a room with a camera and lights.
  const Scene s = loadBuiltinScene("explosion");
  ASSERT_EQ(s.media.size(), 3u);
  EXPECT_EQ(s.media[0].kind, api::MediumKind::Fire);
  EXPECT_EQ(s.media[0].particles.size(), 115u);
  EXPECT_EQ(s.media[1].kind, api::MediumKind::Smoke);
  EXPECT_EQ(s.media[1].particles.size(), 28u);
  EXPECT_EQ(s.media[2].kind, api::MediumKind::Dust);
  EXPECT_EQ(s.media[2].particles.size(), 16u);
  for (const auto& p : s.media[0].particles) {
    EXPECT_GE(p.temperature, 2500.f);  // Fig. 7.10: fire spans 2500-3200 K
    EXPECT_LT(p.temperature, 3200.f);
  }
  EXPECT_EQ(s.features.particles, 159u);
  EXPECT_EQ(s.features.emissiveMedia, 1);
  EXPECT_EQ(s.features.scatteringMedia, 2);
  EXPECT_TRUE(s.features.hasCamera);
  EXPECT_EQ(s.features.pointLights, 2);
  EXPECT_TRUE(s.warnings.empty());
}

TEST(BuiltinScenes, CornellBoxLayout) {
  const Scene s = loadBuiltinScene("cornell_box");
  // ~1 m interior: x in [-0.5, 0.5], y in [0, 1], z in [-0.5, 0.5].
  EXPECT_NEAR(s.features.bounds.min.x, -0.5f, 1e-5f);
  EXPECT_NEAR(s.features.bounds.max.x, 0.5f, 1e-5f);
  EXPECT_NEAR(s.features.bounds.min.y, 0.f, 1e-5f);
  EXPECT_NEAR(s.features.bounds.max.y, 1.f, 1e-5f);
  EXPECT_EQ(s.features.specularMaterials, 0);
  EXPECT_EQ(s.features.transmissiveMaterials, 0);
  // Red on the left (-X), green on the right (+X), walls facing inwards.
  bool sawRed = false, sawGreen = false;
  for (const auto& mi : s.meshes) {
    const Material& m = s.material(mi.material);
    if (mi.name == "left_wall") {
      sawRed = true;
      EXPECT_GT(m.baseColorFactor.r, 5.f * m.baseColorFactor.g);
      EXPECT_NEAR(mi.normals[0].x, 1.f, 1e-5f);
    }
    if (mi.name == "right_wall") {
      sawGreen = true;
      EXPECT_GT(m.baseColorFactor.g, 2.f * m.baseColorFactor.r);
      EXPECT_NEAR(mi.normals[0].x, -1.f, 1e-5f);
    }
  }
  EXPECT_TRUE(sawRed && sawGreen);
  // The camera is in front of the open side, looking in (-Z).
  EXPECT_GT(s.camera.world[3].z, 1.f);
  EXPECT_NEAR(s.camera.world[2].z, 1.f, 1e-5f);  // its -Z axis points into the box
  EXPECT_GT(s.lights[0].intensity, 2.f);
  EXPECT_LT(s.lights[0].intensity, 6.f);
  EXPECT_GT(s.lights[0].position.y, 0.8f);
}

TEST(BuiltinScenes, MirrorAndGlassVariants) {
  const Scene mirror = loadBuiltinScene("cornell_mirror");
  EXPECT_GE(mirror.features.specularMaterials, 1);
  EXPECT_EQ(mirror.features.transmissiveMaterials, 0);
  const Scene glass = loadBuiltinScene("cornell_glass");
  EXPECT_GE(glass.features.transmissiveMaterials, 1);
  for (const auto& m : glass.materials)
    if (m.isTransmissive()) {
      EXPECT_FLOAT_EQ(m.transmissionFactor, 1.f);
      EXPECT_FLOAT_EQ(m.ior, 1.5f);
      EXPECT_FLOAT_EQ(m.roughnessFactor, 0.f);
    }
}

TEST(BuiltinScenes, GlossyBoxIsTheGlosbox) {
  // Stürzlinger & Bastos's Glosbox: the larger block glossy, not a mirror (the specular pass's
  // threshold is roughness 0.2), so photon_gi owns its indirect light.
  const Scene s = loadBuiltinScene("cornell_glossy");
  EXPECT_EQ(s.features.specularMaterials, 0);
  int glossy = 0;
  for (const auto& m : s.materials)
    if (m.metallicFactor == 1.f && m.roughnessFactor > Material::kSpecularRoughness && m.roughnessFactor < 0.5f) ++glossy;
  EXPECT_EQ(glossy, 1);
}

TEST(BuiltinScenes, AoCreasesCameraLooksAtTheCorner) {
  const Scene s = loadBuiltinScene("ao_creases");
  const glm::vec3 eye(s.camera.world[3]);
  const glm::vec3 forward = -glm::vec3(s.camera.world[2]);
  EXPECT_GT(glm::dot(forward, glm::normalize(glm::vec3(0, 0.3f, 0) - eye)), 0.9999f);
  EXPECT_NEAR(s.camera.world[0].y, 0.f, 1e-5f);  // no roll
  EXPECT_EQ(s.features.specularMaterials, 0);
}

}  // namespace
}  // namespace radiant
