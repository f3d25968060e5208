// The photon tracer and the emitters of the ray-tracing core against numbers that energy conservation
// fixes: emitted power per light type, the integrating sphere bounce by bounce, refinement (m + m'
// photons equal a fresh run), determinism across thread counts, albedo 1, and scale invariance.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>

#include "renderer/raytracing/PhotonTracer.h"
#include "tests/support/Directions.h"
#include "tests/unit/reference/TestScenes.h"

namespace radiant::rt {
namespace {

using testing::addMaterial;
using testing::lambert;

using testing::bsdfOf;

// Sum of the flux of the records with a given bounce count, per emitted photon.
glm::dvec3 fluxOfBounce(const PhotonSet& set, std::uint32_t bounce) {
  glm::dvec3 s(0.0);
  for (const PhotonRecord& r : set.records)
    if (r.bounce == bounce) s += glm::dvec3(r.flux);
  return s / double(set.emitted);
}

Scene integratingSphere(float radius, float albedo, float intensity) {
  Scene s;
  const int mat = addMaterial(s, lambert(glm::vec3(albedo)));
  s.meshes.push_back(testing::sphere(glm::vec3(0.f), radius, 48, 96, mat));
  Light l;
  l.type = LightType::Point;
  l.intensity = intensity;
  l.position = glm::vec3(0.f);
  s.lights.push_back(l);
  s.features = computeFeatures(s);
  return s;
}

TEST(Lights, EmittedPowerMatchesEachLightsClosedForm) {
  // Each scene has one emitter, so the mean flux of its emissions is its power (sampleLe's flux is
  // Le cos / (pdf_pos pdf_dir p_select)). The closed forms: point 4 pi I, spot
  // 2 pi I (1 - cos_i + (cos_i - cos_o) / 3), emissive triangle pi A L, directional E pi r^2.
  Scene s;
  const int mat = addMaterial(s, lambert(glm::vec3(0.5f)));
  s.meshes.push_back(testing::square(glm::vec3(0.f), glm::vec3(0, 1, 0), 1.f, mat));  // bounds for the disk
  struct Case { LightType type; float inner, outer; };
  for (Case c : {Case{LightType::Point, 0.f, 0.f}, Case{LightType::Spot, 0.3f, 0.9f},
                 Case{LightType::Spot, 0.f, 1.5f}, Case{LightType::Directional, 0.f, 0.f}}) {
    Scene t = s;
    Light l;
    l.type = c.type;
    l.intensity = 3.f;
    l.color = glm::vec3(1.f, 0.5f, 0.25f);
    l.innerConeAngle = c.inner;
    l.outerConeAngle = c.outer;
    l.position = glm::vec3(0, 2, 0);
    l.direction = glm::vec3(0, -1, 0);
    t.lights.push_back(l);
    t.features = computeFeatures(t);
    const RayScene rays(t);
    const SceneLights lights(rays, nullptr, glm::vec3(0.f));
    double expected;
    const double I = 3.0;
    if (c.type == LightType::Point) expected = 4 * M_PI * I;
    else if (c.type == LightType::Spot)
      expected = 2 * M_PI * I * ((1 - std::cos(c.inner)) + (std::cos(c.inner) - std::cos(c.outer)) / 3);
    else expected = I * M_PI * std::pow(0.5 * std::sqrt(8.0), 2);  // bounds of a 2 x 0 x 2 square: r = sqrt(2)
    ASSERT_NEAR(lights.emitters().at(0).power.r, expected, 1e-4 * expected);
    glm::dvec3 mean(0.0);
    const int n = 200000;
    for (int i = 0; i < n; ++i) {
      Sampler sampler(i, 0, 7);
      Emission e;
      ASSERT_TRUE(lights.sampleLe(sampler, e) || c.type == LightType::Spot);
      mean += glm::dvec3(e.flux) / double(n);
    }
    EXPECT_NEAR(mean.r, expected, 0.01 * expected) << "light type " << int(c.type);
    EXPECT_NEAR(mean.g / mean.r, 0.5, 1e-5);
  }
  // Emissive triangle (single-sided square, two triangles): pi A L.
  Scene e;
  Material em = testing::emitter(glm::vec3(2.f, 1.f, 1.f));
  const int emat = addMaterial(e, em);
  e.meshes.push_back(testing::square(glm::vec3(0.f), glm::vec3(0, -1, 0), 0.5f, emat));
  e.features = computeFeatures(e);
  const RayScene rays(e);
  const SceneLights lights(rays, nullptr, glm::vec3(0.f));
  glm::dvec3 mean(0.0);
  const int n = 100000;
  for (int i = 0; i < n; ++i) {
    Sampler sampler(i, 0, 3);
    Emission em1;
    ASSERT_TRUE(lights.sampleLe(sampler, em1));
    ASSERT_LT(em1.ray.dir.y, 0.f);  // leaves the front face only
    mean += glm::dvec3(em1.flux) / double(n);
  }
  EXPECT_NEAR(mean.r, M_PI * 1.0 * 2.0, 1e-3 * M_PI * 2.0);  // uniform emitter: every sample is exact
}

TEST(PhotonTracer, IntegratingSphereBounceByBounce) {
  // A point light of power Phi at the centre of a closed sphere: every photon lands, so bounce 0
  // carries exactly Phi, and every reflected photon lands again, so bounce k + 1 carries bounce k
  // times the albedo at the incidence it arrives with. Inside a sphere a diffusely reflected photon
  // arrives at the same angle it left with, cosine-distributed, so E_(k+1) / E_k is the cosine-weighted
  // mean a_bar of the directional albedo a(mu) for k >= 1, and E_1 / E_0 = a(1) (normal incidence).
  // For a Lambertian of albedo rho these are rho and the Phi rho^k / (4 pi R^2) per unit area;
  // glTF's dielectric is not Lambertian, so a(mu) comes from quadrature (independent of the sampler).
  const float rho = 0.5f, I = 2.f;
  const double Phi = 4 * M_PI * I;
  const GltfBsdf b = bsdfOf(lambert(glm::vec3(rho)));
  const double a1 = testing::directionalAlbedo(b, 1.f).x;
  double aBar = 0.0;
  const int nMu = 64;
  for (int i = 0; i < nMu; ++i) {
    const double mu = (i + 0.5) / nMu;
    aBar += 2 * mu * testing::directionalAlbedo(b, float(mu), 200, 240).x / nMu;
  }
  for (float radius : {1.f, 1e-3f, 1e4f}) {
    const Scene s = integratingSphere(radius, rho, I);
    const RayScene rays(s);
    const SceneLights lights(rays, nullptr, glm::vec3(0.f));
    PhotonOptions o;
    o.maxBounces = 40;
    PhotonSet set;
    tracePhotons(rays, lights, o, 200000, set);
    EXPECT_NEAR(fluxOfBounce(set, 0).x, Phi, 1e-5 * Phi) << "R = " << radius;
    double expected = Phi * a1;
    for (std::uint32_t k = 1; k <= 4; ++k) {
      // Russian roulette keeps the mean; 2% covers its noise at 2e5 photons (about 0.5% at k = 4).
      EXPECT_NEAR(fluxOfBounce(set, k).x, expected, 0.02 * expected) << "R = " << radius << ", bounce " << k;
      expected *= aBar;
    }
    glm::dvec3 indirect(0.0);
    for (std::uint32_t k = 1; k < 40; ++k) indirect += fluxOfBounce(set, k);
    const double closed = Phi * a1 / (1 - aBar);  // Phi rho / (1 - rho) for a Lambertian
    EXPECT_NEAR(indirect.x, closed, 0.02 * closed) << "R = " << radius;
    for (const PhotonRecord& r : set.records) {
      ASSERT_TRUE(std::isfinite(r.flux.x) && std::isfinite(r.position.x));
      ASSERT_NEAR(glm::length(r.position), radius, 0.01f * radius);
    }
  }
}

TEST(PhotonTracer, RefinementEqualsAFreshRunAndIsThreadIndependent) {
  const Scene s = integratingSphere(1.f, 0.7f, 1.f);
  const RayScene rays(s);
  const SceneLights lights(rays, nullptr, glm::vec3(0.f));
  PhotonOptions o;
  o.seed = 11;
  PhotonSet grown;
  o.threads = 1;
  tracePhotons(rays, lights, o, 30000, grown);
  const std::size_t firstRecords = grown.records.size();
  const glm::dvec3 e1First = fluxOfBounce(grown, 1);
  o.threads = 2;
  tracePhotons(rays, lights, o, 60000, grown);  // m = 30000, m' = 30000
  PhotonSet fresh;
  tracePhotons(rays, lights, o, 60000, fresh);
  ASSERT_EQ(grown.records.size(), fresh.records.size());
  EXPECT_EQ(0, std::memcmp(grown.records.data(), fresh.records.data(), fresh.records.size() * sizeof(PhotonRecord)));
  EXPECT_EQ(grown.recordsOfFirst(30000), firstRecords);
  // Eq. 1 rescales: the merged estimate uses 1 / (m + m'). Without rescaling (1 / m) it doubles.
  const glm::dvec3 e1 = fluxOfBounce(grown, 1);
  EXPECT_NEAR(e1.x, e1First.x, 0.02 * e1First.x);
  EXPECT_NEAR(e1.x * 60000.0 / 30000.0 / e1First.x, 2.0, 0.04);
}

TEST(PhotonTracer, AlbedoOneTerminatesAndConservesEnergy) {
  // Albedo 1 (f0 = 0 dielectric: a(mu) just below 1): Russian roulette survival is capped at 0.95, so
  // paths end after about 20 bounces on average, and each bounce still carries about Phi.
  const Scene s = integratingSphere(1.f, 1.f, 1.f);
  const RayScene rays(s);
  const SceneLights lights(rays, nullptr, glm::vec3(0.f));
  PhotonOptions o;
  o.maxBounces = 1000;
  PhotonSet set;
  tracePhotons(rays, lights, o, 20000, set);
  const double recordsPerPhoton = double(set.records.size()) / set.emitted;
  EXPECT_GT(recordsPerPhoton, 10.0);
  EXPECT_LT(recordsPerPhoton, 25.0);  // 1 / (1 - 0.95) = 20 hits expected
  const double Phi = 4 * M_PI;
  const GltfBsdf b = bsdfOf(lambert(glm::vec3(1.f)));
  const double a1 = testing::directionalAlbedo(b, 1.f).x;
  EXPECT_NEAR(fluxOfBounce(set, 1).x, Phi * a1, 0.03 * Phi);
  for (const PhotonRecord& r : set.records) ASSERT_TRUE(std::isfinite(r.flux.x + r.flux.y + r.flux.z));
}

// KHR_materials_volume: sunlight through a glass slab (thickness d) onto a Lambertian receiver below.
// The photon tracer ends paths at Dirac lobes (light tracing owns L S+ D), so the glass is rough at the
// smallest GGX alpha (roughness 0.03: alpha = kMinGgxAlpha = 1e-3). The photons that land after crossing
// the slab once (bounce 2: entry and exit) carry their flux times a = c^(d / (d0 cos theta_t)) per
// channel (Beer-Lambert). With roulette off and the same seed the clear and the absorbing slab trace the
// same paths, so the ratio of their landed flux is a; the microfacets tilt each crossing by ~alpha,
// which changes its length by ~tan(theta_t) alpha, to first order symmetrically: bound 1e-3 relative
// (measured 9e-5).
TEST(PhotonTracer, AbsorbingSlabScalesTheTransmittedFluxByBeerLambert) {
  const float d = 0.2f, d0 = 0.1f;
  const glm::vec3 c(0.5f, 0.8f, 0.f);
  for (float thetaDeg : {0.f, 40.f}) {
    const float theta = thetaDeg * float(M_PI) / 180.f;
    Scene s;
    Material rough = testing::absorbingGlass(1.5f, c, d0);
    rough.roughnessFactor = 0.03f;
    const int glass = addMaterial(s, rough);
    // The slab overhangs the receiver, so every photon on it crossed the top and the bottom face (a
    // photon entering a side face meets the bottom beyond the critical angle, one leaving a side face
    // moves away from the receiver).
    s.meshes.push_back(testing::box({-1.5f, 0, -1.5f}, {1.5f, d, 1.5f}, glass));
    s.meshes.push_back(testing::square({0, -0.5f, 0}, {0, 1, 0}, 1.f, addMaterial(s, lambert(glm::vec3(0.5f)))));
    Light sun;
    sun.type = LightType::Directional;
    sun.intensity = 3.f;
    sun.direction = glm::vec3(std::sin(theta), -std::cos(theta), 0.f);
    s.lights.push_back(sun);
    s.features = computeFeatures(s);
    Scene clear = s;
    clear.materials[glass].thicknessFactor = 0.f;
    PhotonOptions o;
    o.maxBounces = 3;
    o.russianRoulette = false;
    auto landed = [&](const Scene& scene) {
      const RayScene rays(scene);
      const SceneLights lights(rays, nullptr, glm::vec3(0.f));
      PhotonSet set;
      tracePhotons(rays, lights, o, 200000, set);
      glm::dvec3 sum(0.0);
      std::size_t n = 0;
      for (const PhotonRecord& r : set.records) {
        EXPECT_TRUE(std::isfinite(r.flux.x) && std::isfinite(r.flux.y) && std::isfinite(r.flux.z));
        if (r.mesh == 1 && r.bounce == 2) sum += glm::dvec3(r.flux), ++n;
      }
      EXPECT_GT(n, 1000u);
      return sum;
    };
    const glm::dvec3 vol = landed(s), ref = landed(clear);
    const double cosT = std::sqrt(1 - std::pow(std::sin(theta) / 1.5, 2));
    for (int k = 0; k < 2; ++k) {
      const double a = std::pow(double(c[k]), d / (d0 * cosT));
      std::printf("%g deg, channel %d: flux ratio %.6f, c^(d / (d0 cos theta_t)) %.6f\n", thetaDeg, k, vol[k] / ref[k], a);
      EXPECT_NEAR(vol[k] / ref[k], a, 1e-3 * a) << thetaDeg << " deg, channel " << k;
    }
    EXPECT_EQ(vol[2], 0.0);  // colour 0: opaque, not NaN
    EXPECT_GT(ref[2], 0.0);
  }
}

TEST(PhotonTracer, UnlitSurfacesAbsorbEveryPhoton) {
  // KHR_materials_unlit: nothing lights the surface and it reflects nothing (the reference ends paths
  // there): no records, no bounces.
  Scene s = integratingSphere(1.f, 0.9f, 1.f);
  s.materials[0].unlit = true;
  const RayScene rays(s);
  const SceneLights lights(rays, nullptr, glm::vec3(0.f));
  PhotonSet set;
  tracePhotons(rays, lights, PhotonOptions{}, 5000, set);
  EXPECT_EQ(set.records.size(), 0u);
  EXPECT_EQ(set.emitted, 5000u);
}

TEST(PhotonTracer, DegenerateGeometryAndLightsInsideGeometryStayFinite) {
  Scene s;
  const int mat = addMaterial(s, lambert(glm::vec3(0.8f)));
  const int em = addMaterial(s, testing::emitter(glm::vec3(5.f), true));
  s.meshes.push_back(testing::box(glm::vec3(-1.f), glm::vec3(1.f), mat));
  MeshInstance degenerate;  // a zero-area emissive triangle and a zero-area receiving triangle
  degenerate.material = em;
  degenerate.positions = {glm::vec3(0.f), glm::vec3(0.f), glm::vec3(0.f), glm::vec3(0.1f), glm::vec3(0.2f), glm::vec3(0.3f)};
  degenerate.indices = {0, 1, 2, 3, 4, 5};
  testing::finishMesh(degenerate);
  s.meshes.push_back(degenerate);
  Light l;  // a point light inside the (closed) box and one inside a wall's plane
  l.position = glm::vec3(0.2f, 0.1f, -0.3f);
  s.lights.push_back(l);
  l.position = glm::vec3(1.f, 0.f, 0.f);
  s.lights.push_back(l);
  s.features = computeFeatures(s);
  const RayScene rays(s);
  const SceneLights lights(rays, nullptr, glm::vec3(0.f));
  PhotonSet set;
  tracePhotons(rays, lights, PhotonOptions{}, 20000, set);
  EXPECT_GT(set.records.size(), 20000u);
  for (const PhotonRecord& r : set.records) {
    ASSERT_TRUE(std::isfinite(r.flux.x + r.flux.y + r.flux.z + r.position.x + r.normal().x + r.wi().x));
    ASSERT_NEAR(glm::length(r.wi()), 1.f, 1e-4f);
  }
}

// Light that was scattered diffusely before it meets glass (L D S+ D, e.g. a lit ceiling seen through a
// glass sphere by the floor) is photon_gi's: only paths that *start* with Dirac scatterings (L S+ D)
// are the caustics pass's. A spot pointing up lights a Lambertian ceiling; an index-1 glass slab
// (Fresnel 0: invisible) hangs under it, over the floor, where the spot never reaches it. The
// ceiling's light that lands on the floor under the slab must not depend on the slab: it crosses two
// delta interfaces of weight 1. (When a delta bounce ended every photon, the slab cast a full
// shadow: the ratio below was 0.012.) Same seed, 4e5 photons; the paths differ after the slab (two more
// roulette draws), so the bound is statistical: 3%, about 4 standard errors of the landed flux.
TEST(PhotonTracer, LightScatteredDiffuselyBeforeGlassCrossesIt) {
  auto build = [](bool slab) {
    Scene s;
    const int white = addMaterial(s, lambert(glm::vec3(0.8f)));
    s.meshes.push_back(testing::square(glm::vec3(0, 0, 0), glm::vec3(0, 1, 0), 2.f, white));    // floor
    s.meshes.push_back(testing::square(glm::vec3(0, 2, 0), glm::vec3(0, -1, 0), 2.f, white));   // ceiling
    if (slab) s.meshes.push_back(testing::box(glm::vec3(-0.5f, 0.4f, -0.5f), glm::vec3(0.5f, 0.6f, 0.5f),
                                              addMaterial(s, testing::smoothGlass(1.f))));
    Light l;
    l.type = LightType::Spot;
    l.intensity = 5.f;
    l.innerConeAngle = 0.f;
    l.outerConeAngle = 1.f;
    l.position = glm::vec3(0, 1.5f, 0);
    l.direction = glm::vec3(0, 1, 0);
    s.lights.push_back(l);
    s.features = computeFeatures(s);
    return s;
  };
  auto underSlab = [&](bool slab, std::size_t& records) {
    const Scene s = build(slab);
    const RayScene rays(s);
    const SceneLights lights(rays, nullptr, glm::vec3(0.f));
    PhotonOptions o;
    o.maxBounces = 16;
    o.seed = 3;
    PhotonSet set;
    tracePhotons(rays, lights, o, 400000, set);
    double flux = 0.0;
    records = 0;
    for (const PhotonRecord& r : set.records) {
      EXPECT_TRUE(std::isfinite(r.flux.x));
      if (r.mesh != 0 || std::abs(r.position.x) > 0.5f || std::abs(r.position.z) > 0.5f) continue;
      EXPECT_GE(r.bounce, 1);  // the spot never reaches the floor directly
      EXPECT_EQ(r.flags & kPhotonSpecularChain, 0) << "a ceiling bounce came first: not L S+ D";
      flux += r.flux.x;
      ++records;
    }
    return flux / double(set.emitted);
  };
  std::size_t without = 0, with = 0;
  const double open = underSlab(false, without), covered = underSlab(true, with);
  ASSERT_GT(without, 5000u);
  std::printf("flux under the slab: without %.5f (%zu records), with an ior-1 slab %.5f (%zu): ratio %.4f\n", open,
              without, covered, with, covered / open);
  EXPECT_NEAR(covered / open, 1.0, 0.03);
}

}  // namespace
}  // namespace radiant::rt

namespace radiant::rt {
namespace {

// The records' octahedral normals and directions (PhotonRecord): every direction of a dense spherical
// Fibonacci set, the axes, the octants' diagonals and the fold's edges (z = 0, x or y = 0 below it)
// decode to a unit vector within 1e-4 radians of what was encoded (6.4e-5 measured); zero and non-finite input decode to
// a unit vector (+z), never NaN.
TEST(PhotonTracer, OctahedralRecordVectorsAreWithinTheirStatedAngle) {
  std::vector<glm::vec3> dirs = testing::testDirections(200000);
  for (float t = -1.f; t <= 1.f; t += 1.f / 64.f) {
    dirs.push_back(glm::normalize(glm::vec3(t, 1.f - std::abs(t), 0.f)));
    dirs.push_back(glm::normalize(glm::vec3(t, 0.f, -1.f)));
    dirs.push_back(glm::normalize(glm::vec3(0.f, t, -1.f)));
    dirs.push_back(glm::normalize(glm::vec3(-0.f, t, -1e-7f)));
  }
  double worst = 0.0;
  for (const glm::vec3& v : dirs) {
    const glm::vec3 d = octDecode(octEncode(v));
    ASSERT_NEAR(glm::length(d), 1.f, 1e-6f);
    const double angle = std::atan2(double(glm::length(glm::cross(v, d))), double(glm::dot(v, d)));
    worst = std::max(worst, angle);
  }
  std::printf("largest octahedral error: %.3g rad over %zu directions\n", worst, dirs.size());
  EXPECT_LT(worst, 1e-4);
  for (const glm::vec3& bad : {glm::vec3(0.f), glm::vec3(NAN, 0.f, 1.f), glm::vec3(INFINITY, 0.f, 0.f)}) {
    const glm::vec3 d = octDecode(octEncode(bad));
    EXPECT_TRUE(std::isfinite(d.x) && std::isfinite(d.y) && std::isfinite(d.z));
    EXPECT_NEAR(glm::length(d), 1.f, 1e-6f);
  }
}

}  // namespace
}  // namespace radiant::rt
