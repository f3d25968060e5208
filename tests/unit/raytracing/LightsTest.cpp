// Emission of every kind of emitter (SceneLights::sampleLe / pdfLe / power, renderer/raytracing/Lights.h)
// against what measure theory and the closed forms fix:
// - sampleLe against pdfLe: the densities a sample reports are the ones pdfLe gives its ray; E[1/pdf]
//   over sampleLe's samples is the measure of the sampled domain (4 pi sr, a cone's solid angle, the
//   triangle's area, the disk's area); and the Monte Carlo integral of pdfLe over the whole domain with
//   independent uniform samples is 1.
// - power: each emitter's power is its closed form (point 4 pi I, spot with its cone falloff,
//   directional E pi r^2 over the bounding disk, one-sided Lambertian triangle pi L A, environment
//   pi r^2 \int L dw), and the mean flux L cos / (pdfPos pdfDir) of its samples converges to it.
// Tolerances: 5 standard errors of the estimate (the sample's own standard deviation / sqrt(N)), and
// a float floor where an estimator has no variance (1/pdf constant).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>

#include "renderer/raytracing/Lights.h"
#include "renderer/raytracing/Sampler.h"
#include "tests/unit/reference/TestScenes.h"

namespace radiant::rt {
namespace {

using testing::addMaterial;
using testing::lambert;

// Mean and standard error of f(i), i < n.
struct Estimate {
  double mean = 0.0, stderr_ = 0.0;
};
Estimate estimate(int n, const std::function<double(int)>& f) {
  double sum = 0.0, sum2 = 0.0;
  for (int i = 0; i < n; ++i) {
    const double v = f(i);
    sum += v;
    sum2 += v * v;
  }
  const double mean = sum / n, var = std::max(0.0, sum2 / n - mean * mean);
  return {mean, std::sqrt(var / n)};
}
// |estimate - expected| within 5 standard errors, or a relative float floor when the estimator is exact.
void expectWithin(const Estimate& e, double expected, const std::string& what) {
  const double tolerance = std::max(5.0 * e.stderr_, 2e-4 * std::abs(expected));
  EXPECT_NEAR(e.mean, expected, tolerance) << what << " (standard error " << e.stderr_ << ")";
}

glm::vec2 u2Of(int i, int dim) {
  Sampler s(static_cast<std::uint64_t>(i), static_cast<std::uint64_t>(dim), 11);
  return s.next2();
}

// One emitter in a scene whose bounds are a 2 x 0 x 2 square (bounding radius sqrt(2)).
struct OneEmitter {
  Scene scene;
  std::unique_ptr<RayScene> rays;
  std::unique_ptr<Image> map;
  std::unique_ptr<SceneLights> lights;
};
std::unique_ptr<OneEmitter> withLight(const Light& l) {
  auto o = std::make_unique<OneEmitter>();
  const int mat = addMaterial(o->scene, lambert(glm::vec3(0.5f)));
  o->scene.meshes.push_back(testing::square(glm::vec3(0.f), glm::vec3(0, 1, 0), 1.f, mat));
  o->scene.lights.push_back(l);
  o->scene.features = computeFeatures(o->scene);
  o->rays = std::make_unique<RayScene>(o->scene);
  o->lights = std::make_unique<SceneLights>(*o->rays, nullptr, glm::vec3(0.f));
  return o;
}
std::unique_ptr<OneEmitter> withTriangle(glm::vec3 L, bool doubleSided) {
  auto o = std::make_unique<OneEmitter>();
  const int mat = addMaterial(o->scene, testing::emitter(L, doubleSided));
  o->scene.meshes.push_back(testing::square(glm::vec3(0.f), glm::vec3(0, -1, 0), 0.5f, mat));  // two triangles
  o->scene.features = computeFeatures(o->scene);
  o->rays = std::make_unique<RayScene>(o->scene);
  o->lights = std::make_unique<SceneLights>(*o->rays, nullptr, glm::vec3(0.f));
  return o;
}
// map: null for a uniform sky of radiance `sky`.
std::unique_ptr<OneEmitter> withEnvironment(std::unique_ptr<Image> map, glm::vec3 sky) {
  auto o = std::make_unique<OneEmitter>();
  const int mat = addMaterial(o->scene, lambert(glm::vec3(0.5f)));
  o->scene.meshes.push_back(testing::square(glm::vec3(0.f), glm::vec3(0, 1, 0), 1.f, mat));
  o->scene.features = computeFeatures(o->scene);
  o->rays = std::make_unique<RayScene>(o->scene);
  o->map = std::move(map);
  o->lights = std::make_unique<SceneLights>(*o->rays, o->map.get(), sky);
  return o;
}
int lastEmitter(const SceneLights& l) { return static_cast<int>(l.emitters().size()) - 1; }

// An equirect map: radiance 2 in the upper hemisphere, 0.5 in the lower, with a brighter texel column
// (so the importance sampling is not uniform): \int L dw = 2 pi 2 + 2 pi 0.5 + the column's excess.
std::unique_ptr<Image> twoToneMap(double& integral) {
  const int w = 32, h = 64;
  auto m = std::make_unique<Image>(Image::make("environment", w, h, 3));
  integral = 0.0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float L = (y < h / 2 ? 2.f : 0.5f) * (x == 5 ? 8.f : 1.f);
      for (int c = 0; c < 3; ++c) m->at(x, y)[c] = L;
      integral += L * 2.0 * M_PI * M_PI * std::sin(M_PI * (y + 0.5) / h) / (double(w) * h);  // texel solid angle
    }
  return m;
}

Light punctual(LightType type, float inner = 0.f, float outer = 0.f) {
  Light l;
  l.type = type;
  l.intensity = 3.f;
  l.color = glm::vec3(1.f, 0.5f, 0.25f);
  l.innerConeAngle = inner;
  l.outerConeAngle = outer;
  l.position = glm::vec3(0, 2, 0);
  l.direction = glm::vec3(0, -1, 0);
  return l;
}

constexpr int kN = 40000;

// What sampleLe and pdfLe must agree on for one emitter: `dirMeasure` / `posMeasure` are the measures of
// the sampled direction / position domains (0: that part is a delta).
// cosineWeighted: E[cos / pdfDir] instead of E[1 / pdfDir] (which has infinite variance for a
// cosine-weighted sampler), whose value is then \int cos dw = pi per hemisphere.
void checkSampleLeAgainstPdfLe(const SceneLights& lights, int e, double dirMeasure, double posMeasure,
                               const std::string& what, bool cosineWeighted = false) {
  std::vector<LeSample> samples(kN);
  std::vector<bool> ok(kN);
  for (int i = 0; i < kN; ++i) ok[i] = lights.sampleLe(e, u2Of(i, 0), u2Of(i, 1), samples[i]);
  // Every sample's densities are pdfLe's for its ray. (An environment-map direction that rounds onto a
  // texel edge may be looked up in the neighbouring texel: a few per 10^4 at most.)
  int mismatches = 0;
  for (int i = 0; i < kN; ++i) {
    if (!ok[i]) continue;
    float pdfPos = -1.f, pdfDir = -1.f;
    lights.pdfLe(e, samples[i].ray, pdfPos, pdfDir);
    const float wantDir = dirMeasure > 0 ? samples[i].pdfDir : 0.f;  // a delta: no other strategy hits it
    const float wantPos = posMeasure > 0 ? samples[i].pdfPos : 0.f;
    mismatches += std::abs(pdfDir - wantDir) > 1e-3f * wantDir || std::abs(pdfPos - wantPos) > 1e-3f * wantPos;
  }
  EXPECT_LE(mismatches, kN / 2500) << what;
  // E[1/pdf] over the samples is the measure of the domain they cover (samples that carry nothing,
  // e.g. a spot's zero-falloff rim, still count: their pdf is the sampler's).
  if (dirMeasure > 0)
    expectWithin(estimate(kN, [&](int i) { return (cosineWeighted ? samples[i].cosine : 1.0) / samples[i].pdfDir; }),
                 dirMeasure, what + ": E[1/pdfDir]");
  if (posMeasure > 0)
    expectWithin(estimate(kN, [&](int i) { return 1.0 / samples[i].pdfPos; }), posMeasure, what + ": E[1/pdfPos]");
}

TEST(LightEmission, SampleLeAgainstPdfLeIntegratesToOne) {
  const double R = std::sqrt(2.0), disk = M_PI * R * R;
  {
    auto o = withLight(punctual(LightType::Point));
    checkSampleLeAgainstPdfLe(*o->lights, 0, 4 * M_PI, 0, "point");
  }
  {
    const float outer = 0.9f;
    auto o = withLight(punctual(LightType::Spot, 0.3f, outer));
    checkSampleLeAgainstPdfLe(*o->lights, 0, 2 * M_PI * (1 - std::cos(outer)), 0, "spot");
  }
  {
    auto o = withLight(punctual(LightType::Directional));
    ASSERT_NEAR(o->lights->radius(), R, 1e-5);
    checkSampleLeAgainstPdfLe(*o->lights, 0, 0, disk, "directional");
  }
  for (bool doubleSided : {false, true}) {
    auto o = withTriangle(glm::vec3(2.f, 1.f, 1.f), doubleSided);
    ASSERT_EQ(o->lights->emitters().size(), 2u);
    // A cosine-weighted hemisphere per emitting side (\int cos dw = pi each); the triangle's area (half
    // of the 1 x 1 square).
    checkSampleLeAgainstPdfLe(*o->lights, 0, (doubleSided ? 2 : 1) * M_PI, 0.5,
                              doubleSided ? "double-sided triangle" : "one-sided triangle", true);
  }
  {
    auto o = withEnvironment(nullptr, glm::vec3(0.5f));
    checkSampleLeAgainstPdfLe(*o->lights, lastEmitter(*o->lights), 4 * M_PI, disk, "uniform sky");
  }
  double integral = 0.0;
  auto o = withEnvironment(twoToneMap(integral), glm::vec3(0.f));
  checkSampleLeAgainstPdfLe(*o->lights, lastEmitter(*o->lights), 4 * M_PI, disk, "environment map");
}

// The integral of pdfLe over its whole domain by independent uniform samples: directions uniform on the
// sphere (4 pi / N sum pdfDir), origins uniform on a disk larger than the emitting one (area / N sum
// pdfPos). Both are 1: pdfLe is a density, zero outside what sampleLe can produce.
TEST(LightEmission, PdfLeIsADensity) {
  auto sphereIntegral = [&](const SceneLights& lights, int e, glm::vec3 origin) {
    return estimate(kN, [&](int i) {
      float pdfPos = 0.f, pdfDir = 0.f;
      lights.pdfLe(e, Ray{origin, sampleUniformSphere(u2Of(i, 2)), 0.f, kInf}, pdfPos, pdfDir);
      return 4 * M_PI * pdfDir;
    });
  };
  {
    auto o = withLight(punctual(LightType::Point));
    expectWithin(sphereIntegral(*o->lights, 0, glm::vec3(0, 2, 0)), 1.0, "point");
  }
  {
    auto o = withLight(punctual(LightType::Spot, 0.3f, 0.9f));
    expectWithin(sphereIntegral(*o->lights, 0, glm::vec3(0, 2, 0)), 1.0, "spot");
  }
  for (bool doubleSided : {false, true}) {
    auto o = withTriangle(glm::vec3(1.f), doubleSided);
    // An origin on the first triangle (the square's centre lies on its diagonal: use a point inside).
    LeSample s;
    ASSERT_TRUE(o->lights->sampleLe(0, glm::vec2(0.3f, 0.3f), glm::vec2(0.7f, 0.2f), s));
    expectWithin(sphereIntegral(*o->lights, 0, s.ray.org), 1.0, doubleSided ? "double-sided triangle" : "triangle");
  }
  double integral = 0.0;
  for (bool useMap : {false, true}) {
    auto o = withEnvironment(useMap ? twoToneMap(integral) : nullptr, glm::vec3(0.5f));
    const SceneLights& lights = *o->lights;
    const int e = lastEmitter(lights);
    const std::string what = useMap ? "environment map" : "uniform sky";
    expectWithin(sphereIntegral(lights, e, glm::vec3(0.f)), 1.0, what + ": directions");
    // Origins uniform on a disk of radius 1.5 r across the direction -z: only the inner r counts.
    const double big = 1.5 * lights.radius(), area = M_PI * big * big;
    expectWithin(estimate(kN,
                          [&](int i) {
                            const glm::vec2 d = sampleConcentricDisk(u2Of(i, 3)) * static_cast<float>(big);
                            float pdfPos = 0.f, pdfDir = 0.f;
                            const glm::vec3 org = lights.center() + glm::vec3(d.x, d.y, 3.f);
                            lights.pdfLe(e, Ray{org, glm::vec3(0, 0, -1), 0.f, kInf}, pdfPos, pdfDir);
                            return area * pdfPos;
                          }),
                 1.0, what + ": positions");
  }
  // Directional: its origin density over a larger disk across the beam.
  auto o = withLight(punctual(LightType::Directional));
  const SceneLights& lights = *o->lights;
  const double big = 1.5 * lights.radius(), area = M_PI * big * big;
  expectWithin(estimate(kN,
                        [&](int i) {
                          const glm::vec2 d = sampleConcentricDisk(u2Of(i, 4)) * static_cast<float>(big);
                          float pdfPos = 0.f, pdfDir = 0.f;
                          const glm::vec3 org = lights.center() + glm::vec3(d.x, 3.f, d.y);
                          lights.pdfLe(0, Ray{org, glm::vec3(0, -1, 0), 0.f, kInf}, pdfPos, pdfDir);
                          return area * pdfPos;
                        }),
               1.0, "directional: positions");
}

// Each emitter's power() against its closed form, and the mean flux of its own samples against power().
TEST(LightEmission, TotalEmittedPowerMatchesEachLightsClosedForm) {
  const double I = 3.0, R = std::sqrt(2.0);
  auto check = [&](const SceneLights& lights, int e, double expected, const std::string& what) {
    EXPECT_NEAR(lights.power(e).r, expected, 1e-4 * expected) << what << ": power()";
    const Estimate flux = estimate(kN, [&](int i) {
      LeSample s;
      if (!lights.sampleLe(e, u2Of(i, 0), u2Of(i, 1), s)) return 0.0;
      return double(s.L.r) * s.cosine / (double(s.pdfPos) * s.pdfDir);
    });
    expectWithin(flux, expected, what + ": mean flux of sampleLe");
  };
  check(*withLight(punctual(LightType::Point))->lights, 0, 4 * M_PI * I, "point: 4 pi I");
  for (auto [inner, outer] : {std::pair{0.3f, 0.9f}, std::pair{0.f, 1.5f}}) {
    // \int I t(cos)^2 dw with t linear in cos between the cone angles: the inner cap at full intensity
    // and a third of the band between them.
    const double expected = 2 * M_PI * I * ((1 - std::cos(inner)) + (std::cos(inner) - std::cos(outer)) / 3);
    check(*withLight(punctual(LightType::Spot, inner, outer))->lights, 0, expected,
          "spot " + std::to_string(inner) + ".." + std::to_string(outer));
  }
  check(*withLight(punctual(LightType::Directional))->lights, 0, I * M_PI * R * R, "directional: E pi r^2");
  // Lambertian emitter of radiance L and area A (the 1 x 1 square: two triangles of 1/2): pi L A per side.
  for (bool doubleSided : {false, true}) {
    auto o = withTriangle(glm::vec3(2.f, 1.f, 1.f), doubleSided);
    for (int e = 0; e < 2; ++e)
      check(*o->lights, e, (doubleSided ? 2 : 1) * M_PI * 2.0 * 0.5, doubleSided ? "triangle, two sides" : "triangle");
  }
  // Environment: pi r^2 \int L dw (a uniform sky: pi r^2 4 pi L).
  {
    auto o = withEnvironment(nullptr, glm::vec3(0.5f));
    check(*o->lights, lastEmitter(*o->lights), M_PI * R * R * 4 * M_PI * 0.5, "uniform sky");
  }
  double integral = 0.0;
  auto o = withEnvironment(twoToneMap(integral), glm::vec3(0.f));
  // The map's integral: 2 pi (2 + 0.5) for the halves plus the bright column, to the midpoint rule.
  EXPECT_NEAR(integral, 2 * M_PI * 2.5 * (1 + 7.0 / 32), 2e-3 * integral);
  check(*o->lights, lastEmitter(*o->lights), M_PI * R * R * integral, "environment map");
}

}  // namespace
}  // namespace radiant::rt
