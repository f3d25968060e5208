// The environment's split into lights and a residual (renderer/shading/EnvironmentLights.h): exact in
// energy per texel, a sun found where it is with the irradiance it gives, nothing taken from a map
// without a compact bright region.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "renderer/raytracing/Lights.h"
#include "renderer/raytracing/Sampler.h"
#include "renderer/scene/Environment.h"
#include "renderer/shading/EnvironmentLights.h"

namespace radiant {
namespace {

constexpr double kPi = 3.14159265358979323846;

double texelSolidAngle(const Image& m, int y) {
  return 2.0 * kPi * kPi * std::sin(kPi * (y + 0.5) / m.height) / (double(m.width) * m.height);
}

glm::vec3 texelDir(const Image& m, int x, int y) {
  const double u = (x + 0.5) / m.width, v = (y + 0.5) / m.height;
  const double phi = (u - 0.5) * 2.0 * kPi, theta = v * kPi;
  return glm::vec3(std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi));
}

// A sky of radiance (0.5, 0.6, 0.8) with a sun of radiance (5e4, 4e4, 3e4) in every texel within
// `radius` of `sun`.
Image sunnySky(glm::vec3 sun, float radius) {
  Image m = Image::make("environment", 256, 128, 3);
  for (int y = 0; y < m.height; ++y)
    for (int x = 0; x < m.width; ++x) {
      const bool inSun = std::acos(std::clamp(glm::dot(texelDir(m, x, y), sun), -1.f, 1.f)) < radius;
      const glm::vec3 L = inSun ? glm::vec3(5e4f, 4e4f, 3e4f) : glm::vec3(0.5f, 0.6f, 0.8f);
      float* p = m.at(x, y);
      p[0] = L.x, p[1] = L.y, p[2] = L.z;
    }
  return m;
}

// A sun as HDR skies hold one: a small core (radius 0.03 rad, radiance 5e4) in a halo (to 0.09 rad)
// just above the threshold. The light's radius is where its light is: near the core's (the cap of the
// same S-weighted mean cosine), not the whole region's 0.09 (the cap of its solid angle), which
// spread smooth metals' glints over the halo. Its irradiance is still every texel's part above T.
TEST(EnvironmentLights, ASunWithAHaloGetsItsCoresRadius) {
  const glm::vec3 sun = glm::normalize(glm::vec3(-0.2f, 0.8f, 0.5f));
  Image map = sunnySky(sun, 0.03f);
  double mean = 0.0, sphere = 0.0;
  for (int y = 0; y < map.height; ++y)
    for (int x = 0; x < map.width; ++x) {
      const float* p = map.at(x, y);
      mean += (0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]) * texelSolidAngle(map, y);
      sphere += texelSolidAngle(map, y);
    }
  mean /= sphere;
  // The halo: 1.5 x the default threshold (10 x the mean luminance), grey.
  const float halo = float(15.0 * mean);
  double regionSolidAngle = 0.0;
  for (int y = 0; y < map.height; ++y)
    for (int x = 0; x < map.width; ++x) {
      const float a = std::acos(std::clamp(glm::dot(texelDir(map, x, y), sun), -1.f, 1.f));
      float* p = map.at(x, y);
      if (a >= 0.03f && a < 0.09f) p[0] = p[1] = p[2] = halo;
      if (a < 0.09f) regionSolidAngle += texelSolidAngle(map, y);
    }
  const EnvironmentLights split = extractEnvironmentLights(map);
  ASSERT_EQ(split.lights.size(), 1u);
  const double wholeRegion = std::acos(1.0 - regionSolidAngle / (2.0 * kPi));
  EXPECT_NEAR(wholeRegion, 0.09, 0.015);
  EXPECT_LT(split.lights[0].angularRadius, 0.04f) << "whole region " << wholeRegion;
  EXPECT_GT(split.lights[0].angularRadius, 0.02f);
}

TEST(EnvironmentLights, ASunBecomesOneLightWithItsIrradianceAndTheSplitIsExact) {
  const glm::vec3 sun = glm::normalize(glm::vec3(0.4f, 0.7f, -0.3f));
  const Image map = sunnySky(sun, 0.05f);
  const EnvironmentLights split = extractEnvironmentLights(map);
  ASSERT_EQ(split.lights.size(), 1u);
  const Light& l = split.lights[0];
  EXPECT_EQ(l.type, LightType::Directional);
  // Light travels from the sun: its direction is -sun, within a texel's angle (1.4 degrees).
  EXPECT_GT(glm::dot(-l.direction, sun), std::cos(0.025f));
  // The light and the residual add up to the map, texel by texel and channel by channel: the sun's
  // texels keep exactly the threshold's luminance, the sky's all of theirs.
  glm::dvec3 sunIrradiance(0.0), residualInSun(0.0);
  double sunSolidAngle = 0.0;
  for (int y = 0; y < map.height; ++y)
    for (int x = 0; x < map.width; ++x) {
      const float* p = map.at(x, y);
      const float* r = split.residual.at(x, y);
      const double dw = texelSolidAngle(map, y);
      if (p[0] > 1.f) {
        sunIrradiance += glm::dvec3(p[0], p[1], p[2]) * dw;
        residualInSun += glm::dvec3(r[0], r[1], r[2]) * dw;
        sunSolidAngle += dw;
        EXPECT_NEAR(0.2126 * r[0] + 0.7152 * r[1] + 0.0722 * r[2], split.threshold, 1e-3 * split.threshold);
        EXPECT_NEAR(r[0] / r[2], p[0] / p[2], 1e-4);  // the colour is kept
      } else {
        for (int c = 0; c < 3; ++c) EXPECT_EQ(r[c], p[c]);
      }
    }
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(l.color[c] * l.intensity, sunIrradiance[c] - residualInSun[c], 1e-4 * sunIrradiance[c]);
  // A uniform disc: the cap of the same mean cosine is the cap of its solid angle, its radius (0.05 rad
  // up to texel quantisation, which moves the two estimates apart by 0.5%).
  EXPECT_NEAR(l.angularRadius, std::acos(1.0 - sunSolidAngle / (2.0 * kPi)), 0.01 * l.angularRadius);
  EXPECT_NEAR(l.angularRadius, 0.05, 0.01);
  // The sun holds nearly all the power: (5e4 x 0.0079 sr) against 0.59 x 4 pi.
  EXPECT_GT(split.fraction, 0.95f);
  EXPECT_NEAR(split.residualShare(map, sun), split.threshold / (0.2126 * 5e4 + 0.7152 * 4e4 + 0.0722 * 3e4), 1e-6);
  EXPECT_EQ(split.residualShare(map, -sun), 1.f);
}

// photon_gi draws sky photons by R + w S when the map is split (renderer/techniques/photon_gi/PhotonGi.cpp,
// photonEnvironmentDistribution): the weighted distribution keeps the map's integral, its samples land
// on the sun as often as the weights say, and the estimate L / pdf stays the map's integral (unbiased).
TEST(EnvironmentLights, PhotonsDrawnByTheResidualPlusAWeightedSunEstimateTheWholeMap) {
  const glm::vec3 sun = glm::normalize(glm::vec3(0.4f, 0.7f, -0.3f));
  const Image map = sunnySky(sun, 0.05f);
  const EnvironmentLights split = extractEnvironmentLights(map);
  ASSERT_TRUE(split.split());
  constexpr float kWeight = 0.5f;
  Image weight = Image::make("weight", map.width, map.height, 1);
  double sunShareOfWeight = 0.0, totalWeight = 0.0, sunShareOfMap = 0.0, totalMap = 0.0;
  for (int y = 0; y < map.height; ++y)
    for (int x = 0; x < map.width; ++x) {
      const float* l = map.at(x, y);
      const float* r = split.residual.at(x, y);
      const float yl = 0.2126f * l[0] + 0.7152f * l[1] + 0.0722f * l[2];
      const float yr = 0.2126f * r[0] + 0.7152f * r[1] + 0.0722f * r[2];
      weight.at(x, y)[0] = yr + kWeight * (yl - yr);
      const double wdw = weight.at(x, y)[0] * texelSolidAngle(map, y);
      totalWeight += wdw;
      totalMap += yl * texelSolidAngle(map, y);
      if (l[0] > 1.f) sunShareOfWeight += wdw, sunShareOfMap += yl * texelSolidAngle(map, y);
    }
  sunShareOfWeight /= totalWeight;
  sunShareOfMap /= totalMap;
  const auto plain = rt::EnvironmentDistribution::build(map);
  const auto weighted = rt::EnvironmentDistribution::build(map, &weight);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(weighted->integral[c], plain->integral[c]);
  const Image small = Image::make("weight", 8, 4, 1);
  EXPECT_THROW(rt::EnvironmentDistribution::build(map, &small), std::invalid_argument) << "a weight of another size";
  const rt::EnvironmentLight light(&map, glm::vec3(0.f), weighted);
  constexpr int kSamples = 200000;
  glm::dvec3 estimate(0.0);
  int onSun = 0, pdfMismatch = 0;
  for (int i = 0; i < kSamples; ++i) {
    rt::Sampler sampler(static_cast<std::uint64_t>(i), 0, 7);
    float pdf = 0.f;
    const glm::vec3 dir = light.sample(sampler.next2(), pdf);
    ASSERT_GT(pdf, 0.f);
    if (std::abs(light.pdf(dir) - pdf) > 1e-3f * pdf) ++pdfMismatch;
    estimate += glm::dvec3(light.radiance(dir)) / double(pdf) / double(kSamples);
    if (light.radiance(dir).x > 1.f) ++onSun;
  }
  // pdf(dir) is the sample's density but for directions that float rounding maps to a neighbouring
  // texel (acos near the poles loses about 3e-4 rad, a polar row being 0.025 rad high).
  EXPECT_LT(pdfMismatch, kSamples / 1000) << pdfMismatch;
  // Drawn by L, 98% of the samples land on the sun; drawn by R + S / 2 nearly twice as many land on the
  // sky: (R + S) / (R + S / 2) with S >> R.
  EXPECT_GT((1.0 - sunShareOfWeight) / (1.0 - sunShareOfMap), 1.9);
  EXPECT_NEAR(double(onSun) / kSamples, sunShareOfWeight, 0.01);
  // L / pdf is at most 2 (sun) or 1 (sky) times the weight's mean: 200k samples, well under 1%.
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(estimate[c], plain->integral[c], 0.01 * plain->integral[c]);
}

// Issue 30: both builds are linear in the map's texels (a 1 x 22-million map is within the decode
// budget) and poll the request's cancel flag; a raised flag stops them, an unraised one changes nothing.
TEST(EnvironmentLights, TheSplitAndTheSamplingDistributionStopWhenCancelled) {
  const Image map = sunnySky(glm::normalize(glm::vec3(0.4f, 0.7f, -0.3f)), 0.05f);
  std::atomic<bool> flag{true};
  const rt::Cancel raised(&flag);
  EXPECT_THROW(extractEnvironmentLights(map, {}, raised), rt::Cancelled);
  EXPECT_THROW(rt::EnvironmentDistribution::build(map, nullptr, raised), rt::Cancelled);
  flag = false;
  const EnvironmentLights split = extractEnvironmentLights(map, {}, raised);
  ASSERT_EQ(split.lights.size(), 1u);
  EXPECT_EQ(split.residual.pixels, extractEnvironmentLights(map).residual.pixels);
  EXPECT_EQ(rt::EnvironmentDistribution::build(map, nullptr, raised)->marginal,
            rt::EnvironmentDistribution::build(map)->marginal);
}

TEST(EnvironmentLights, NothingIsTakenFromAMapWithoutACompactBrightRegion) {
  // A uniform sky, and a broad bright half: no texel or only a wide region above 10x the mean.
  Image uniform = Image::make("environment", 64, 32, 3);
  for (float& v : uniform.pixels) v = 1.f;
  EXPECT_FALSE(extractEnvironmentLights(uniform).split());
  Image half = uniform;
  for (int y = 0; y < half.height / 2; ++y)
    for (int x = 0; x < half.width; ++x) half.at(x, y)[0] = half.at(x, y)[1] = half.at(x, y)[2] = 1000.f;
  EnvironmentLightOptions o;
  o.threshold = 1.5f;  // the upper half is 2x the mean: above it, but 2 pi sr wide
  EXPECT_FALSE(extractEnvironmentLights(half, o).split());
  // maxLights 0 turns the split off; two suns with maxLights 1 keep the weaker one in the residual.
  const Image sunny = sunnySky(glm::vec3(0, 1, 0), 0.05f);
  o = {};
  o.maxLights = 0;
  EXPECT_FALSE(extractEnvironmentLights(sunny, o).split());
  Image two = sunnySky(glm::normalize(glm::vec3(1, 1, 0)), 0.06f);
  const Image other = sunnySky(glm::normalize(glm::vec3(-1, 1, 0)), 0.04f);
  for (std::size_t i = 0; i < two.pixels.size(); ++i) two.pixels[i] = std::max(two.pixels[i], other.pixels[i]);
  o = {};
  o.maxLights = 1;
  const EnvironmentLights one = extractEnvironmentLights(two, o);
  ASSERT_EQ(one.lights.size(), 1u);
  EXPECT_GT(glm::dot(-one.lights[0].direction, glm::normalize(glm::vec3(1, 1, 0))), 0.999f);  // the larger
  EXPECT_EQ(one.residualShare(two, glm::normalize(glm::vec3(-1, 1, 0))), 1.f);
  EXPECT_EQ(extractEnvironmentLights(two).lights.size(), 2u);
}

TEST(EnvironmentLights, NonFiniteAndEmptyMapsAreLeftAlone) {
  Image m = Image::make("environment", 32, 16, 3);
  EXPECT_FALSE(extractEnvironmentLights(m).split());  // black: no power
  for (float& v : m.pixels) v = 1.f;
  m.at(3, 3)[0] = std::numeric_limits<float>::infinity();
  m.at(4, 3)[1] = std::numeric_limits<float>::quiet_NaN();
  const EnvironmentLights s = extractEnvironmentLights(m);
  for (const Light& l : s.lights) EXPECT_TRUE(std::isfinite(l.color.x + l.color.y + l.color.z));
  EXPECT_FALSE(extractEnvironmentLights(Image{}).split());
  EnvironmentLightOptions withSky;
  withSky.skyLights = 16;
  const EnvironmentLights sky = extractEnvironmentLights(m, withSky);
  EXPECT_FALSE(sky.skyLights.empty());
  for (const Light& l : sky.skyLights) {
    EXPECT_TRUE(std::isfinite(l.color.x + l.color.y + l.color.z));
    EXPECT_TRUE(std::isfinite(l.direction.x + l.direction.y + l.direction.z));
  }
  EXPECT_TRUE(extractEnvironmentLights(Image::make("environment", 32, 16, 3), withSky).skyLights.empty());  // black
}

// The sky lights (median cut of the residual, Debevec 2005): each carries its region's vector
// irradiance (sum R w dw) along its direction, so together they give any surface that sees whole
// regions the residual's cosine-weighted irradiance, and the first cut is the horizon, so a surface
// facing up or down sees whole regions (one across the horizon would light an upward plane from its
// centroid near the horizon, with a fraction of its upper half's light).
TEST(EnvironmentLights, SkyLightsCarryTheResidualAndLightAPlaneAsTheMapDoes) {
  const glm::vec3 sun = glm::normalize(glm::vec3(0.4f, 0.7f, -0.3f));
  Image map = sunnySky(sun, 0.05f);
  // A sky brighter at the horizon than at the zenith and a darker ground, as daylight maps are.
  for (int y = 0; y < map.height; ++y)
    for (int x = 0; x < map.width; ++x) {
      const glm::vec3 d = texelDir(map, x, y);
      float* p = map.at(x, y);
      if (p[0] > 100.f) continue;  // the sun
      const float k = d.y >= 0.f ? 1.5f - d.y : 0.3f;
      p[0] *= k, p[1] *= k, p[2] *= k;
    }
  EnvironmentLightOptions o;
  o.skyLights = 16;
  const EnvironmentLights split = extractEnvironmentLights(map, o);
  ASSERT_TRUE(split.split());
  ASSERT_EQ(split.skyLights.size(), 16u);
  glm::dvec3 residualVector(0.0), lightVector(0.0);  // luminance-weighted vector irradiance
  double upMap = 0.0, downMap = 0.0, upLights = 0.0, downLights = 0.0;
  for (int y = 0; y < map.height; ++y)
    for (int x = 0; x < map.width; ++x) {
      const float* r = split.residual.at(x, y);
      const glm::dvec3 R(r[0], r[1], r[2]);
      const double dw = texelSolidAngle(map, y), cy = texelDir(map, x, y).y;
      residualVector += glm::dvec3(texelDir(map, x, y)) * (0.2126 * R.x + 0.7152 * R.y + 0.0722 * R.z) * dw;
      upMap += R.y * dw * std::max(0.0, cy);
      downMap += R.y * dw * std::max(0.0, -cy);
    }
  for (const Light& l : split.skyLights) {
    const glm::dvec3 from = -glm::dvec3(l.direction);  // the light comes from -direction
    const double Y = 0.2126 * l.color.x + 0.7152 * l.color.y + 0.0722 * l.color.z;
    lightVector += from * Y;
    upLights += l.color.y * std::max(0.0, from.y);
    downLights += l.color.y * std::max(0.0, -from.y);
    EXPECT_GT(l.angularRadius, 0.f);
  }
  EXPECT_LT(glm::length(lightVector - residualVector), 2e-3 * glm::length(residualVector));
  EXPECT_NEAR(upLights / upMap, 1.0, 0.01) << upLights << " against " << upMap;
  EXPECT_NEAR(downLights / downMap, 1.0, 0.01) << downLights << " against " << downMap;
  // Without compact lights the sky lights cut the whole map, sun included: the upward irradiance holds.
  EnvironmentLightOptions none = o;
  none.maxLights = 0;
  const EnvironmentLights whole = extractEnvironmentLights(map, none);
  EXPECT_FALSE(whole.split());
  double upWhole = 0.0, upWholeMap = 0.0;
  for (int y = 0; y < map.height; ++y)
    for (int x = 0; x < map.width; ++x)
      upWholeMap += map.at(x, y)[1] * texelSolidAngle(map, y) * std::max(0.f, texelDir(map, x, y).y);
  for (const Light& l : whole.skyLights) upWhole += l.color.y * std::max(0.f, -l.direction.y);
  EXPECT_NEAR(upWhole / upWholeMap, 1.0, 0.01);
}

// A map over 2^20 texels is cut on a copy averaged by solid angle (its summed-area table would be 8
// bytes a texel): the lights still give an upward surface the map's cosine-weighted irradiance, and a
// 1 x 2^22 strip (within the decode limits' pixel count) is cut without a table of its size.
TEST(EnvironmentLights, SkyLightsOfALargeMapAreCutOnACoarseCopy) {
  Image map = Image::make("environment", 2048, 1024, 3);
  double upMap = 0.0;
  for (int y = 0; y < map.height; ++y)
    for (int x = 0; x < map.width; ++x) {
      const glm::vec3 d = texelDir(map, x, y);
      const float k = d.y >= 0.f ? 1.5f - d.y + 0.5f * d.x : 0.3f;
      float* p = map.at(x, y);
      p[0] = 0.5f * k, p[1] = 0.6f * k, p[2] = 0.8f * k;
      upMap += p[1] * texelSolidAngle(map, y) * std::max(0.f, d.y);
    }
  EnvironmentLightOptions o;
  o.skyLights = 16;
  const EnvironmentLights split = extractEnvironmentLights(map, o);
  ASSERT_EQ(split.skyLights.size(), 16u);
  double upLights = 0.0;
  for (const Light& l : split.skyLights) upLights += l.color.y * std::max(0.f, -l.direction.y);
  EXPECT_NEAR(upLights / upMap, 1.0, 0.01);
  Image strip = Image::make("environment", 1, 1 << 22, 3);
  for (float& v : strip.pixels) v = 1.f;
  const EnvironmentLights stripSplit = extractEnvironmentLights(strip, o);
  ASSERT_FALSE(stripSplit.skyLights.empty());
  double total = 0.0;
  for (const Light& l : stripSplit.skyLights) total += l.color.x * std::max(0.f, -l.direction.y);
  EXPECT_NEAR(total / kPi, 1.0, 0.01) << "a uniform sky of 1 gives an upward surface pi";
}

}  // namespace
}  // namespace radiant
