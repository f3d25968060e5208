// The reference BSDF's math against closed forms and quadrature: pdfs integrate to 1, samples follow
// their pdfs, sample weights agree with eval/pdf, Fresnel and visibility match their textbook forms.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>
#include <vector>

#include "renderer/raytracing/Bsdf.h"
#include "tests/unit/reference/TestScenes.h"

namespace radiant::rt {
namespace {

using PdfFn = std::function<double(const glm::vec3&)>;
using SampleFn = std::function<bool(glm::vec2, float, glm::vec3&)>;

// \int pdf dw over the sphere (or the upper hemisphere) by midpoint quadrature in (cos theta, phi).
double integrate(const PdfFn& pdf, bool fullSphere, int nCos = 2000, int nPhi = 256) {
  const double lo = fullSphere ? -1.0 : 0.0;
  const double dc = (1.0 - lo) / nCos, dp = 2.0 * M_PI / nPhi;
  double sum = 0.0;
  for (int i = 0; i < nCos; ++i) {
    const double c = lo + (i + 0.5) * dc, s = std::sqrt(std::max(0.0, 1.0 - c * c));
    for (int j = 0; j < nPhi; ++j) {
      const double phi = (j + 0.5) * dp;
      sum += pdf(glm::vec3(float(s * std::cos(phi)), float(s * std::sin(phi)), float(c))) * dc * dp;
    }
  }
  return sum;
}

// Histogram test: samples binned in (cos theta, phi) against the pdf integrated over each bin.
void expectSamplesFollowPdf(const SampleFn& sample, const PdfFn& pdf, bool fullSphere, const char* what,
                            int n = 400000) {
  constexpr int kCos = 16, kPhi = 16, kSub = 6;
  const double lo = fullSphere ? -1.0 : 0.0;
  std::vector<double> observed(kCos * kPhi, 0.0), expected(kCos * kPhi, 0.0);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> U(0.f, 1.f);
  int produced = 0;
  for (int s = 0; s < n; ++s) {
    glm::vec3 w;
    if (!sample({U(rng), U(rng)}, U(rng), w)) continue;
    ++produced;
    const double c = std::clamp<double>(w.z, lo, 1.0);
    double phi = std::atan2(w.y, w.x);
    if (phi < 0) phi += 2 * M_PI;
    const int ic = std::min(kCos - 1, int((c - lo) / (1.0 - lo) * kCos));
    const int ip = std::min(kPhi - 1, int(phi / (2 * M_PI) * kPhi));
    observed[ic * kPhi + ip] += 1.0;
  }
  const double dc = (1.0 - lo) / kCos, dp = 2 * M_PI / kPhi;
  double total = 0.0;
  for (int ic = 0; ic < kCos; ++ic)
    for (int ip = 0; ip < kPhi; ++ip) {
      double e = 0.0;
      for (int a = 0; a < kSub; ++a)
        for (int b = 0; b < kSub; ++b) {
          const double c = lo + (ic + (a + 0.5) / kSub) * dc, phi = (ip + (b + 0.5) / kSub) * dp;
          const double sn = std::sqrt(std::max(0.0, 1 - c * c));
          e += pdf(glm::vec3(float(sn * std::cos(phi)), float(sn * std::sin(phi)), float(c))) * (dc / kSub) * (dp / kSub);
        }
      expected[ic * kPhi + ip] = e * n;
      total += e;
    }
  // The pdf's mass equals the fraction of successful samples (a failed sample carries no direction).
  EXPECT_NEAR(total, double(produced) / n, 0.01) << what;
  for (int i = 0; i < kCos * kPhi; ++i) {
    if (expected[i] < 200.0) continue;
    // 5 sigma of the Poisson count + 3% for the bin quadrature of steep pdfs.
    EXPECT_NEAR(observed[i], expected[i], 5.0 * std::sqrt(expected[i]) + 0.03 * expected[i])
        << what << " bin " << i / kPhi << "," << i % kPhi;
  }
}

TEST(Sampling, CosineHemispherePdfIntegratesToOne) {
  EXPECT_NEAR(integrate([](const glm::vec3& w) { return cosineHemispherePdf(w.z); }, false), 1.0, 1e-4);
  EXPECT_NEAR(integrate([](const glm::vec3& w) { return cosinePowerHemispherePdf(w.z, 3.f); }, false), 1.0, 1e-4);
  EXPECT_NEAR(integrate([](const glm::vec3&) { return uniformSpherePdf(); }, true), 1.0, 1e-5);
}

TEST(Sampling, CosineSamplesFollowPdf) {
  expectSamplesFollowPdf([](glm::vec2 u, float, glm::vec3& w) { w = sampleCosineHemisphere(u); return true; },
                         [](const glm::vec3& w) { return cosineHemispherePdf(w.z); }, false, "cosine");
  expectSamplesFollowPdf(
      [](glm::vec2 u, float, glm::vec3& w) { w = sampleCosinePowerHemisphere(u, 3.f); return true; },
      [](const glm::vec3& w) { return cosinePowerHemispherePdf(w.z, 3.f); }, false, "cos^3");
  expectSamplesFollowPdf([](glm::vec2 u, float, glm::vec3& w) { w = sampleUniformSphere(u); return true; },
                         [](const glm::vec3&) { return uniformSpherePdf(); }, true, "sphere");
}

TEST(Sampling, VndfPdfIntegratesToOne) {
  for (float alpha : {0.1f, 0.3f, 0.6f, 1.f})
    for (float cosO : {1.f, 0.7f, 0.3f, 0.05f}) {
      const glm::vec3 wo(std::sqrt(1 - cosO * cosO), 0.f, cosO);
      // Over microfacet normals h: \int D_wo(h) dh = 1 (Heitz 2018 eq. 2, by the definition of G1).
      const double mass = integrate([&](const glm::vec3& h) { return ggxVndfPdf(wo, h, alpha); }, false, 4000, 256);
      EXPECT_NEAR(mass, 1.0, 5e-3) << "alpha " << alpha << " cos " << cosO;
      // And D itself is normalised: \int D(h) (n.h) dh = 1.
      if (cosO == 1.f) {
        EXPECT_NEAR(integrate([&](const glm::vec3& h) { return ggxD(h.z, alpha) * h.z; }, false, 4000, 64), 1.0, 5e-3);
      }
    }
}

TEST(Sampling, VndfReflectionSamplesFollowPdf) {
  for (float alpha : {0.2f, 0.5f, 1.f})
    for (float cosO : {0.9f, 0.4f}) {
      const glm::vec3 wo(std::sqrt(1 - cosO * cosO), 0.f, cosO);
      expectSamplesFollowPdf(
          [&](glm::vec2 u, float, glm::vec3& w) {
            w = reflect(wo, sampleGgxVndf(wo, alpha, u));
            return w.z > 0.f;
          },
          [&](const glm::vec3& w) { return ggxReflectionPdf(wo, w, alpha); }, false, "vndf reflection");
    }
}

// Non-delta samples of b at wo follow b.pdf (histogram against the pdf) and carry the weight
// f |cos| / pdf with that same pdf (the MIS weights rely on it).
void expectSampleWeightsFollowPdf(const GltfBsdf& b, const glm::vec3& wo, const char* label) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> U(0.f, 1.f);
  expectSamplesFollowPdf(
      [&](glm::vec2 u, float ul, glm::vec3& w) {
        GltfBsdf::Sample s;
        if (!b.sample(wo, ul, U(rng), u, s) || s.delta) return false;
        const glm::vec3 expectW = b.eval(wo, s.wi) * std::abs(s.wi.z) / b.pdf(wo, s.wi);
        EXPECT_NEAR(s.weight.x, expectW.x, 1e-3f * (1.f + expectW.x));
        w = s.wi;
        return true;
      },
      [&](const glm::vec3& w) { return b.pdf(wo, w); }, true, label, 200000);
}

TEST(Sampling, GltfBsdfSamplesFollowPdf) {
  struct Case { float metallic, roughness, transmission; };
  for (const Case c : {Case{0.f, 0.5f, 0.f}, Case{0.3f, 0.4f, 0.f}, Case{1.f, 0.7f, 0.f}, Case{0.f, 0.5f, 1.f},
                       Case{0.f, 0.6f, 0.5f}})
    for (float eta : {1.5f, 1.f / 1.5f}) {
      GltfBsdf b;
      b.baseColor = {0.8f, 0.6f, 0.4f};
      b.metallic = c.metallic;
      b.roughness = c.roughness;
      b.transmission = c.transmission;
      b.ior = 1.5f;
      b.eta = eta;
      const glm::vec3 wo = glm::normalize(glm::vec3(0.5f, 0.2f, 0.8f));
      expectSampleWeightsFollowPdf(b, wo, "gltf bsdf");
    }
}

TEST(Brdf, VisibilityIsHeightCorrelatedSmithOverFourCosines) {
  for (float alpha : {0.01f, 0.2f, 0.7f, 1.f})
    for (float nl : {0.05f, 0.5f, 1.f})
      for (float nv : {0.1f, 0.6f, 0.95f})
        EXPECT_NEAR(ggxVisibility(nl, nv, alpha), smithG2HeightCorrelated(nv, nl, alpha) / (4.f * nl * nv),
                    1e-4f * ggxVisibility(nl, nv, alpha));
}

TEST(Brdf, FresnelDielectricClosedForms) {
  const float n = 1.5f;
  EXPECT_NEAR(fresnelDielectric(1.f, n), sqr((n - 1) / (n + 1)), 1e-6f);  // 0.04 at normal incidence
  // Hand-evaluated Fresnel equations at 45 degrees into glass: Rs = 0.0920, Rp = 0.00847.
  EXPECT_NEAR(fresnelDielectric(std::cos(kPi / 4), n), 0.5f * (0.092013f + 0.0084663f), 2e-5f);
  // Total internal reflection beyond the critical angle asin(1 / n) = 41.81 degrees, from inside.
  const float critical = std::asin(1.f / n);
  EXPECT_LT(fresnelDielectric(std::cos(critical - 0.01f), 1.f / n), 1.f);
  EXPECT_EQ(fresnelDielectric(std::cos(critical + 0.01f), 1.f / n), 1.f);
  // Reciprocity (Stokes): R(theta_i, n) = R(theta_t, 1/n).
  for (float ti : {0.1f, 0.5f, 1.0f, 1.4f}) {
    const float tt = std::asin(std::sin(ti) / n);
    EXPECT_NEAR(fresnelDielectric(std::cos(ti), n), fresnelDielectric(std::cos(tt), 1.f / n), 1e-5f);
  }
  glm::vec3 wi;
  const glm::vec3 wo(std::sin(critical + 0.01f), 0.f, std::cos(critical + 0.01f));
  EXPECT_FALSE(refract(wo, {0, 0, 1}, 1.f / n, wi));
  const glm::vec3 wo2(std::sin(0.5f), 0.f, std::cos(0.5f));
  ASSERT_TRUE(refract(wo2, {0, 0, 1}, n, wi));
  EXPECT_NEAR(std::sqrt(wi.x * wi.x + wi.y * wi.y), std::sin(0.5f) / n, 1e-6f);  // Snell
  EXPECT_LT(wi.z, 0.f);
}

TEST(Brdf, WhiteFurnaceNeverGainsEnergyAndSamplingAgreesWithQuadrature) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> U(0.f, 1.f);
  for (float metallic : {0.f, 1.f})
    for (float roughness : {0.3f, 0.6f, 1.f})
      for (float cosO : {1.f, 0.5f, 0.15f}) {
        GltfBsdf b;
        b.baseColor = glm::vec3(1.f);
        b.metallic = metallic;
        b.roughness = roughness;
        const double e = testing::directionalAlbedo(b, cosO).x;
        // A white metal (single-scattering GGX) only loses energy. The glTF dielectric does not have
        // that property: fresnel_mix weights the diffuse lobe by 1 - F(v.h) per direction rather than by
        // 1 - (specular albedo), so at grazing view it reflects more than it receives (quadrature gives
        // E = 1.236 at roughness 0.3, n.v = 0.15). That is the spec's model; we check it only at normal
        // incidence, where it holds.
        if (metallic == 1.f || cosO == 1.f) {
          EXPECT_LE(e, 1.0 + 1e-3) << metallic << " " << roughness << " " << cosO;
        }
        const glm::vec3 wo(std::sqrt(1 - cosO * cosO), 0.f, cosO);
        double mc = 0.0;
        const int n = 200000;
        for (int i = 0; i < n; ++i) {
          GltfBsdf::Sample s;
          if (b.sample(wo, U(rng), U(rng), {U(rng), U(rng)}, s)) mc += s.weight.x;
        }
        EXPECT_NEAR(mc / n, e, 0.01 * e) << metallic << " " << roughness << " " << cosO;
      }
}

TEST(Brdf, SmoothMirrorAndDielectricDeltas) {
  GltfBsdf mirror;
  mirror.baseColor = glm::vec3(0.5f);
  mirror.metallic = 1.f;
  mirror.roughness = 0.f;
  const glm::vec3 wo(std::sin(1.f), 0.f, std::cos(1.f));
  GltfBsdf::Sample s;
  ASSERT_TRUE(mirror.sample(wo, 0.5f, 0.5f, {0.3f, 0.7f}, s));
  EXPECT_TRUE(s.delta);
  EXPECT_NEAR(s.wi.x, -wo.x, 1e-6f);
  EXPECT_NEAR(s.wi.z, wo.z, 1e-6f);
  EXPECT_NEAR(s.weight.x, 0.5f + 0.5f * std::pow(1.f - std::cos(1.f), 5.f), 1e-5f);  // Schlick, f0 = base
  EXPECT_FALSE(mirror.hasNonDeltaLobe(wo));
  EXPECT_EQ(mirror.eval(wo, glm::vec3(-wo.x, 0, wo.z)), glm::vec3(0.f));

  // Smooth glass: reflection with probability R, refraction with 1 - R; the expected weight, with
  // refraction's 1/eta^2 radiance scaling undone, is R + T = 1.
  GltfBsdf glass;
  glass.baseColor = glm::vec3(1.f);
  glass.metallic = 0.f;
  glass.roughness = 0.f;
  glass.transmission = 1.f;
  glass.eta = 1.5f;
  const float R = fresnelDielectric(wo.z, 1.5f);
  double reflected = 0.0, energy = 0.0;
  const int n = 10000;
  for (int i = 0; i < n; ++i) {
    ASSERT_TRUE(glass.sample(wo, 0.5f, (i + 0.5f) / n, {0.5f, 0.5f}, s));
    ASSERT_TRUE(s.delta);
    if (s.wi.z > 0.f) { reflected += 1.0; energy += s.weight.x; }
    else energy += s.weight.x * 1.5 * 1.5;
  }
  EXPECT_NEAR(reflected / n, R, 2.0 / n);
  EXPECT_NEAR(energy / n, 1.0, 1e-4);
}

TEST(Brdf, ReflectionIsReciprocalAndRefractionDiffersByEtaSquaredBetweenTransportModes) {
  // Issue #20's adjointness oracle (Veach 1997, eq. 5.14): reflection is symmetric, f(wo, wi) =
  // f(wi, wo), in either transport mode; refraction carries radiance compressed by 1 / eta^2 and
  // importance uncompressed, so f_radiance / f_importance = 1 / eta^2 exactly, from either side.
  std::mt19937 rng(20);
  std::uniform_real_distribution<float> U(-1.f, 1.f);
  auto upper = [&] {
    glm::vec3 w;
    do w = glm::vec3(U(rng), U(rng), std::abs(U(rng)));
    while (glm::dot(w, w) > 1.f || w.z < 0.02f);
    return glm::normalize(w);
  };
  int reflections = 0, refractions = 0;
  for (int i = 0; i < 4000; ++i) {
    GltfBsdf b;
    b.baseColor = glm::vec3(0.9f, 0.6f, 0.3f);
    b.metallic = i % 4 == 0 ? 1.f : 0.f;
    b.roughness = 0.05f + 0.9f * (0.5f + 0.5f * U(rng));
    b.transmission = i % 2 ? 1.f : 0.f;
    b.eta = i % 3 ? 1.5f : 1.f / 1.5f;
    const glm::vec3 wo = upper(), wi = upper();
    for (TransportMode mode : {TransportMode::Radiance, TransportMode::Importance}) {
      b.mode = mode;
      const glm::vec3 f = b.eval(wo, wi), g = b.eval(wi, wo);
      for (int c = 0; c < 3; ++c) ASSERT_NEAR(f[c], g[c], 1e-4f * std::max(1.f, f[c])) << i;
    }
    ++reflections;
    if (b.transmission == 0.f || b.metallic == 1.f) continue;
    const glm::vec3 wt = glm::vec3(wi.x, wi.y, -wi.z);  // below the surface: a refracted direction
    b.mode = TransportMode::Radiance;
    const glm::vec3 radiance = b.eval(wo, wt);
    b.mode = TransportMode::Importance;
    const glm::vec3 importance = b.eval(wo, wt);
    if (!(importance.x > 1e-6f)) continue;
    for (int c = 0; c < 3; ++c)
      ASSERT_NEAR(radiance[c] / importance[c], 1.f / (b.eta * b.eta), 1e-5f) << i << " eta " << b.eta;
    ++refractions;
  }
  EXPECT_EQ(reflections, 4000);
  EXPECT_GT(refractions, 300);  // 437 of the 1500 transmissive dielectric pairs have f > 0 (rough refraction does not reach every pair)
}

TEST(Brdf, NeverNaN) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> U(0.f, 1.f);
  for (int i = 0; i < 200000; ++i) {
    GltfBsdf b;
    b.baseColor = {U(rng), U(rng), U(rng)};
    b.metallic = U(rng) < 0.3f ? 1.f : U(rng);
    const float r = U(rng);
    b.roughness = r < 0.2f ? 0.f : (r < 0.4f ? 1e-4f : U(rng));
    b.transmission = U(rng) < 0.5f ? 0.f : U(rng);
    b.eta = U(rng) < 0.5f ? 1.5f : 1.f / 1.5f;
    glm::vec3 wo = sampleCosineHemisphere({U(rng), U(rng)});
    if (i % 7 == 0) wo = glm::normalize(glm::vec3(1.f, 0.f, 1e-6f));  // grazing
    const glm::vec3 wi = sampleUniformSphere({U(rng), U(rng)});
    const glm::vec3 f = b.eval(wo, wi);
    const float p = b.pdf(wo, wi);
    ASSERT_TRUE(std::isfinite(f.x + f.y + f.z) && f.x >= 0.f) << i;
    ASSERT_TRUE(std::isfinite(p) && p >= 0.f) << i;
    GltfBsdf::Sample s;
    if (b.sample(wo, U(rng), U(rng), {U(rng), U(rng)}, s)) {
      ASSERT_TRUE(std::isfinite(s.weight.x + s.weight.y + s.weight.z)) << i;
      ASSERT_TRUE(std::isfinite(s.wi.x + s.wi.y + s.wi.z)) << i;
    }
  }
}


// ---------------------------------------------------------------------------------------------------
// The layered extensions: KHR_materials_clearcoat, _sheen, _specular.

GltfBsdf layered(float metallic, float roughness, glm::vec3 base, float coat, float coatRoughness,
                 glm::vec3 sheen, float sheenRoughness) {
  GltfBsdf b;
  b.baseColor = base;
  b.metallic = metallic;
  b.roughness = roughness;
  b.clearcoat = coat;
  b.clearcoatRoughness = coatRoughness;
  b.sheenColor = sheen;
  b.sheenRoughness = sheenRoughness;
  return b;
}

TEST(LayeredBsdf, SheenAlbedoTableMatchesQuadratureOfTheSheenLobe) {
  // A sheen over a black, non-reflecting base (specular weight 0): the albedo is c E(mu, r) exactly.
  constexpr int N = gpu::kSheenAlbedoSize;
  for (int j : {0, 7, 20, N - 1})
    for (int i : {3, 5, 10, 20, N - 1}) {
      const float r = gpu::kMinSheenRoughness + (1.f - gpu::kMinSheenRoughness) * float(j) / float(N - 1);
      const float mu = float(i) / float(N - 1);
      GltfBsdf b = layered(0.f, 0.5f, glm::vec3(0.f), 0.f, 0.f, glm::vec3(1.f), r);
      b.specularWeight = 0.f;
      const double e = testing::directionalAlbedo(b, mu, 400, 360).x;
      // At the grid points the table is the quadrature (measured within 0.4%).
      EXPECT_NEAR(sheenAlbedo(mu, r), e, 0.01 * e + 2e-4) << "r " << r << " mu " << mu;
      EXPECT_LE(e, 1.0) << "r " << r << " mu " << mu;
      // Between them it is bilinear. Where E falls steeply (smallest roughness, grazing) the chord lies
      // above the curve: measured +4.7% at r = 0.07, mu = 0.15. Too large an E only makes the base
      // lose a little more under the sheen (never gain energy), so 6% bounds it.
      const float mid = (float(i) - 0.5f) / float(N - 1);
      const double em = testing::directionalAlbedo(b, mid, 400, 360).x;
      EXPECT_NEAR(sheenAlbedo(mid, r), em, 0.06 * em + 2e-3) << "r " << r << " mu " << mid;
    }
}

TEST(LayeredBsdf, WhiteFurnaceNeverGainsEnergyWithCoatAndSheen) {
  // Over an energy-conserving base (a white GGX metal) the layers only redistribute: the coat takes
  // cw and leaves (1 - cw), the sheen takes c E and leaves at most 1 - c E. Quadrature of eval, and the
  // sampler's mean weight (which also covers the Dirac coat) agree with it.
  std::mt19937 rng(13);
  std::uniform_real_distribution<float> U(0.f, 1.f);
  for (float coatRoughness : {0.f, 0.3f})
    for (float sheen : {0.f, 1.f})
      for (float cosO : {1.f, 0.5f, 0.15f}) {
        const GltfBsdf b = layered(1.f, 0.5f, glm::vec3(1.f), 1.f, coatRoughness, glm::vec3(sheen), 0.5f);
        const glm::vec3 wo(std::sqrt(1 - cosO * cosO), 0.f, cosO);
        double e = testing::directionalAlbedo(b, cosO, 400, 360).x;
        if (coatRoughness == 0.f) e += b.coatWeight(wo);  // the Dirac coat reflects cw into the mirror direction
        EXPECT_LE(e, 1.0 + 5e-3) << coatRoughness << " " << sheen << " " << cosO;
        EXPECT_GT(e, 0.5) << coatRoughness << " " << sheen << " " << cosO;
        double mc = 0.0;
        const int n = 200000;
        for (int i = 0; i < n; ++i) {
          GltfBsdf::Sample s;
          if (b.sample(wo, U(rng), U(rng), {U(rng), U(rng)}, s)) mc += s.weight.x;
        }
        EXPECT_NEAR(mc / n, e, 0.015 * e) << coatRoughness << " " << sheen << " " << cosO;
      }
}

TEST(LayeredBsdf, SmoothCoatOverBlackReflectsItsFresnelWeight) {
  // clearcoat 1, roughness 0, over a black base that reflects nothing: every sample is the coat's
  // mirror with weight such that the expected reflectance is Fc(mu) = 0.04 + 0.96 (1 - mu)^5.
  for (float mu : {1.f, 0.5f, 0.1f}) {
    GltfBsdf b = layered(0.f, 0.5f, glm::vec3(0.f), 1.f, 0.f, glm::vec3(0.f), 0.5f);
    b.specularWeight = 0.f;
    const glm::vec3 wo(std::sqrt(1 - mu * mu), 0.f, mu);
    GltfBsdf::Sample s;
    ASSERT_TRUE(b.sample(wo, 0.f, 0.5f, {0.5f, 0.5f}, s));
    ASSERT_TRUE(s.delta);
    EXPECT_NEAR(s.wi.x, -wo.x, 1e-6f);
    const float p = b.lobeProbabilities(wo).coat;
    EXPECT_NEAR(s.weight.x * p, 0.04f + 0.96f * std::pow(1.f - mu, 5.f), 1e-5f) << mu;
  }
}

TEST(LayeredBsdf, ReciprocityAndTheCoatsStatedAsymmetry) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> U(0.f, 1.f);
  for (int i = 0; i < 2000; ++i) {
    const glm::vec3 a = sampleCosineHemisphere({U(rng), U(rng)}), c = sampleCosineHemisphere({U(rng), U(rng)});
    if (a.z < 0.05f || c.z < 0.05f) continue;
    // Sheen and specular (tinted F0, partial weight) keep the BRDF reciprocal: f(a, c) = f(c, a).
    GltfBsdf s = layered(0.3f, 0.4f, {0.8f, 0.5f, 0.3f}, 0.f, 0.f, {0.9f, 0.4f, 0.6f}, 0.35f);
    s.specularColor = {1.5f, 0.5f, 2.f};
    s.specularWeight = 0.7f;
    const glm::vec3 fac = s.eval(a, c), fca = s.eval(c, a);
    ASSERT_NEAR(fac.x, fca.x, 1e-4f * (fac.x + 1e-3f)) << i;
    ASSERT_NEAR(fac.z, fca.z, 1e-4f * (fac.z + 1e-3f)) << i;
    // The coat alone (black base): f(a, c) / f(c, a) = Fc(a) / Fc(c), KHR_materials_clearcoat's mix
    // weight taken at v (Bsdf.h states it).
    GltfBsdf coat = layered(0.f, 0.5f, glm::vec3(0.f), 1.f, 0.4f, glm::vec3(0.f), 0.5f);
    coat.specularWeight = 0.f;
    const float ratio = coat.coatWeight(a) / coat.coatWeight(c);
    const float fa = coat.eval(a, c).x, fc = coat.eval(c, a).x;
    if (fc > 1e-6f) {
      ASSERT_NEAR(fa / fc, ratio, 1e-4f * ratio) << i;
    }
  }
}

TEST(LayeredBsdf, PdfIsTheDensityOfItsSamples) {
  struct Case { float metallic, roughness, transmission, coat, coatRoughness, sheen; };
  for (const Case c : {Case{0.f, 0.5f, 0.f, 1.f, 0.3f, 0.f}, Case{0.f, 0.6f, 0.f, 0.f, 0.f, 1.f},
                       Case{1.f, 0.4f, 0.f, 0.7f, 0.2f, 0.5f}, Case{0.f, 0.5f, 1.f, 1.f, 0.3f, 0.8f}}) {
    GltfBsdf b = layered(c.metallic, c.roughness, {0.8f, 0.6f, 0.4f}, c.coat, c.coatRoughness, glm::vec3(c.sheen),
                         0.4f);
    b.transmission = c.transmission;
    b.specularColor = {1.2f, 0.8f, 1.f};
    b.specularWeight = 0.8f;
    // A coat normal tilted off the shading normal (a normal-mapped base under a flat coat).
    b.coatNormal = glm::normalize(glm::vec3(0.2f, -0.1f, 1.f));
    const glm::vec3 wo = glm::normalize(glm::vec3(0.5f, 0.2f, 0.8f));
    // The pdf integrates to the fraction of sample() calls that return a non-delta direction (the
    // reflection lobes lose the microfacet reflections that point below the horizon, as
    // single-scattering GGX does); expectSamplesFollowPdf checks that equality and the shape.
    const double mass = integrate([&](const glm::vec3& w) { return double(b.pdf(wo, w)); }, true, 1000, 256);
    EXPECT_LE(mass, 1.0 + 2e-3) << c.coat << " " << c.sheen << " " << c.transmission;
    EXPECT_GT(mass, 0.95) << c.coat << " " << c.sheen << " " << c.transmission;
    expectSampleWeightsFollowPdf(b, wo, "layered bsdf");
  }
}

TEST(LayeredBsdf, SheenOverLambertPdfIntegratesToOne) {
  // Two cosine lobes (sheen and diffuse) lose nothing: the pdf integrates to exactly 1.
  GltfBsdf b = layered(0.f, 1.f, glm::vec3(0.7f), 0.f, 0.f, glm::vec3(0.8f), 0.5f);
  b.specularWeight = 0.f;
  for (float mu : {1.f, 0.4f, 0.1f}) {
    const glm::vec3 wo(std::sqrt(1.f - mu * mu), 0.f, mu);
    EXPECT_NEAR(integrate([&](const glm::vec3& w) { return double(b.pdf(wo, w)); }, false, 1000, 128), 1.0, 1e-3)
        << mu;
  }
}

TEST(LayeredBsdf, SpecularExtensionClosedForms) {
  GltfBsdf b;
  b.baseColor = {0.6f, 0.4f, 0.2f};
  b.metallic = 0.f;
  b.roughness = 0.5f;
  // KHR_materials_specular: F0 = min(F0(ior) specularColor, 1), F90 = 1.
  b.specularColor = {0.5f, 2.f, 40.f};
  EXPECT_NEAR(b.dielectricFresnel(1.f).x, 0.02f, 1e-6f);
  EXPECT_NEAR(b.dielectricFresnel(1.f).y, 0.08f, 1e-6f);
  EXPECT_NEAR(b.dielectricFresnel(1.f).z, 1.f, 1e-6f);
  EXPECT_NEAR(b.dielectricFresnel(0.f).x, 1.f, 1e-6f);
  // specularFactor 0 leaves the Lambertian base alone: f = baseColor / pi in every direction.
  b.specularWeight = 0.f;
  std::mt19937 rng(23);
  std::uniform_real_distribution<float> U(0.f, 1.f);
  for (int i = 0; i < 100; ++i) {
    const glm::vec3 wo = sampleCosineHemisphere({U(rng), U(rng)}), wi = sampleCosineHemisphere({U(rng), U(rng)});
    if (wo.z <= 0.f || wi.z <= 0.f) continue;
    EXPECT_NEAR(b.eval(wo, wi).x, 0.6f * kInvPi, 1e-6f);
  }
}

TEST(LayeredBsdf, NeverNaN) {
  std::mt19937 rng(29);
  std::uniform_real_distribution<float> U(0.f, 1.f);
  for (int i = 0; i < 100000; ++i) {
    GltfBsdf b = layered(U(rng) < 0.3f ? 1.f : U(rng), U(rng) < 0.2f ? 0.f : U(rng), {U(rng), U(rng), U(rng)},
                         U(rng) < 0.3f ? 0.f : U(rng), U(rng) < 0.3f ? 0.f : U(rng),
                         U(rng) < 0.3f ? glm::vec3(0.f) : glm::vec3(U(rng), U(rng), U(rng)),
                         std::max(gpu::kMinSheenRoughness, U(rng)));
    b.transmission = U(rng) < 0.5f ? 0.f : U(rng);
    b.eta = U(rng) < 0.5f ? 1.5f : 1.f / 1.5f;
    b.specularColor = {2.f * U(rng), 2.f * U(rng), 2.f * U(rng)};
    b.specularWeight = U(rng);
    b.coatNormal = glm::normalize(glm::vec3(U(rng) - 0.5f, U(rng) - 0.5f, 1.f));
    glm::vec3 wo = sampleCosineHemisphere({U(rng), U(rng)});
    if (i % 7 == 0) wo = glm::normalize(glm::vec3(1.f, 0.f, 1e-6f));
    const glm::vec3 wi = sampleUniformSphere({U(rng), U(rng)});
    const glm::vec3 f = b.eval(wo, wi);
    const float p = b.pdf(wo, wi);
    ASSERT_TRUE(std::isfinite(f.x + f.y + f.z) && f.x >= 0.f && f.y >= 0.f && f.z >= 0.f) << i;
    ASSERT_TRUE(std::isfinite(p) && p >= 0.f) << i;
    GltfBsdf::Sample s;
    if (b.sample(wo, U(rng), U(rng), {U(rng), U(rng)}, s)) {
      ASSERT_TRUE(std::isfinite(s.weight.x + s.weight.y + s.weight.z) && s.weight.x >= 0.f) << i;
    }
  }
}

}  // namespace
}  // namespace radiant::rt
