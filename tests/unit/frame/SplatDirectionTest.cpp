// photon_gi's splat records (renderer/techniques/photon_gi/Splatting.h, GpuSplat): the direction each
// splat carries in 30 bits and its two flags, against the stated precision.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "renderer/techniques/photon_gi/Splatting.h"
#include "tests/support/Directions.h"

namespace radiant::photon_gi {
namespace {

// Every direction of a dense spherical Fibonacci set, the axes and the octants' diagonals come back
// within 2e-4 radians (what 15 bits per octahedral coordinate allow, after the photon record's 16),
// and the flags beside them survive and do not disturb the direction.
TEST(SplatDirection, IsWithinItsStatedAngleAndKeepsItsFlags) {
  const std::vector<glm::vec3> dirs = testing::testDirections(100000);
  double worst = 0.0;
  for (const glm::vec3& v : dirs)
    for (bool diffuseOnly : {false, true}) {
      GpuSplat s = photonSplat(glm::vec3(1.f, 2.f, 3.f), 0.5f, glm::vec3(0.f, 1.f, 0.f), v, glm::vec3(1.f), diffuseOnly);
      s.wiFlags |= kSplatCopy;
      EXPECT_EQ((s.wiFlags & kSplatDiffuseOnly) != 0, diffuseOnly);
      const glm::vec3 d = splatDirection(s);
      ASSERT_NEAR(glm::length(d), 1.f, 1e-6f);
      worst = std::max(worst, std::atan2(double(glm::length(glm::cross(v, d))), double(glm::dot(v, d))));
    }
  std::printf("largest splat direction error: %.3g rad over %zu directions\n", worst, dirs.size());
  EXPECT_LT(worst, 2e-4);
}

}  // namespace
}  // namespace radiant::photon_gi
