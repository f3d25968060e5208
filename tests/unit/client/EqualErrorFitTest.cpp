// radiant bench --equal-error's fit (client/commands/EqualError.cpp, fitEqualError): on exact data
// MSE(s) = a / s + b and t(s) = t0 + c s it recovers a, b, t0, c, and the reference's spp and time at the
// frame's own error; the truth-limited and firefly (b < 0) cases; bad ladders are usage errors.
#include <gtest/gtest.h>

#include "client/Commands.h"

namespace radiant::client {
namespace {

std::vector<LadderPoint> exactLadder(double a, double b, double t0, double c, std::vector<double> spps) {
  std::vector<LadderPoint> out;
  for (double s : spps) out.push_back({s, a / s + b, t0 + c * s});
  return out;
}

TEST(EqualErrorFit, ExactDataGivesBackItsCurveAndTheEqualErrorPoint) {
  const double a = 2.5, b = 0.004, t0 = 12, c = 0.5;
  const EqualErrorFit f = fitEqualError(exactLadder(a, b, t0, c, {64, 256, 1024}), 0.009);
  EXPECT_NEAR(f.a, a, 1e-9);
  EXPECT_NEAR(f.b, b, 1e-12);
  EXPECT_NEAR(f.t0, t0, 1e-9);
  EXPECT_NEAR(f.msPerSpp, c, 1e-12);
  EXPECT_FALSE(f.truthLimited);
  EXPECT_NEAR(f.frameOwnMse, 0.005, 1e-12);
  EXPECT_NEAR(f.spp, a / 0.005, 1e-6);  // 500 spp
  EXPECT_NEAR(f.ms, t0 + c * 500, 1e-6);
}

TEST(EqualErrorFit, AFrameWithinTheTruthsNoiseIsTruthLimited) {
  const EqualErrorFit f = fitEqualError(exactLadder(1, 0.01, 0, 1, {16, 64}), 0.008);
  EXPECT_TRUE(f.truthLimited);
  EXPECT_NEAR(f.frameOwnMse, -0.002, 1e-12);
  EXPECT_EQ(f.spp, 0.0);
}

TEST(EqualErrorFit, ANegativeInterceptTakesTheLargestSppAsTheAsymptote) {
  // Fireflies at 16 spp: the line through 1/s would cross below 0.
  const std::vector<LadderPoint> ladder{{16, 0.5, 1}, {64, 0.01, 4}, {256, 0.002, 16}};
  const EqualErrorFit f = fitEqualError(ladder, 0.004);
  EXPECT_EQ(f.b, 0.0);
  EXPECT_NEAR(f.a, 256 * 0.002, 1e-12);
  EXPECT_NEAR(f.spp, 0.512 / 0.004, 1e-9);
}

TEST(EqualErrorFit, LaddersThatCannotBeFittedAreUsageErrors) {
  EXPECT_THROW(fitEqualError({{64, 0.1, 1}}, 0.1), UsageError);
  EXPECT_THROW(fitEqualError({{64, 0.1, 1}, {64, 0.2, 1}}, 0.1), UsageError);
  EXPECT_THROW(fitEqualError({{0, 0.1, 1}, {64, 0.2, 1}}, 0.1), UsageError);
}

}  // namespace
}  // namespace radiant::client
