// light_volumes against the reference's own lobe (issue 15, notes A8): the roughness-to-sigma fit and
// the glossy beam's flux.
// - sigma = kSigmaScaleFit alpha sqrt(cos theta_i) is the L1-best Gaussian of the reference BSDF's GGX
//   lobe (Bsdf.h: D V cos(theta_o), white metal) over roughness 0.1..0.5 and theta_i 0..60 degrees,
//   and the single constant loses little against the best sigma of each (roughness, theta_i);
// - ggxReflectionAlbedo (the beam's flux weight) is the lobe's directional albedo, checked against an
//   independent quadrature of D V cos over the hemisphere;
// - a glossy plate's beams carry the light tracer's energy onto the floor within 3% (the issue's
//   bound), with the relative L1 of the image printed beside the light tracer's own noise.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "api/Validate.h"
#include "renderer/raytracing/Bsdf.h"
#include "renderer/raytracing/RayScene.h"
#include "renderer/reference/LightTracer.h"
#include "renderer/techniques/light_volumes/Beams.h"
#include "tests/support/SceneBuilder.h"

namespace radiant::light_volumes {
namespace {

// The reference lobe p(w) = D V cos(theta_o) of a white GGX metal (F = 1) lit from theta_i, tabulated
// in polar coordinates (phi, psi) about the mirror direction out to phiMax.
struct Lobe {
  std::vector<double> p, dw, phi;
  double albedo = 0.0;
};

Lobe referenceLobe(float alpha, float mu, float phiMax, int nPhi = 240, int nPsi = 48) {
  Lobe l;
  const glm::vec3 wi(std::sqrt(1.f - mu * mu), 0.f, mu);  // towards the light
  const glm::vec3 r(-wi.x, 0.f, mu);                      // the mirror direction
  const glm::vec3 t1 = glm::normalize(glm::cross(r, glm::vec3(0.f, 1.f, 0.f))), t2 = glm::cross(r, t1);
  for (int i = 0; i < nPhi; ++i) {
    const double phi = phiMax * (i + 0.5) / nPhi;
    for (int j = 0; j < nPsi; ++j) {
      const double psi = 2.0 * M_PI * (j + 0.5) / nPsi;
      const glm::vec3 wo = float(std::cos(phi)) * r + float(std::sin(phi)) * (float(std::cos(psi)) * t1 + float(std::sin(psi)) * t2);
      double v = 0.0;
      if (wo.z > 0.f) {
        const glm::vec3 h = glm::normalize(wo + wi);
        v = double(rt::ggxD(h.z, alpha)) * rt::ggxVisibility(wo.z, wi.z, alpha) * wo.z;
      }
      const double dw = std::sin(phi) * (phiMax / nPhi) * (2.0 * M_PI / nPsi);
      l.p.push_back(v);
      l.dw.push_back(dw);
      l.phi.push_back(phi);
      l.albedo += v * dw;
    }
  }
  return l;
}

// L1 distance between the normalised lobe and the beam's Gaussian rho(phi) = exp(-phi^2 / 2 sigma^2) /
// (2 pi sigma^2), which is a density over the flat angular domain (phi dphi dpsi): per steradian it is
// rho phi / sin(phi).
double lobeL1(const Lobe& l, double sigma) {
  double d = 0.0;
  for (std::size_t k = 0; k < l.p.size(); ++k) {
    const double phi = l.phi[k];
    const double g = std::exp(-phi * phi / (2.0 * sigma * sigma)) / (2.0 * M_PI * sigma * sigma) * phi / std::sin(phi);
    d += std::abs(l.p[k] / l.albedo - g) * l.dw[k];
  }
  return d;
}

template <class F>
double goldenMinimum(F f, double lo, double hi) {
  for (int it = 0; it < 48; ++it) {
    const double a = lo + (hi - lo) * 0.382, b = lo + (hi - lo) * 0.618;
    if (f(a) < f(b)) hi = b;
    else lo = a;
  }
  return 0.5 * (lo + hi);
}

TEST(LightVolumesCalibration, SigmaFitIsTheL1BestGaussianOfTheReferenceLobe) {
  const float roughness[] = {0.1f, 0.2f, 0.3f, 0.4f, 0.5f};
  const float thetaDeg[] = {0.f, 20.f, 40.f, 60.f};
  struct Case { Lobe lobe; float alpha, mu; double bestScale, bestL1; };
  std::vector<Case> cases;
  for (float r : roughness)
    for (float t : thetaDeg) {
      const float alpha = r * r, mu = std::cos(t * float(M_PI) / 180.f);
      Case c{referenceLobe(alpha, mu, std::min(1.5f, 30.f * alpha)), alpha, mu, 0.0, 0.0};
      const double norm = alpha * std::sqrt(mu);
      c.bestScale = goldenMinimum([&](double s) { return lobeL1(c.lobe, s * norm); }, 0.3, 3.0);
      c.bestL1 = lobeL1(c.lobe, c.bestScale * norm);
      cases.push_back(std::move(c));
    }
  auto meanL1 = [&](double scale) {
    double s = 0.0;
    for (const Case& c : cases) s += lobeL1(c.lobe, scale * c.alpha * std::sqrt(c.mu));
    return s / cases.size();
  };
  const double fit = goldenMinimum(meanL1, 0.8, 2.5);
  double worstExcess = 0.0, lo = 1e9, hi = 0.0;
  for (const Case& c : cases) {
    const double atFit = lobeL1(c.lobe, kSigmaScaleFit * c.alpha * std::sqrt(c.mu));
    std::printf("alpha %.3f cos %.3f: best scale %.3f (lobe L1 %.3f), at %.2f %.3f, at 1.1 %.3f\n", c.alpha, c.mu,
                c.bestScale, c.bestL1, kSigmaScaleFit, atFit, lobeL1(c.lobe, 1.1 * c.alpha * std::sqrt(c.mu)));
    worstExcess = std::max(worstExcess, atFit - c.bestL1);
    lo = std::min(lo, c.bestScale);
    hi = std::max(hi, c.bestScale);
  }
  std::printf("fitted scale %.4f (kSigmaScaleFit %.2f): mean lobe L1 %.4f (at 1.1: %.4f); worst excess over the "
              "best sigma per case %.4f; best scales %.3f..%.3f\n",
              fit, kSigmaScaleFit, meanL1(fit), meanL1(1.1), worstExcess, lo, hi);
  EXPECT_NEAR(fit, kSigmaScaleFit, 0.02) << "the documented constant is the fit";
  // The pass reads the schema's default (Params has no fallback): it is the fit too.
  EXPECT_FLOAT_EQ(api::techniqueParams("light_volumes").at("sigma_scale").get<float>(), kSigmaScaleFit);
  // sqrt(cos theta_i) carries the incidence dependence: one constant is within 0.03 of L1 of the best
  // Gaussian for every roughness and angle (measured 0.019, at roughness 0.5 and 60 degrees).
  EXPECT_LT(worstExcess, 0.03);
  EXPECT_GT(lo, 1.35);
  EXPECT_LT(hi, 1.7);
  // The half-maximum fit of the notes (1.1) fits GGX's peak and misses its tails: ~0.25 more L1.
  EXPECT_LT(meanL1(kSigmaScaleFit), meanL1(1.1) - 0.2);
}

TEST(LightVolumesCalibration, BeamAlbedoIsTheReferenceLobesDirectionalAlbedo) {
  for (float r : {0.1f, 0.3f, 0.5f})
    for (float t : {0.f, 30.f, 60.f}) {
      const float alpha = r * r, mu = std::cos(t * float(M_PI) / 180.f);
      // Independent quadrature of D V cos over the whole hemisphere (phi up to pi about the mirror).
      const Lobe l = referenceLobe(alpha, mu, float(M_PI), 2000, 96);
      const glm::vec2 ab = ggxReflectionAlbedo(mu, alpha);
      EXPECT_NEAR(ab.x, l.albedo, 0.004 * l.albedo) << "roughness " << r << " theta " << t;
      EXPECT_LE(ab.y, ab.x);
    }
  // The Dirac limit is Schlick at the mirror direction.
  EXPECT_NEAR(ggxReflectionAlbedo(0.5f, 1e-7f).x, 1.f, 2e-3f);
  EXPECT_NEAR(ggxReflectionAlbedo(0.5f, 1e-7f).y, rt::schlickWeight(0.5f), 2e-3f);
  EXPECT_EQ(ggxReflectionAlbedo(0.5f, 0.f).y, rt::schlickWeight(0.5f));
}

// A glossy metal plate (baseColor 0.9, 24 x 24 x 2 triangles: edge 0.025 m over ~1.3 m to the floor,
// at most a third of sigma for roughness >= 0.2) 1.2 m over a Lambertian floor (albedo 0.5), lit from
// below by a spot whose inner cone covers the plate. The orthographic camera sees 5 x 5 m of the
// floor: the whole footprint and the lobe's tails out to ~1 rad. The light tracer renders the paths
// with exactly two scattering events (L G D E: the floor cannot see itself, the plate is above the
// camera); the beams' image is L = albedo / pi E at the pixel centres. Prints and returns
// (energy ratio, relative L1, the light tracer's noise floor).
glm::dvec3 plateAgainstLightTracer(float roughness) {
  testing::SceneBuilder b;
  const int floor = b.material(testing::lambertian(glm::vec3(0.5f)));
  b.quad(glm::vec3(0.f), {3.f, 0, 0}, {0, 0, -3.f}, floor, "floor");
  Material metal = testing::lambertian(glm::vec3(0.9f));
  metal.metallicFactor = 1.f;
  metal.roughnessFactor = roughness;
  const glm::vec3 light(-0.3f, 0.4f, 0.f), plateCentre(0.f, 1.2f, 0.f);
  b.gridY(plateCentre, 0.3f, 24, false, b.material(metal), "plate");
  b.spotLight(light, plateCentre - light, 3.f, 0.7f, 0.8f);
  const float half = 2.5f;
  b.topDownOrtho(1.f, half);
  const Scene scene = b.build("test:light_volumes:plate_energy:" + std::to_string(roughness));

  const BeamSet beams = buildBeams(scene, BeamOptions{});
  EXPECT_EQ(beams.glossy, 24u * 24u * 2u);
  const int size = 64;
  std::vector<double> lv(size * size);
  double lvSum = 0.0;
  for (int py = 0; py < size; ++py)
    for (int px = 0; px < size; ++px) {
      const glm::vec2 xz = testing::topDownPixelToWorld(px, py, size, half);
      const glm::vec3 E = gatherIrradiance(beams.beams, {xz.x, 0.f, xz.y}, {0.f, 1.f, 0.f}, Split::TwoD);
      lv[py * size + px] = 0.5 / M_PI * E.x;
      lvSum += lv[py * size + px];
    }

  rt::RayScene rays(scene);
  reference::LightTracer tracer(rays);
  reference::LightTracerOptions o;
  o.paths = reference::LightTracerOptions::Paths::All;
  o.minPathBounce = o.maxPathBounce = 2;
  o.pathsPerPixel = 256;
  std::vector<Image> ref;
  for (std::uint64_t seed : {1u, 2u}) {
    o.seed = seed;
    ref.push_back(tracer.render(scene.camera, size, size, o));
  }
  double refSum[2] = {0.0, 0.0}, l1 = 0.0, noise = 0.0;
  for (int i = 0; i < size * size; ++i) {
    const double a = ref[0].pixels[i * ref[0].channels], c = ref[1].pixels[i * ref[1].channels];
    refSum[0] += a;
    refSum[1] += c;
    l1 += std::abs(lv[i] - 0.5 * (a + c));
    noise += std::abs(a - c);
  }
  const double refMean = 0.5 * (refSum[0] + refSum[1]);
  EXPECT_NEAR(refSum[0] / refSum[1], 1.0, 0.01) << "the light tracer's energy is converged to 1%";
  // The two seeds' difference has sqrt(2) the noise of one image and 2 sqrt(2) that of their mean.
  const glm::dvec3 r(lvSum / refMean, l1 / refMean, noise / refMean / 2.0);
  std::printf("glossy plate (roughness %.1f) against the light tracer: energy %.4f, relative L1 %.4f, the "
              "reference's own noise (relative L1 of the mean of two seeds) %.4f\n",
              roughness, r.x, r.y, r.z);
  return r;
}

TEST(LightVolumesCalibration, GlossyPlateCarriesTheLightTracersEnergyWithin3Percent) {
  // Measured 1.013 (roughness 0.2) and 0.995 (0.3). Before the flux carried the Smith loss and the
  // plane gain 1 + 8/3 sigma^2 was divided out, the roughness 0.3 plate was 5.2% bright (8% with
  // sigma_scale 1.1 on the old bench framing).
  for (float roughness : {0.2f, 0.3f}) {
    const glm::dvec3 r = plateAgainstLightTracer(roughness);
    EXPECT_NEAR(r.x, 1.0, 0.03) << "roughness " << roughness;
    // Measured 0.088 and 0.10 against a noise floor of 0.033: the rest is GGX's shape, which no
    // Gaussian has (lobe L1 ~0.35 in the angular domain, blurred here by the 0.7 m footprint).
    EXPECT_LT(r.y, 0.13) << "roughness " << roughness;
  }
}

}  // namespace
}  // namespace radiant::light_volumes
