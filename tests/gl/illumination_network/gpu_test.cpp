// The illumination network on llvmpipe (NetworkGpu) against its CPU double-precision twin
// (Network.h): the visibility network built by GPU binning equals the CPU build (binning in float
// alike: a node on a bin edge may fall the other way after FMA contraction, so a tiny fraction of
// links may differ), and the fp32 iteration on the GPU's own V matches the double iteration within
// fp16 tolerance (2^-10 of the largest radiance), deterministically, with the same residuals.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include <gtest/gtest.h>

#include "renderer/gl/Gl.h"
#include "renderer/gl/ShaderLibrary.h"
#include "renderer/platform/EglDevice.h"
#include "renderer/raytracing/ParticleMedium.h"
#include "renderer/techniques/illumination_network/NetworkGpu.h"

namespace radiant::network {
namespace {

class NetworkGpuTest : public ::testing::Test {
protected:
  static void SetUpTestSuite() { device_ = EglDevice::create(); }
  static void TearDownTestSuite() { device_.reset(); }
  void SetUp() override { device_->makeCurrent(); }
  static std::unique_ptr<EglDevice> device_;
  gl::ShaderLibrary library_;
};
std::unique_ptr<EglDevice> NetworkGpuTest::device_;

std::vector<api::ParticleSystem> lumpyCloud() {
  // Three overlapping constant spheres of different extinction and albedo: nodes of varying tau.
  api::ParticleSystem s;
  s.kind = api::MediumKind::Cloud;
  s.phase = api::PhaseModel::HenyeyGreenstein;
  s.g = 0.4f;
  const glm::vec3 c[3] = {{0, 0, 0}, {0.6f, 0.2f, 0}, {-0.3f, -0.5f, 0.3f}};
  const float r[3] = {1.f, 0.6f, 0.5f}, tau[3] = {6.f, 4.f, 9.f};
  const glm::vec3 a[3] = {glm::vec3(0.9f), glm::vec3(0.8f, 0.85f, 0.95f), glm::vec3(0.95f)};
  for (int k = 0; k < 3; ++k) {
    api::Particle p;
    p.position = c[k], p.radius = r[k], p.tau = tau[k], p.albedo = a[k];
    s.particles.push_back(p);
  }
  return {s};
}

TEST_F(NetworkGpuTest, VisibilityAndIterationMatchTheCpuDoubleVersion) {
  const rt::ParticleMedium medium(lumpyCloud());
  const NodeSet ns = sampleNodes(medium, 384, 5);
  const auto dirs = makeDirections(48, true, 2);
  const int M = 9;
  const auto W = phaseWeights(dirs, ns.phase, ns.g);
  const std::vector<DirectionalLight> lights = {{glm::normalize(glm::vec3(0.3f, -1.f, -0.2f)), glm::vec3(4.f, 3.5f, 3.f)},
                                                {glm::normalize(glm::vec3(-1.f, 0.2f, 0.5f)), glm::vec3(1.f)}};
  NetworkGpu gpu(ns, dirs, W, M, 8);
  gpu.buildVisibility(library_);
  const Visibility vg = gpu.downloadVisibility();
  const Visibility vc = buildVisibility(ns, dirs, M);
  std::size_t same = 0;
  double alphaErr = 0;
  for (std::size_t k = 0; k < vc.upstream.size(); ++k)
    if (vg.upstream[k] == vc.upstream[k]) {
      ++same;
      alphaErr = std::max(alphaErr, double(std::abs(vg.alpha[k] - vc.alpha[k])));
    }
  const double agree = double(same) / vc.upstream.size();
  std::printf("V: %.5f of %zu links agree, max |alpha_gpu - alpha_cpu| %.2e, sky links %.3f\n", agree,
              vc.upstream.size(), alphaErr, vc.occupancy());
  EXPECT_GT(agree, 0.998);
  EXPECT_LT(alphaErr, 1e-5);

  Problem pb;
  pb.nodes = &ns, pb.dirs = &dirs, pb.visibility = &vg, pb.weights = &W;
  pb.lights = lights;
  pb.transmittance = lightTransmittance(ns, lights, M);
  pb.sky = glm::dvec3(0.3, 0.4, 0.6);
  gpu.setLights(lights, pb.transmittance);
  const int n = 24;
  // Both link schemes: the upstream source (Algorithm 7) and the linear one (Problem::linearSource).
  std::vector<glm::dvec3> I, Ig;
  for (const bool linear : {false, true}) {
    pb.linearSource = linear;
    gpu.clearRadiance();
    const std::vector<double> rg = gpu.iterate(library_, n, glm::vec3(pb.sky), linear);
    I.assign(std::size_t(ns.nodes.size()) * dirs.size(), glm::dvec3(0.0));
    std::vector<glm::dvec3> next;
    std::vector<double> rc;
    for (int k = 0; k < n; ++k) rc.push_back(iterate(pb, I, next)), I.swap(next);
    Ig = gpu.downloadRadiance();
    double peak = 0, err = 0;
    for (std::size_t k = 0; k < I.size(); ++k)
      for (int c = 0; c < 3; ++c) peak = std::max(peak, I[k][c]), err = std::max(err, std::abs(Ig[k][c] - I[k][c]));
    double residualErr = 0;
    for (int k = 0; k < n; ++k) residualErr = std::max(residualErr, std::abs(rg[k] - rc[k]));
    std::printf("%s source: I after %d iterations: peak %.4f, max |gpu - cpu| %.2e (%.2e of peak); residuals %.4g -> "
                "%.4g, max diff %.2e\n", linear ? "linear" : "upstream", n, peak, err, err / peak, rc.front(), rc.back(),
                residualErr);
    ASSERT_GT(peak, 0.1);
    EXPECT_LT(err / peak, std::ldexp(1.0, -10));
    EXPECT_LT(residualErr, std::ldexp(1.0, -10) * peak);
  }

  // Deterministic: the same iterations again from 0 give the same bits.
  gpu.clearRadiance();
  gpu.iterate(library_, n, glm::vec3(pb.sky), true);
  const std::vector<glm::dvec3> again = gpu.downloadRadiance();
  double rerun = 0;
  for (std::size_t k = 0; k < I.size(); ++k) rerun = std::max(rerun, glm::length(again[k] - Ig[k]));
  EXPECT_EQ(rerun, 0.0);
}

TEST_F(NetworkGpuTest, GpuFurnaceRisesMonotonicallyToTheSky) {
  api::ParticleSystem s;
  s.kind = api::MediumKind::Cloud;
  api::Particle p;
  p.radius = 1.f, p.tau = 2.f, p.albedo = glm::vec3(1.f);
  s.particles = {p};
  const rt::ParticleMedium medium({s});
  const NodeSet ns = sampleNodes(medium, 200, 1);
  const auto dirs = makeDirections(32, true, 1);
  NetworkGpu gpu(ns, dirs, phaseWeights(dirs, ns.phase, ns.g), 6, 1);
  gpu.buildVisibility(library_);
  gpu.setLights({}, {});
  std::vector<glm::dvec3> last(ns.nodes.size() * dirs.size(), glm::dvec3(0.0));
  double drop = 0;
  for (int k = 0; k < 40; ++k) {
    gpu.iterate(library_, 25, glm::vec3(1.f));
    const auto I = gpu.downloadRadiance();
    for (std::size_t j = 0; j < I.size(); ++j) drop = std::max(drop, last[j].x - I[j].x);
    last = I;
  }
  double err = 0;
  for (const auto& v : last) err = std::max(err, std::abs(v.x - 1.0));
  std::printf("GPU furnace after 1000 iterations: max |I - 1| %.2e, largest decrease %.2e\n", err, drop);
  EXPECT_LT(err, 1e-5);   // fp32 rounding of a fixed point
  EXPECT_LE(drop, 1e-6);  // monotone up to rounding
}

// A cancelled request stops the iteration (the pass then answers 409): iterate() asks every 4
// iterations, so a request cancelled at the third question has run exactly 8 iterations, and the state
// is those 8 iterations' (a valid warm start).
TEST_F(NetworkGpuTest, CancelledIterationStopsAtTheNextPoll) {
  api::ParticleSystem s;
  s.kind = api::MediumKind::Cloud;
  api::Particle p;
  p.radius = 1.f, p.tau = 4.f, p.albedo = glm::vec3(0.9f);
  s.particles = {p};
  const rt::ParticleMedium medium({s});
  const NodeSet ns = sampleNodes(medium, 200, 1);
  const auto dirs = makeDirections(16, true, 1);
  NetworkGpu gpu(ns, dirs, phaseWeights(dirs, ns.phase, ns.g), 6, 1);
  gpu.buildVisibility(library_);
  gpu.setLights({}, {});
  int asked = 0;
  const std::vector<double> r = gpu.iterate(library_, 1000, glm::vec3(1.f), true, [&] { return ++asked == 3; });
  EXPECT_EQ(asked, 3);
  ASSERT_EQ(r.size(), 8u);
  const std::vector<glm::dvec3> cancelled = gpu.downloadRadiance();
  gpu.clearRadiance();
  gpu.iterate(library_, 8, glm::vec3(1.f), true);
  const std::vector<glm::dvec3> eight = gpu.downloadRadiance();
  double diff = 0;
  for (std::size_t k = 0; k < eight.size(); ++k) diff = std::max(diff, glm::length(eight[k] - cancelled[k]));
  EXPECT_EQ(diff, 0.0);
}

}  // namespace
}  // namespace radiant::network
