// The maps' levels of detail (renderer/scene/MeshLod.h): each level keeps within its bound of the full
// surface, has fewer triangles than the one before, and small meshes get none.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "renderer/scene/MeshLod.h"

namespace radiant {
namespace {

// A UV sphere of radius 1 (rings x segments quads, shared vertices but for the seam column).
MeshInstance uvSphere(int rings, int segments) {
  MeshInstance m;
  for (int r = 0; r <= rings; ++r)
    for (int s = 0; s <= segments; ++s) {
      const float theta = float(M_PI) * r / rings, phi = 2.f * float(M_PI) * s / segments;
      const glm::vec3 p(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
      m.positions.push_back(p);
      m.normals.push_back(p);
      m.bounds.extend(p);
    }
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      const std::uint32_t a = r * (segments + 1) + s, b = a + segments + 1;
      m.indices.insert(m.indices.end(), {a, b, a + 1, a + 1, b, b + 1});
    }
  return m;
}

glm::vec3 closestOnTriangle(const glm::vec3& p, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
  // Ericson, Real-Time Collision Detection, 5.1.5.
  const glm::vec3 ab = b - a, ac = c - a, ap = p - a;
  const float d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const glm::vec3 bp = p - b;
  const float d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const float vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const glm::vec3 cp = p - c;
  const float d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const float vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const float va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const float denom = 1.f / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

float distanceToMesh(const glm::vec3& p, const MeshInstance& m, const std::vector<std::uint32_t>& indices) {
  float best = INFINITY;
  for (std::size_t i = 0; i < indices.size(); i += 3) {
    const glm::vec3 q = closestOnTriangle(p, m.positions[indices[i]], m.positions[indices[i + 1]], m.positions[indices[i + 2]]);
    best = std::min(best, glm::length(p - q));
  }
  return best;
}

TEST(MeshLod, EveryLevelStaysWithinItsBoundOfTheFullSurface) {
  const MeshInstance sphere = uvSphere(64, 128);  // 16,384 triangles
  const std::vector<MeshLodLevel> levels = buildMeshLods(sphere, 1e-3f, 4, 4.f);
  ASSERT_GE(levels.size(), 3u);
  std::size_t before = sphere.indices.size();
  float bound = 1e-3f;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  for (const MeshLodLevel& level : levels) {
    EXPECT_LE(level.indices.size() * 4, before * 3);  // at most 3/4 of the triangles before it
    EXPECT_FLOAT_EQ(level.error, bound);
    float worst = 0.f;
    // Points spread over the level's triangles, each compared with the full mesh.
    for (int k = 0; k < 400; ++k) {
      const std::size_t t = std::size_t(u(rng) * float(level.indices.size() / 3)) % (level.indices.size() / 3);
      float b1 = u(rng), b2 = u(rng);
      if (b1 + b2 > 1.f) b1 = 1.f - b1, b2 = 1.f - b2;
      const glm::vec3& a = sphere.positions[level.indices[3 * t]];
      const glm::vec3& b = sphere.positions[level.indices[3 * t + 1]];
      const glm::vec3& c = sphere.positions[level.indices[3 * t + 2]];
      worst = std::max(worst, distanceToMesh(a + b1 * (b - a) + b2 * (c - a), sphere, sphere.indices));
    }
    EXPECT_LE(worst, level.error) << level.indices.size() / 3 << " triangles";
    // And the bound is used: a sphere this fine reaches at least a tenth of it.
    EXPECT_GE(worst, 0.1f * level.error) << level.indices.size() / 3 << " triangles";
    before = level.indices.size();
    bound *= 4.f;
  }
}

TEST(MeshLod, SmallMeshesAndFlatLevelsKeepTheirTriangles) {
  EXPECT_TRUE(buildMeshLods(uvSphere(16, 32), 1e-2f).empty());  // 1,024 triangles: under the minimum
  // A bound far below the tessellation's own detail gains nothing at the first level: no level at all
  // unless a later one halves it; every level kept still holds 3/4 or less of its predecessor.
  const MeshInstance sphere = uvSphere(32, 64);
  for (const MeshLodLevel& l : buildMeshLods(sphere, 1e-7f, 2, 4.f)) EXPECT_LE(l.indices.size() * 4, sphere.indices.size() * 3);
  EXPECT_TRUE(buildMeshLods(sphere, 0.f).empty());
  EXPECT_TRUE(buildMeshLods(sphere, NAN).empty());
}

TEST(MeshLod, TheBaseErrorIsAQuarterOfTheFinestShadowTexel) {
  Bounds b;
  b.extend(glm::vec3(-2.f));
  b.extend(glm::vec3(2.f));
  EXPECT_FLOAT_EQ(lodBaseError(b), 0.25f * 2.f * b.radius() / 4096.f);
}

}  // namespace
}  // namespace radiant
