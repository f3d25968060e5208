// The volumetric reference against closed forms: the transmittance through a constant sphere along a
// chord is e^(-2 tau sqrt(r^2 - d^2)) (linear falloff: its chord closed form); a lone fire particle
// emits L_e (1 - T) exactly (emission-absorption); a medium of albedo 1 under a uniform sky L returns
// the furnace radiance (media + L * T = L) in the single-scatter-unshadowed model exactly, and in the
// full model (delta tracking, all orders) within its Bernoulli noise.
#include <cmath>

#include <gtest/gtest.h>

#include "renderer/raytracing/Media.h"
#include "renderer/raytracing/ParticleMedium.h"
#include "renderer/raytracing/RayScene.h"
#include "renderer/reference/VolumeTracer.h"
#include "tests/support/SceneBuilder.h"

namespace radiant::reference {
namespace {

api::ParticleSystem sphere(api::MediumKind kind, float r, float tau, glm::vec3 albedo,
                           api::DensityProfile profile = api::DensityProfile::Constant, float kelvin = 0.f) {
  api::ParticleSystem s;
  s.kind = kind;
  s.profile = profile;
  api::Particle p;
  p.radius = r, p.tau = tau, p.albedo = albedo, p.temperature = kelvin;
  s.particles.push_back(p);
  return s;
}

// Pixel centre (x, y) of an n x n image over [-half, half]^2 -> world (x, y).
glm::vec2 pixelToWorld(int x, int y, int n, float half) {
  return {(-1.f + 2.f * (x + 0.5f) / n) * half, (1.f - 2.f * (y + 0.5f) / n) * half};
}

struct Fixture {
  Scene scene;
  rt::RayScene rays{scene};
};

TEST(VolumeTracer, TransmittanceAlongAChordIsExact) {
  const float r = 1.f, tau = 1.5f, half = 1.2f;
  const int n = 32;
  for (auto profile : {api::DensityProfile::Constant, api::DensityProfile::LinearExact}) {
    Fixture f;
    const rt::ParticleMedium medium({sphere(api::MediumKind::Smoke, r, tau, glm::vec3(0.f), profile)});
    VolumeOptions o;
    o.spp = 1;  // the pixel centre
    o.mode = MediaMode::EmissionAbsorption;
    const Image img = VolumeTracer(f.rays, medium).render(testing::orthoCameraAlongZ(half), n, n, o);
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const glm::vec2 p = pixelToWorld(x, y, n, half);
        const double d = glm::length(p);
        const double depth = profile == api::DensityProfile::Constant
                                 ? (d < r ? 2.0 * tau * std::sqrt(r * r - d * d) : 0.0)
                                 : rt::linearChordOpticalDepth(tau, r, d);
        EXPECT_NEAR(img.at(x, y)[3], std::exp(-depth), 2e-6) << x << "," << y;
        EXPECT_EQ(img.at(x, y)[0], 0.f);  // albedo 0, no emission: no light
      }
  }
}

TEST(VolumeTracer, FireEmitsItsBlackBodyTimesOpacity) {
  Fixture f;
  auto fire = sphere(api::MediumKind::Fire, 1.f, 0.8f, glm::vec3(0.f), api::DensityProfile::LinearExact, 2800.f);
  fire.emissionScale = 3.f;
  const rt::ParticleMedium medium({fire});
  const glm::vec3 Le = 3.f * rt::blackbodyRgb(2800.0);
  VolumeOptions o;
  o.spp = 1;
  o.mode = MediaMode::EmissionAbsorption;
  const Image img = VolumeTracer(f.rays, medium).render(testing::orthoCameraAlongZ(1.2f), 24, 24, o);
  for (int y = 0; y < 24; ++y)
    for (int x = 0; x < 24; ++x)
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(img.at(x, y)[c], Le[c] * (1.f - img.at(x, y)[3]), 1e-5f * (1.f + Le[c]));
}

TEST(VolumeTracer, AlbedoOneInAWhiteFurnaceReturnsTheFurnaceRadiance) {
  Fixture f;
  const glm::vec3 sky(0.7f, 1.f, 1.3f);
  // Two overlapping spheres, one constant, one linear, albedo 1, forward scattering.
  auto a = sphere(api::MediumKind::Cloud, 1.f, 2.f, glm::vec3(1.f));
  auto b = sphere(api::MediumKind::Cloud, 0.6f, 4.f, glm::vec3(1.f), api::DensityProfile::LinearExact);
  b.particles[0].position = {0.4f, 0.3f, 0.f};
  b.phase = api::PhaseModel::HenyeyGreenstein;
  b.g = 0.6f;
  const rt::ParticleMedium medium({a, b});
  VolumeOptions o;
  o.sky = sky;
  o.spp = 1;
  o.mode = MediaMode::SingleScatterUnshadowed;  // source = albedo * sky: exact
  const int n = 16;
  Image img = VolumeTracer(f.rays, medium).render(testing::orthoCameraAlongZ(1.2f), n, n, o);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x)
      for (int c = 0; c < 3; ++c)  // up to float rounding of the piecewise depths
        EXPECT_NEAR(img.at(x, y)[c] + sky[c] * img.at(x, y)[3], sky[c], 1e-4f * sky[c]);

  // Full: every path that collides ends in the sky with throughput 1 (albedo 1, HG sampled exactly),
  // so a pixel's media radiance is sky times the fraction of its samples that collided: mean 1 - T.
  o.mode = MediaMode::Full;
  o.spp = 64;
  img = VolumeTracer(f.rays, medium).render(testing::orthoCameraAlongZ(1.2f), n, n, o);
  double sum = 0, expected = 0, variance = 0;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const double T = img.at(x, y)[3];
      sum += img.at(x, y)[1] / sky[1];
      expected += 1 - T;
      variance += T * (1 - T) / o.spp;
      // Each sample adds sky exactly or nothing: the ratio between channels is the sky's.
      EXPECT_NEAR(img.at(x, y)[0] * sky[1], img.at(x, y)[1] * sky[0], 1e-5);
    }
  EXPECT_NEAR(sum, expected, 4 * std::sqrt(variance) + 1e-6);
}

TEST(VolumeTracer, ANonAbsorbingMediumInAClosedBoxConservesItsRadiance) {
  // A closed box whose walls show radiance Lw (KHR_materials_unlit: exactly Lw from both sides, no
  // scattering) around a medium of albedo 1: the radiance is Lw everywhere, so every pixel's media
  // light + Lw T is Lw. In the full model every path that collides leaves through the medium to a wall
  // with throughput 1: a pixel's media light is Lw times the fraction of its samples that collided.
  testing::SceneBuilder b;
  Material wall;
  wall.unlit = true;
  wall.doubleSided = true;
  wall.baseColorFactor = glm::vec4(0.25f, 0.5f, 1.f, 1.f);  // (base colours are clamped to [0, 1])
  const glm::vec3 Lw(0.25f, 0.5f, 1.f);
  b.box(glm::vec3(-1.f), glm::vec3(1.f), b.material(wall));
  Scene scene = b.build();
  const rt::RayScene rays(scene);
  auto a = sphere(api::MediumKind::Cloud, 0.5f, 3.f, glm::vec3(1.f));
  auto c = sphere(api::MediumKind::Cloud, 0.4f, 5.f, glm::vec3(1.f), api::DensityProfile::LinearExact);
  c.particles[0].position = {0.3f, -0.2f, 0.1f};
  c.phase = api::PhaseModel::HenyeyGreenstein;
  c.g = -0.4f;
  const rt::ParticleMedium medium({a, c});
  Camera cam;
  cam.yfov = 1.2f;
  cam.znear = 0.01f;
  cam.world = glm::mat4(1.f);
  cam.world[3] = glm::vec4(0, 0, 0.9f, 1);
  VolumeOptions o;
  o.mode = MediaMode::Full;
  o.spp = 32;
  o.maxScattering = 1000;
  const int n = 16;
  const Image img = VolumeTracer(rays, medium).render(cam, n, n, o);
  double sum = 0, expected = 0, variance = 0;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const double T = img.at(x, y)[3];
      sum += img.at(x, y)[1] / Lw[1];
      expected += 1 - T;
      variance += T * (1 - T) / o.spp;
      EXPECT_NEAR(img.at(x, y)[2], 2.f * img.at(x, y)[1], 1e-5);  // the walls' colour, exactly
    }
  ASSERT_GT(expected, 10.0);  // the medium covers a good part of the view
  EXPECT_NEAR(sum, expected, 4 * std::sqrt(variance) + 1e-6);
}

}  // namespace
}  // namespace radiant::reference
