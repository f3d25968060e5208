// depth_impostors' light slices on llvmpipe (renderer/techniques/depth_impostors/Impostors.h), driven
// directly from a BlockSet (no frame):
//   the slices are built by commutative multiplicative blending, so shuffling the blocks' draw order
//   leaves them identical up to float rounding of the products;
//   slice k is the transmittance behind groups 0..k: in [0, 1] and non-increasing in k at every texel;
//   the transmittance the gather pass reads at a particle centre (bilinear in the slice, linear between
//   the enclosing knots) approaches the exact exp(-optical depth) towards the light (rt::ParticleMedium,
//   closed-form chords) as K grows over {1, 2, 4, 8, 16}.
// Fourier opacity maps (light_transmittance: fourier, Blocks.h), the same light pass with 2M + 1
// coefficients in the slice textures:
//   the Jackson damping's kernel is non-negative (what makes the transmittance monotone);
//   a constant-density sphere, the box sigma = tau on its chord: the reconstruction along the light
//   through its centre against Beer-Lambert exp(-tau (z - z_front)), the error falling over M = 1, 3, 5, 7;
//   every texel's reconstruction is in [0, 1] and non-increasing along the light, where the undamped
//   truncated series rings (its transmittance rises behind sharp edges);
//   at particle centres of a cloud against the exact chords, beside the slices of equal texture memory
//   (K = 4, 8, 12, 16 against M = 1, 3, 5, 7).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <utility>

#include <gtest/gtest.h>

#include "renderer/gl/ShaderLibrary.h"
#include "renderer/platform/EglDevice.h"
#include "renderer/raytracing/ParticleMedium.h"
#include "renderer/techniques/depth_impostors/Impostors.h"
#include "renderer/techniques/spherical_billboards/SphericalBillboards.h"

namespace radiant {
namespace {

using impostors::BlockSet;
using impostors::ImpostorAxis;
using impostors::ImpostorSet;

class ImpostorSlices : public ::testing::Test {
protected:
  static void SetUpTestSuite() { device_ = EglDevice::create(); }
  static void TearDownTestSuite() { device_.reset(); }
  void SetUp() override { device_->makeCurrent(); }
  static std::unique_ptr<EglDevice> device_;
  gl::ShaderLibrary shaders_;
};
std::unique_ptr<EglDevice> ImpostorSlices::device_;

// n constant-density particles of radius r, centres uniform in the unit ball.
api::ParticleSystem cloud(int n, float r, float tau, unsigned seed) {
  api::ParticleSystem s;
  s.kind = api::MediumKind::Cloud;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  while (static_cast<int>(s.particles.size()) < n) {
    const glm::vec3 p(u(rng), u(rng), u(rng));
    if (glm::dot(p, p) > 1.f) continue;
    api::Particle q;
    q.position = p;
    q.radius = r;
    q.tau = tau;
    q.albedo = glm::vec3(0.9f);
    s.particles.push_back(q);
  }
  return s;
}

BlockSet blocksOf(const std::vector<api::ParticleSystem>& media, int b) {
  std::vector<int> systemOf;
  const auto particles = SphericalBillboardsPass::gpuParticles(media, glm::vec3(0.f), glm::vec3(0.f),
                                                               glm::vec3(0, 0, -1), true, false, &systemOf);
  return impostors::buildBlocks(particles, systemOf, b);
}

const glm::vec3 kLight = glm::normalize(glm::vec3(0.3f, -1.f, 0.2f));  // the direction light travels

// The K slices, or (fourierTerms M > 0) the 2M + 1 Fourier coefficients, channel-major.
std::vector<float> slicesOf(gl::ShaderLibrary& shaders, const BlockSet& blocks, int K, int sliceRes,
                            impostors::SliceFrame* frameOut = nullptr, int fourierTerms = 0) {
  const impostors::AtlasLayout layout = impostors::atlasLayout(static_cast<int>(blocks.blocks.size()), 32);
  ImpostorSet set(blocks, layout, K, sliceRes, fourierTerms);
  const ImpostorAxis light{0, kLight};
  const impostors::SliceFrame frame = impostors::fitSliceFrame(blocks.blocks, kLight, K);
  set.build(shaders, ImpostorAxis{0, glm::vec3(0, 0, -1)}, &light, frame);
  if (frameOut) *frameOut = frame;
  return set.downloadSlices();
}

TEST_F(ImpostorSlices, ShufflingTheBlocksLeavesTheSlicesIdentical) {
  const std::vector<api::ParticleSystem> media{cloud(600, 0.15f, 4.f, 7)};
  const BlockSet blocks = blocksOf(media, 8);
  ASSERT_EQ(blocks.blocks.size(), 75u);
  const std::vector<float> a = slicesOf(shaders_, blocks, 8, 64);
  // The same blocks in a shuffled order (their tiles and draw order change, their content does not).
  BlockSet shuffled;
  std::vector<int> perm(blocks.blocks.size());
  std::iota(perm.begin(), perm.end(), 0);
  std::shuffle(perm.begin(), perm.end(), std::mt19937(3));
  for (int newIndex = 0; newIndex < static_cast<int>(perm.size()); ++newIndex) {
    impostors::Block blk = blocks.blocks[perm[newIndex]];
    const int first = static_cast<int>(shuffled.particles.size());
    for (int i = blk.first; i < blk.first + blk.count; ++i) {
      gpu::MediaParticle p = blocks.particles[i];
      p.models.z = newIndex;
      shuffled.particles.push_back(p);
    }
    std::reverse(shuffled.particles.begin() + first, shuffled.particles.end());  // particle order too
    blk.first = first;
    blk.tile = perm[newIndex];  // the same texels: what changes is only the order of the products
    shuffled.blocks.push_back(blk);
  }
  const std::vector<float> b = slicesOf(shaders_, shuffled, 8, 64);
  ASSERT_EQ(a.size(), b.size());
  double maxDiff = 0, minT = 1;
  for (std::size_t i = 0; i < a.size(); ++i) maxDiff = std::max(maxDiff, double(std::abs(a[i] - b[i]))), minT = std::min(minT, double(a[i]));
  std::printf("shuffled slices: max |diff| %.3g (darkest texel %.3g)\n", maxDiff, minT);
  EXPECT_LT(minT, 0.2);  // the cloud does shadow
  // Products of the same factors in another order: float rounding only (a few ulp of 1).
  EXPECT_LE(maxDiff, 1e-6);
}

TEST_F(ImpostorSlices, SliceTransmittanceIsInTheUnitIntervalAndNonIncreasingAlongTheLight) {
  const std::vector<api::ParticleSystem> media{cloud(500, 0.2f, 3.f, 11)};
  const int K = 16, res = 64;
  const std::vector<float> s = slicesOf(shaders_, blocksOf(media, 4), K, res);
  const std::size_t n = static_cast<std::size_t>(res) * res;
  int violations = 0;
  double drop = 0;
  for (std::size_t p = 0; p < n; ++p)
    for (int k = 0; k < K; ++k) {
      const float t = s[k * n + p];
      if (!(t >= 0.f && t <= 1.f)) ++violations;
      if (k > 0 && t > s[(k - 1) * n + p]) ++violations;
      if (k > 0) drop = std::max(drop, double(s[(k - 1) * n + p] - t));
    }
  EXPECT_EQ(violations, 0);
  EXPECT_GT(drop, 0.1);  // slices differ: the groups do go to different slices
  // Slices beyond the cloud's last group all equal the total; the first slice is not all 1.
  EXPECT_LT(*std::min_element(s.begin(), s.begin() + n), 0.9f);
}

// The transmittance the gather pass reads: bilinear in each slice (GL_LINEAR, clamp to edge), linear
// between the enclosing knots.
float sliceLookup(const std::vector<float>& s, int K, int res, const impostors::SliceFrame& f, const glm::vec3& x) {
  const glm::vec2 uv = f.uv(x);
  const float fx = std::clamp(uv.x * res - 0.5f, 0.f, res - 1.f), fy = std::clamp(uv.y * res - 0.5f, 0.f, res - 1.f);
  const int x0 = static_cast<int>(fx), y0 = static_cast<int>(fy);
  const int x1 = std::min(x0 + 1, res - 1), y1 = std::min(y0 + 1, res - 1);
  const float ax = fx - x0, ay = fy - y0;
  std::vector<float> at(K);
  const std::size_t n = static_cast<std::size_t>(res) * res;
  for (int k = 0; k < K; ++k) {
    auto v = [&](int xx, int yy) { return s[k * n + static_cast<std::size_t>(yy) * res + xx]; };
    at[k] = (1 - ay) * ((1 - ax) * v(x0, y0) + ax * v(x1, y0)) + ay * ((1 - ax) * v(x0, y1) + ax * v(x1, y1));
  }
  return impostors::interpolateSlices(at.data(), K, f.knot(x));
}

TEST_F(ImpostorSlices, ShadowingErrorAgainstExactChordsFallsAsKGrows) {
  // 1500 small particles (one per block, so a block's group is its particle's) in the unit ball:
  // optical depth through the centre 2 * 1500 * tau r^3 ~ 3.9, each particle's own chord 2 tau r = 0.72.
  const std::vector<api::ParticleSystem> media{cloud(1500, 0.06f, 6.f, 5)};
  const BlockSet blocks = blocksOf(media, 1);
  const rt::ParticleMedium medium(media);
  const int res = 128;
  std::vector<double> errors;
  for (int K : {1, 2, 4, 8, 16}) {
    impostors::SliceFrame frame;
    const std::vector<float> s = slicesOf(shaders_, blocks, K, res, &frame);
    double sum2 = 0;
    for (const auto& p : media[0].particles) {
      // Exact: exp(-optical depth) from the particle centre back towards the light.
      const double exact = medium.transmittance(p.position, -kLight, 0.f, 1e3f);
      const double got = sliceLookup(s, K, res, frame, p.position);
      sum2 += (got - exact) * (got - exact);
    }
    errors.push_back(std::sqrt(sum2 / media[0].particles.size()));
    std::printf("K = %2d: rms error of the slice transmittance at particle centres %.4f\n", K, errors.back());
  }
  for (std::size_t i = 1; i < errors.size(); ++i) EXPECT_LT(errors[i], errors[i - 1]) << "K index " << i;
  EXPECT_LT(errors.back(), 0.4 * errors.front());  // measured 0.29 -> 0.091
}

// Bilinear (GL_LINEAR, clamp to edge) values of `channels` channel images at slice uv of x.
std::vector<float> bilinear(const std::vector<float>& s, int channels, int res, const impostors::SliceFrame& f,
                            const glm::vec3& x) {
  const glm::vec2 uv = f.uv(x);
  const float fx = std::clamp(uv.x * res - 0.5f, 0.f, res - 1.f), fy = std::clamp(uv.y * res - 0.5f, 0.f, res - 1.f);
  const int x0 = static_cast<int>(fx), y0 = static_cast<int>(fy);
  const int x1 = std::min(x0 + 1, res - 1), y1 = std::min(y0 + 1, res - 1);
  const float ax = fx - x0, ay = fy - y0;
  std::vector<float> at(channels);
  const std::size_t n = static_cast<std::size_t>(res) * res;
  for (int k = 0; k < channels; ++k) {
    auto v = [&](int xx, int yy) { return s[k * n + static_cast<std::size_t>(yy) * res + xx]; };
    at[k] = (1 - ay) * ((1 - ax) * v(x0, y0) + ax * v(x1, y0)) + ay * ((1 - ax) * v(x0, y1) + ax * v(x1, y1));
  }
  return at;
}

// What the gather reads with light_transmittance: fourier (coefficients bilinear, linear in them).
float fourierLookup(const std::vector<float>& s, int M, int res, const impostors::SliceFrame& f, const glm::vec3& x) {
  const std::vector<float> c = bilinear(s, impostors::fourierChannels(M), res, f, x);
  return static_cast<float>(impostors::fourierTransmittance(c.data(), M, f.fourierDepth(x)));
}

TEST(FourierOpacity, JacksonKernelIsNonNegativeAndKeepsTheMean) {
  // K(x) = 1 + 2 sum_k g_k cos(2 pi k x): the reconstructed density is the true one convolved with it.
  for (int M = 1; M <= impostors::kMaxFourierTerms; ++M) {
    double minK = 1e30, minPlain = 1e30;
    for (int i = 0; i <= 4000; ++i) {
      const double x = i / 4000.0;
      double k = 1, plain = 1;
      for (int j = 1; j <= M; ++j)
        k += 2 * impostors::fourierDamping(j, M) * std::cos(2 * M_PI * j * x), plain += 2 * std::cos(2 * M_PI * j * x);
      minK = std::min(minK, k), minPlain = std::min(minPlain, plain);
    }
    std::printf("M = %d: damping g_1 %.4f g_M %.4f; kernel min: Jackson %.2e, undamped (Dirichlet) %.3f\n", M,
                impostors::fourierDamping(1, M), impostors::fourierDamping(M, M), minK, minPlain);
    EXPECT_GE(minK, -1e-12) << M;
    EXPECT_LT(minPlain, -0.2) << M;  // the plain truncation's kernel dips: negative density lobes
    EXPECT_DOUBLE_EQ(impostors::fourierDamping(0, M), 1.0);  // g_0 = 1: the total optical depth is kept
  }
}

TEST_F(ImpostorSlices, FourierTransmittanceOfAConstantSphereApproachesBeerLambertAsTermsGrow) {
  // One constant particle, radius 1, tau 2 (optical diameter 4): along the light ray through its centre
  // the extinction is a box, the exact transmittance exp(-tau (t + 1)) for t in [-1, 1] (t along the light
  // from the centre), 1 before and e^-4 after. A second, transparent particle (optical depth 1e-7) 3 m
  // further along the light moves the far plane, so that the box fills half of the normalised depth range
  // (alone, the box would fill all of it: a constant, which a_0 alone represents exactly).
  api::ParticleSystem s;
  s.kind = api::MediumKind::Cloud;
  api::Particle q;
  q.radius = 1.f, q.tau = 2.f, q.albedo = glm::vec3(0.9f);
  s.particles.push_back(q);
  q.position = 3.f * kLight, q.radius = 0.05f, q.tau = 1e-6f;
  s.particles.push_back(q);
  const std::vector<api::ParticleSystem> media{s};
  const BlockSet blocks = blocksOf(media, 1);
  ASSERT_EQ(blocks.blocks.size(), 2u);
  const rt::ParticleMedium medium(media);
  const int res = 256;
  std::vector<double> maxErr, rmsErr;
  for (int M : {1, 3, 5, 7}) {
    impostors::SliceFrame frame;
    const std::vector<float> c = slicesOf(shaders_, blocks, 8, res, &frame, M);
    double e2 = 0, emax = 0, plainMax = 0;
    const int n = 97;
    for (int i = 0; i < n; ++i) {
      const float t = -1.2f + 2.4f * i / (n - 1);  // through the sphere, to 0.2 m either side
      const glm::vec3 x = t * kLight;
      const double exact = medium.transmittance(x, -kLight, 0.f, 1e3f);
      const double got = fourierLookup(c, M, res, frame, x);
      const std::vector<float> at = bilinear(c, impostors::fourierChannels(M), res, frame, x);
      const double plain = std::exp(-impostors::fourierOpticalDepth(at.data(), M, frame.fourierDepth(x), false));
      e2 += (got - exact) * (got - exact), emax = std::max(emax, std::abs(got - exact));
      plainMax = std::max(plainMax, std::abs(plain - exact));
    }
    maxErr.push_back(emax), rmsErr.push_back(std::sqrt(e2 / n));
    std::printf("M = %d (%d coefficients): |T_fourier - exp(-tau chord)| along the light: max %.4f, rms %.4f "
                "(undamped series: max %.4f)\n",
                M, impostors::fourierChannels(M), emax, rmsErr.back(), plainMax);
  }
  for (std::size_t i = 1; i < rmsErr.size(); ++i) {
    EXPECT_LT(rmsErr[i], rmsErr[i - 1]) << i;
    EXPECT_LT(maxErr[i], maxErr[i - 1]) << i;
  }
  // A box of optical depth 4 over half the normalised depth range, smoothed by the Jackson kernel (about
  // 1/(M + 2) of the 4 m range wide, so its edges blur over 0.4-1.3 m against a 2 m chord): measured rms
  // 0.103, 0.068, 0.053, 0.044 and max 0.173, 0.136, 0.113, 0.098 for M = 1, 3, 5, 7 (the undamped series:
  // max 0.128 ... 0.054, closer on average but ringing, next test). The rms falls about as 1/(M + 2).
  EXPECT_LT(rmsErr.back(), 0.5 * rmsErr.front());
  EXPECT_LT(rmsErr.back(), 0.06);
  EXPECT_LT(maxErr.back(), 0.12);
}

TEST_F(ImpostorSlices, FourierTransmittanceIsInTheUnitIntervalAndNonIncreasingAlongTheLight) {
  const std::vector<api::ParticleSystem> media{cloud(500, 0.2f, 3.f, 11)};
  const BlockSet blocks = blocksOf(media, 4);
  const int res = 64;
  const std::size_t n = static_cast<std::size_t>(res) * res;
  for (int M : {1, 3, 5, 7}) {
    const std::vector<float> c = slicesOf(shaders_, blocks, 8, res, nullptr, M);
    const int channels = impostors::fourierChannels(M);
    int violations = 0, plainRises = 0;
    double minT = 1, worstRise = 0, worstPlainRise = 0;
    std::vector<float> at(channels);
    for (std::size_t p = 0; p < n; ++p) {
      for (int k = 0; k < channels; ++k) at[k] = c[k * n + p];
      double prev = 1, prevPlain = 1;
      for (int i = 0; i <= 200; ++i) {
        const double d = i / 200.0;
        const double t = impostors::fourierTransmittance(at.data(), M, d);
        const double plain = std::exp(-impostors::fourierOpticalDepth(at.data(), M, d, false));
        if (!(t >= 0 && t <= 1)) ++violations;
        if (t > prev + 1e-6) ++violations;
        worstRise = std::max(worstRise, t - prev);
        if (plain > prevPlain + 1e-6) ++plainRises;
        worstPlainRise = std::max(worstPlainRise, plain - prevPlain);
        minT = std::min(minT, t);
        prev = t, prevPlain = plain;
      }
    }
    std::printf("M = %d: %d violations of [0, 1] or monotonicity (largest rise %.2e, darkest %.3f); undamped series: "
                "%d rising steps, largest rise %.3f\n",
                M, violations, worstRise, minT, plainRises, worstPlainRise);
    EXPECT_EQ(violations, 0) << M;
    EXPECT_LT(minT, 0.2) << M;  // the cloud does shadow
    // Measured: 0 violations for every M; the undamped series rises at 72041-81434 of the 64^2 x 200 steps,
    // by up to 0.081, 0.051, 0.041, 0.031 for M = 1, 3, 5, 7.
    EXPECT_GT(plainRises, 0) << M;  // the ringing is real, and handled by the damping
  }
}

TEST_F(ImpostorSlices, FourierAndSlicesAtEqualMemoryAgainstExactChords) {
  // The cloud of ShadowingErrorAgainstExactChordsFallsAsKGrows (1500 particles, b = 1): K slices in K/4
  // RGBA textures against M Fourier terms in ceil((2M + 1)/4) of them.
  const std::vector<api::ParticleSystem> media{cloud(1500, 0.06f, 6.f, 5)};
  const BlockSet blocks = blocksOf(media, 1);
  const rt::ParticleMedium medium(media);
  const int res = 128;
  std::vector<double> fourierErr, sliceErr;
  for (auto [K, M] : {std::pair{4, 1}, std::pair{8, 3}, std::pair{12, 5}, std::pair{16, 7}}) {
    impostors::SliceFrame fs, ff;
    const std::vector<float> s = slicesOf(shaders_, blocks, K, res, &fs);
    const std::vector<float> c = slicesOf(shaders_, blocks, K, res, &ff, M);
    double s2 = 0, f2 = 0;
    for (const auto& p : media[0].particles) {
      const double exact = medium.transmittance(p.position, -kLight, 0.f, 1e3f);
      s2 += std::pow(sliceLookup(s, K, res, fs, p.position) - exact, 2);
      f2 += std::pow(fourierLookup(c, M, res, ff, p.position) - exact, 2);
    }
    sliceErr.push_back(std::sqrt(s2 / media[0].particles.size()));
    fourierErr.push_back(std::sqrt(f2 / media[0].particles.size()));
    std::printf("%d RGBA textures: rms error at particle centres: slices K = %2d %.4f, fourier M = %d %.4f\n", (K + 3) / 4,
                K, sliceErr.back(), M, fourierErr.back());
  }
  // Measured: slices 0.130, 0.108, 0.096, 0.091; fourier 0.102, 0.070, 0.055, 0.046 (each particle's own
  // chord, optical depth 0.72, is a box in the Fourier maps and lumped at its centre in the slices).
  for (std::size_t i = 1; i < fourierErr.size(); ++i) EXPECT_LT(fourierErr[i], fourierErr[i - 1]) << i;
  for (std::size_t i = 0; i < fourierErr.size(); ++i) EXPECT_LT(fourierErr[i], sliceErr[i]) << i;
  EXPECT_LT(fourierErr.back(), 0.6 * sliceErr.back());
}

}  // namespace
}  // namespace radiant
