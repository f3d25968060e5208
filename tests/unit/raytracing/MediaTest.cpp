// The media math of the ray-tracing core against closed forms: phase functions normalised (and
// Cornette-Shanks' g = 0 is Rayleigh), optical depth of a particle sphere (constant and linear
// falloff, notes §2 oracle 5, and eq. 7.4's factor 2 at the centre), Planck with 2hc^2
// (Stefan-Boltzmann), CIE Illuminant A's chromaticity at 2856 K, Wien's peak, and delta tracking's
// collision probability 1 - e^(-optical depth).
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "renderer/raytracing/Media.h"
#include "renderer/raytracing/ParticleMedium.h"

namespace radiant::rt {
namespace {

constexpr double kPiD = 3.14159265358979323846;

// \int_{-1}^{1} f(mu) 2 pi dmu by Simpson's rule.
template <class F>
double sphereIntegral(F f, int n = 20000) {
  double s = 0.0;
  for (int i = 0; i <= n; ++i) {
    const double mu = -1.0 + 2.0 * i / n;
    s += (i == 0 || i == n ? 1 : (i % 2 ? 4 : 2)) * f(mu);
  }
  return s * (2.0 / n) / 3.0 * 2.0 * kPiD;
}

TEST(Phase, EachIntegratesToOneAndHasItsMeanCosine) {
  for (float g : {-0.7f, 0.f, 0.3f, 0.5f, 0.9f}) {
    EXPECT_NEAR(sphereIntegral([&](double mu) { return henyeyGreensteinPhase(float(mu), g); }), 1.0, 2e-4) << g;
    EXPECT_NEAR(sphereIntegral([&](double mu) { return cornetteShanksPhase(float(mu), g); }), 1.0, 2e-4) << g;
    // HG's mean cosine is g; Cornette-Shanks' is 3g(4+g^2)/(5(2+g^2)) (0.567 at g = 0.5, not 0.5).
    EXPECT_NEAR(sphereIntegral([&](double mu) { return mu * henyeyGreensteinPhase(float(mu), g); }), g, 2e-3);
    EXPECT_NEAR(sphereIntegral([&](double mu) { return mu * cornetteShanksPhase(float(mu), g); }),
                3.0 * g * (4 + g * g) / (5 * (2 + g * g)), 2e-3);
  }
  EXPECT_NEAR(isotropicPhase() * 4 * kPiD, 1.0, 1e-6);
  // Thesis eq. 1.3 with g = 0 is Rayleigh, 3 (1 + mu^2) / (16 pi).
  for (float mu : {-1.f, -0.3f, 0.f, 0.8f})
    EXPECT_NEAR(cornetteShanksPhase(mu, 0.f), 3.0 * (1 + mu * mu) / (16 * kPiD), 1e-7);
}

TEST(Phase, SampledDirectionsFollowThePhaseFunction) {
  // The sample mean of mu (weighted) matches the mean cosine: HG g, Cornette-Shanks its closed form.
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  const glm::vec3 dir(0, 0, 1);
  for (auto [model, g, expected] : {std::tuple{api::PhaseModel::HenyeyGreenstein, 0.6f, 0.6},
                                    std::tuple{api::PhaseModel::CornetteShanks, 0.5f, 3 * 0.5 * 4.25 / (5 * 2.25)},
                                    std::tuple{api::PhaseModel::Isotropic, 0.8f, 0.0}}) {
    double sum = 0, wsum = 0;
    const int n = 200000;
    for (int i = 0; i < n; ++i) {
      float w;
      const glm::vec3 o = samplePhase(model, g, dir, {u(rng), u(rng)}, w);
      EXPECT_NEAR(glm::length(o), 1.f, 1e-4f);
      sum += w * o.z, wsum += w;
    }
    EXPECT_NEAR(wsum / n, 1.0, 0.01);  // E[P / pdf] = 1
    EXPECT_NEAR(sum / n, expected, 0.01);
  }
}

TEST(OpticalDepth, ConstantSphereChordIsTwoTauW) {
  const double tau = 1.7, r = 0.8;
  for (double d : {0.0, 0.3, 0.79}) {
    const double w = std::sqrt(r * r - d * d);
    EXPECT_NEAR(sphereOpticalDepth(false, tau, r, d, -10, 10), 2 * tau * w, 1e-12);
    EXPECT_NEAR(sphereOpticalDepth(false, tau, r, d, 0, 10), tau * w, 1e-12);  // clipped at the middle
  }
  EXPECT_EQ(sphereOpticalDepth(false, tau, r, 0.8, -10, 10), 0.0);
}

TEST(OpticalDepth, LinearFalloffMatchesQuadratureAndItsChordClosedForm) {
  const double tau = 2.0, r = 1.3;
  for (double d : {0.0, 0.1, 0.6, 1.2}) {
    const double w = std::sqrt(r * r - d * d);
    for (auto [a, b] : {std::pair{-w, w}, std::pair{-0.2, 0.5}, std::pair{0.1, 5.0}}) {
      const double lo = std::max(a, -w), hi = std::min(b, w);
      double q = 0;  // midpoint rule
      const int n = 200000;
      for (int i = 0; i < n; ++i) {
        const double t = lo + (hi - lo) * (i + 0.5) / n;
        q += tau * (1 - std::sqrt(d * d + t * t) / r);
      }
      q *= (hi - lo) / n;
      EXPECT_NEAR(sphereOpticalDepth(true, tau, r, d, a, b), q, 1e-7) << d << " " << a << " " << b;
    }
    EXPECT_NEAR(sphereOpticalDepth(true, tau, r, d, -w, w), linearChordOpticalDepth(tau, r, d), 1e-12);
  }
  EXPECT_NEAR(linearChordOpticalDepth(tau, r, 0.0), tau * r, 1e-12);  // tau r at the centre
  // Eq. 7.4 gives 2 tau r there: twice the integral of the density it stands for (notes erratum),
  // and between 1.5x and 2x it over most of the disk.
  EXPECT_NEAR(thesisChordOpticalDepth(tau, r, 0.0) / linearChordOpticalDepth(tau, r, 0.0), 2.0, 1e-12);
  for (double d : {0.2, 0.5, 0.8}) {
    const double ratio = thesisChordOpticalDepth(tau, r, d * r) / linearChordOpticalDepth(tau, r, d * r);
    EXPECT_GT(ratio, 1.45) << d;
    EXPECT_LT(ratio, 2.0) << d;
  }
}

TEST(Blackbody, PlanckIntegratesToStefanBoltzmannOverPi) {
  // \int B dlambda = sigma T^4 / pi: with the thesis' C1 (2 pi hc^2) it would be 2 pi times this.
  const double sigma = 5.670374419e-8;
  for (double T : {1500.0, 2856.0, 6500.0}) {
    double s = 0;
    const double lo = 50e-9, hi = 200e-6;  // log-spaced midpoint rule
    const int n = 200000;
    for (int i = 0; i < n; ++i) {
      const double l0 = lo * std::pow(hi / lo, double(i) / n), l1 = lo * std::pow(hi / lo, double(i + 1) / n);
      s += planckRadiance(0.5 * (l0 + l1), T) * (l1 - l0);
    }
    EXPECT_NEAR(s / (sigma * T * T * T * T / kPiD), 1.0, 1e-3) << T;
  }
}

TEST(Blackbody, WienPeakAtB_overT) {
  for (double T : {1000.0, 2856.0, 5000.0}) {
    double best = 0, bestL = 0;
    for (double nm = 100; nm < 5000; nm += 0.05) {
      const double b = planckRadiance(nm * 1e-9, T);
      if (b > best) best = b, bestL = nm * 1e-9;
    }
    EXPECT_NEAR(bestL, 2.897771955e-3 / T, 1e-10) << T;
  }
}

TEST(Blackbody, IlluminantAChromaticityAndNoNaNAsTGoesToZero) {
  const glm::dvec3 xyz = blackbodyXyz(2856.0);
  const double sum = xyz.x + xyz.y + xyz.z;
  EXPECT_NEAR(xyz.x / sum, 0.4476, 0.002);  // CIE Illuminant A
  EXPECT_NEAR(xyz.y / sum, 0.4074, 0.002);
  for (double T : {0.0, 1e-30, 1.0, 50.0, 300.0}) {
    const glm::vec3 c = blackbodyRgb(T);
    for (int k = 0; k < 3; ++k) {
      EXPECT_TRUE(std::isfinite(c[k])) << T;
      EXPECT_GE(c[k], 0.f);
    }
  }
  EXPECT_EQ(blackbodyRgb(0.0), glm::vec3(0.f));
  // emission_scale is the luminance at 3000 K (sRGB's Y row: the Rec. 709 luminance weights).
  EXPECT_NEAR(luminance(blackbodyRgb(kBlackbodyReferenceKelvin)), 1.0, 1e-3);
  // Hotter is bluer: b/r rises monotonically (strictly once blue is inside the gamut; below ~1900 K
  // linear sRGB blue is negative and clamped to 0).
  double last = 0;
  for (double T = 1000; T <= 10000; T += 250) {
    const glm::vec3 c = blackbodyRgb(T);
    ASSERT_GT(c.r, 0.f);
    if (c.b > 0.f) EXPECT_GT(c.b / c.r, last) << T;
    else EXPECT_LT(T, 2000.0);
    last = c.b / c.r;
  }
}

api::ParticleSystem oneSphere(glm::vec3 c, float r, float tau, api::DensityProfile profile) {
  api::ParticleSystem s;
  s.profile = profile;
  api::Particle p;
  p.position = c, p.radius = r, p.tau = tau;
  s.particles.push_back(p);
  return s;
}

TEST(ParticleMedium, OpticalDepthAddsOverOverlappingSpheres) {
  std::vector<api::ParticleSystem> systems{oneSphere({0, 0, 0}, 1.f, 0.7f, api::DensityProfile::Constant),
                                           oneSphere({0.5f, 0.2f, 0}, 0.6f, 1.3f, api::DensityProfile::LinearExact)};
  const ParticleMedium m(systems);
  const glm::vec3 org(-5, 0.1f, 0), dir(1, 0, 0);
  const double expected = sphereOpticalDepth(false, 0.7, 1.0, 0.1, -10, 10) +
                          sphereOpticalDepth(true, 1.3, 0.6, 0.1, -10, 10);
  EXPECT_NEAR(m.opticalDepth(org, dir, 0.f, 100.f), expected, 1e-5);
  // Clipped at t = 5 (the plane x = 0): half of the constant chord, and the linear sphere's part
  // left of x = 0 (its closest point is at x = 0.5, so that is line parameters up to -0.5).
  EXPECT_NEAR(m.opticalDepth(org, dir, 0.f, 5.f),
              0.7 * std::sqrt(1 - 0.01) + sphereOpticalDepth(true, 1.3, 0.6, 0.1, -10, -0.5), 1e-5);
}

TEST(ParticleMedium, DeltaTrackingCollidesWithProbabilityOneMinusTransmittance) {
  std::vector<api::ParticleSystem> systems{oneSphere({0, 0, 0}, 1.f, 0.9f, api::DensityProfile::LinearExact),
                                           oneSphere({0.3f, 0, 0}, 0.5f, 2.f, api::DensityProfile::Constant)};
  const ParticleMedium m(systems);
  const glm::vec3 org(-3, 0.2f, 0), dir(1, 0, 0);
  const double T = std::exp(-m.opticalDepth(org, dir, 0.f, 100.f));
  std::vector<Chord> scratch;
  int hits = 0, hitsFirstHalf = 0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    Sampler s(i, 0, 11);
    float t;
    int p;
    if (m.sampleCollision(org, dir, 0.f, 100.f, s, t, p, scratch)) {
      ++hits;
      if (t < 3.f) ++hitsFirstHalf;
    }
  }
  const double pHit = 1 - T, sd = std::sqrt(pHit * (1 - pHit) / n);
  EXPECT_NEAR(double(hits) / n, pHit, 4 * sd);
  // Collisions before x = 0 happen with probability 1 - e^(-depth of [0, 3]).
  const double pFirst = 1 - std::exp(-m.opticalDepth(org, dir, 0.f, 3.f));
  EXPECT_NEAR(double(hitsFirstHalf) / n, pFirst, 4 * std::sqrt(pFirst * (1 - pFirst) / n));
}

}  // namespace
}  // namespace radiant::rt
