// RADIANT_particle_system: particle systems in a glTF node (api/schema/media.json, particles as
// accessors), moved to world space by the node's transform, counted in SceneFeatures, and bad
// extension values refused with a pointer into the document.
#include <gtest/gtest.h>

#include "renderer/scene/GltfLoader.h"
#include "tests/unit/scene/GltfTestBuilder.h"

namespace radiant {
namespace {

using test::GltfBuilder;
using nlohmann::json;

GltfBuilder particleFile(const json& extension) {
  GltfBuilder b;
  b.doc["extensionsUsed"] = {"RADIANT_particle_system"};
  const int n = b.node({{"name", "explosion"},
                        {"translation", {1, 2, 3}},
                        {"scale", {2, 2, 2}},
                        {"extensions", {{"RADIANT_particle_system", extension}}}});
  b.scene({n});
  return b;
}

TEST(GltfMedia, ParticlesFromAccessorsInWorldSpace) {
  GltfBuilder b;
  b.doc["extensionsUsed"] = {"RADIANT_particle_system"};
  const std::vector<glm::vec3> positions{{0, 0, 0}, {1, 0, 0}};
  const std::vector<float> radii{0.5f, 0.25f}, temps{3000.f, 2000.f};
  const int pos = b.vec3(positions);
  const int rad = b.accessor(b.view(radii.data(), 8), 5126, 2, "SCALAR");
  const int tk = b.accessor(b.view(temps.data(), 8), 5126, 2, "SCALAR");
  const int n = b.node({{"name", "fire"}, {"translation", {1, 2, 3}}, {"scale", {2, 2, 2}},
                        {"extensions", {{"RADIANT_particle_system",
                                         {{"kind", "fire"}, {"tau", 3},
                                          {"particles", {{"positions", pos}, {"radii", rad}, {"temperature", tk}}}}}}}});
  b.scene({n});
  const Scene s = loadSceneFromMemory(b.gltf());
  ASSERT_EQ(s.media.size(), 1u);
  const auto& sys = s.media[0];
  EXPECT_EQ(sys.name, "fire");
  ASSERT_EQ(sys.particles.size(), 2u);
  EXPECT_EQ(sys.particles[1].position, glm::vec3(3, 2, 3));  // 2 * (1, 0, 0) + (1, 2, 3)
  EXPECT_FLOAT_EQ(sys.particles[0].radius, 1.f);              // 0.5 * 2
  EXPECT_FLOAT_EQ(sys.particles[1].temperature, 2000.f);
  EXPECT_FLOAT_EQ(sys.particles[0].tau, 3.f);
  EXPECT_EQ(s.features.particleSystems, 1);
  EXPECT_EQ(s.features.particles, 2u);
  EXPECT_EQ(s.features.emissiveMedia, 1);
  EXPECT_TRUE(s.warnings.empty());
  // The particles are inside the scene bounds (the automatic camera frames them).
  EXPECT_LE(s.features.bounds.max.x, 3.5f + 1e-6f);
  EXPECT_GE(s.features.bounds.max.x, 3.5f - 1e-6f);
}

TEST(GltfMedia, GeneratorInTheNodeFrame) {
  const Scene s = loadSceneFromMemory(
      particleFile({{"kind", "smoke"}, {"generator", {{"count", 100}, {"extent", {1, 1, 1}}, {"radius", 0.1}}}}).gltf());
  ASSERT_EQ(s.media.size(), 1u);
  ASSERT_EQ(s.media[0].particles.size(), 100u);
  for (const auto& p : s.media[0].particles) {
    EXPECT_LE(glm::length(p.position - glm::vec3(1, 2, 3)), 2.f + 1e-5f);  // the unit ball scaled by 2
    EXPECT_FLOAT_EQ(p.radius, 0.2f);
    EXPECT_FLOAT_EQ(p.albedo.x, 0.2f);  // smoke
  }
  EXPECT_EQ(s.features.scatteringMedia, 1);
}

TEST(GltfMedia, BadValuesNameTheirPointer) {
  auto pointerOf = [](const std::string& bytes) {
    try {
      loadSceneFromMemory(bytes);
    } catch (const SceneError& e) {
      return e.pointer;
    }
    return std::string("no error");
  };
  EXPECT_EQ(pointerOf(particleFile({{"kind", "smoke"}, {"tau", -1}, {"generator", {{"count", 3}}}}).gltf()),
            "/nodes/0/extensions/RADIANT_particle_system/tau");
  EXPECT_EQ(pointerOf(particleFile({{"kind", "smoke"}}).gltf()), "/nodes/0/extensions/RADIANT_particle_system");
  EXPECT_EQ(pointerOf(particleFile({{"kind", "smoke"}, {"particles", {{"positions", 7}, {"radii", 8}}}}).gltf()),
            "/accessors/7");
  // A radius of 0 in an accessor: the same rule as the request's particles.
  GltfBuilder b;
  const std::vector<glm::vec3> positions{{0, 0, 0}};
  const std::vector<float> radii{0.f};
  const int pos = b.vec3(positions);
  const int rad = b.accessor(b.view(radii.data(), 4), 5126, 1, "SCALAR");
  const int n = b.node({{"extensions", {{"RADIANT_particle_system",
                                         {{"kind", "dust"}, {"particles", {{"positions", pos}, {"radii", rad}}}}}}}});
  b.scene({n});
  EXPECT_EQ(pointerOf(b.gltf()), "/nodes/0/extensions/RADIANT_particle_system/particles/0/r");
}

}  // namespace
}  // namespace radiant
