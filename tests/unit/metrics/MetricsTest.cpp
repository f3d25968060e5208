// Image metrics against hand-computed values (numbers below were evaluated by hand / in a calculator
// from the formulas in Metrics.h).
#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <random>

#include "renderer/metrics/Metrics.h"

namespace radiant::metrics {
namespace {

Image constant(int w, int h, float v, int channels = 3) {
  Image i = Image::make("beauty", w, h, channels);
  std::fill(i.pixels.begin(), i.pixels.end(), v);
  return i;
}

TEST(Metrics, IdenticalImages) {
  Image a = constant(16, 16, 0.3f);
  a.at(3, 4)[1] = 7.f;
  const ImageMetrics m = compareImages(a, a);
  EXPECT_EQ(m.rmse, 0.0);
  EXPECT_EQ(m.relMse, 0.0);
  EXPECT_EQ(m.meanAbs, 0.0);
  EXPECT_EQ(m.maxAbs, 0.0);
  EXPECT_FALSE(m.psnr.has_value());
  EXPECT_NEAR(m.ssim, 1.0, 1e-12);
}

TEST(Metrics, HandComputedSinglePixelError) {
  // Reference 0.5 everywhere (2x2 RGB = 12 values); the test differs by 0.5 in one value.
  const Image ref = constant(2, 2, 0.5f);
  Image test = ref;
  test.at(1, 0)[0] = 1.f;
  const ImageMetrics m = compareImages(test, ref);
  EXPECT_NEAR(m.rmse, std::sqrt(0.25 / 12), 1e-7);                // 0.1443376
  EXPECT_NEAR(m.relMse, (0.25 / (0.25 + 0.01)) / 12, 1e-7);       // 0.0801282, eps = 0.01
  EXPECT_NEAR(m.meanAbs, 0.5 / 12, 1e-7);
  EXPECT_NEAR(m.maxAbs, 0.5, 1e-7);
  // Tone mapped: sRGB(1) = 1, sRGB(0.5) = 0.7353570; MSE' = 0.2646430^2 / 12 -> 22.33860 dB.
  ASSERT_TRUE(m.psnr.has_value());
  EXPECT_NEAR(*m.psnr, 22.338604, 1e-4);
  // Exposure +1 EV maps both 0.5 and 1 to >= 1, clamped: identical after tone mapping.
  const ImageMetrics e = compareImages(test, ref, 1.f);
  EXPECT_FALSE(e.psnr.has_value());
  EXPECT_NEAR(e.ssim, 1.0, 1e-12);
  EXPECT_NEAR(e.rmse, m.rmse, 1e-12);  // linear metrics ignore exposure

  const Image err = errorMap(test, ref);
  ASSERT_EQ(err.channels, 1);
  EXPECT_NEAR(*err.at(1, 0), 0.2126f * 0.5f, 1e-7f);
  EXPECT_EQ(*err.at(0, 0), 0.f);
}

TEST(Metrics, SsimOfConstantImagesIsTheLuminanceTerm) {
  // Constant images: sigma = 0, so SSIM = (2 mu_x mu_y + C1) / (mu_x^2 + mu_y^2 + C1), C1 = 1e-4, with
  // mu = sRGB(0.5) = 0.7353570 and sRGB(0.25) = 0.5370987: 0.9526044.
  const ImageMetrics m = compareImages(constant(16, 16, 0.25f), constant(16, 16, 0.5f));
  EXPECT_NEAR(m.ssim, 0.9526044, 1e-6);
  // Also through the small-image path (clipped window): the same for constant images.
  EXPECT_NEAR(compareImages(constant(5, 4, 0.25f), constant(5, 4, 0.5f)).ssim, 0.9526044, 1e-6);
}

// SSIM of one 11x11 window (the whole image), written straight from Wang et al. 2004 eqs. 13-16.
double ssimSingleWindow(const Image& a, const Image& b) {
  double w[11], ws = 0;
  for (int i = 0; i < 11; ++i) { w[i] = std::exp(-(i - 5) * (i - 5) / (2 * 1.5 * 1.5)); ws += w[i]; }
  double mx = 0, my = 0, sxx = 0, syy = 0, sxy = 0;
  for (int y = 0; y < 11; ++y)
    for (int x = 0; x < 11; ++x) {
      const double k = w[x] * w[y] / (ws * ws);
      auto luma = [&](const Image& im) {
        const float* p = im.at(x, y);
        return 0.2126 * toneMap(p[0], 0) + 0.7152 * toneMap(p[1], 0) + 0.0722 * toneMap(p[2], 0);
      };
      const double u = luma(a), v = luma(b);
      mx += k * u; my += k * v; sxx += k * u * u; syy += k * v * v; sxy += k * u * v;
    }
  const double vx = sxx - mx * mx, vy = syy - my * my, cxy = sxy - mx * my;
  const double c1 = 1e-4, c2 = 9e-4;
  return (2 * mx * my + c1) * (2 * cxy + c2) / ((mx * mx + my * my + c1) * (vx + vy + c2));
}

TEST(Metrics, SsimMatchesFormulaAndFallsWithNoise) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> U(0.f, 1.f);
  std::normal_distribution<float> N(0.f, 1.f);
  Image ref = Image::make("beauty", 11, 11, 3);
  for (float& v : ref.pixels) v = U(rng);
  Image test = ref;
  for (float& v : test.pixels) v = std::max(0.f, v + 0.1f * N(rng));
  EXPECT_NEAR(compareImages(test, ref).ssim, ssimSingleWindow(test, ref), 1e-9);

  Image big = Image::make("beauty", 48, 48, 3);
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 48; ++x)
      for (int c = 0; c < 3; ++c) big.at(x, y)[c] = 0.5f + 0.4f * std::sin(0.3f * x + 0.2f * y + c);
  double previous = 1.0;
  for (float sigma : {0.01f, 0.05f, 0.1f, 0.3f}) {
    Image noisy = big;
    std::mt19937 r2(2);
    for (float& v : noisy.pixels) v = std::max(0.f, v + sigma * N(r2));
    const ImageMetrics m = compareImages(noisy, big);
    EXPECT_LT(m.ssim, previous) << sigma;
    EXPECT_GT(m.ssim, -1.0);
    EXPECT_GT(m.rmse, 0.0);
    previous = m.ssim;
  }
  EXPECT_LT(previous, 0.8);
}

TEST(Metrics, ErrorsAgreeWithDirectSums) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> U(0.f, 4.f);
  Image a = Image::make("beauty", 23, 17, 4), b = Image::make("beauty", 23, 17, 4);
  for (float& v : a.pixels) v = U(rng);
  for (float& v : b.pixels) v = U(rng);
  double sq = 0, ab = 0, mx = 0, rel = 0;
  int n = 0;
  for (int i = 0; i < 23 * 17; ++i)
    for (int c = 0; c < 3; ++c) {  // alpha (channel 3) is not a colour channel
      const double d = a.pixels[i * 4 + c] - b.pixels[i * 4 + c];
      sq += d * d; ab += std::abs(d); mx = std::max(mx, std::abs(d));
      rel += d * d / (double(b.pixels[i * 4 + c]) * b.pixels[i * 4 + c] + 0.01);
      ++n;
    }
  const ImageMetrics m = compareImages(a, b);
  EXPECT_NEAR(m.rmse, std::sqrt(sq / n), 1e-6);
  EXPECT_NEAR(m.meanAbs, ab / n, 1e-6);
  EXPECT_NEAR(m.maxAbs, mx, 1e-6);
  EXPECT_NEAR(m.relMse, rel / n, 1e-6 * rel / n);
}

// Issue 30: a frame may hold any finite radiance (a 1e15 light, an HDR of 1.7e38). The metrics of
// +-FLT_MAX against 0 and against -FLT_MAX are the closed forms, finite, and the error map holds FLT_MAX
// where the difference (2 x FLT_MAX) is not a float.
TEST(Metrics, ValuesNearFltMaxGiveFiniteMetrics) {
  Image a = constant(2, 1, 0.f), b = constant(2, 1, 0.f);
  std::fill(a.pixels.begin(), a.pixels.begin() + 3, FLT_MAX);  // pixel 0: FLT_MAX against 0
  std::fill(a.pixels.begin() + 3, a.pixels.end(), FLT_MAX);    // pixel 1: FLT_MAX against -FLT_MAX
  std::fill(b.pixels.begin() + 3, b.pixels.end(), -FLT_MAX);
  const double f = FLT_MAX;
  const ImageMetrics m = compareImages(a, b);
  EXPECT_DOUBLE_EQ(m.maxAbs, 2 * f);
  EXPECT_DOUBLE_EQ(m.meanAbs, (f + 2 * f) / 2);
  EXPECT_DOUBLE_EQ(m.rmse, std::sqrt((f * f + 4 * f * f) / 2));
  EXPECT_TRUE(std::isfinite(m.relMse));
  EXPECT_NEAR(m.relMse, (f * f / kRelMseEpsilon + 4 * f * f / (f * f + kRelMseEpsilon)) / 2, 1e-12 * m.relMse);
  // Tone-mapped, both pixels are white against black (a negative reference maps to 0): MSE 1, PSNR 0 dB.
  ASSERT_TRUE(m.psnr.has_value());
  EXPECT_NEAR(*m.psnr, 0.0, 1e-9);
  const Image e = errorMap(a, b);
  EXPECT_TRUE(std::isfinite(e.pixels[0]));
  EXPECT_NEAR(e.pixels[0], f, 1e-6 * f);  // the weights sum to 1
  EXPECT_EQ(e.pixels[1], FLT_MAX);
}

TEST(Metrics, RejectsMismatchedImages) {
  EXPECT_THROW(compareImages(constant(4, 4, 0.f), constant(4, 5, 0.f)), std::invalid_argument);
  EXPECT_THROW(compareImages(constant(4, 4, 0.f, 3), constant(4, 4, 0.f, 4)), std::invalid_argument);
  EXPECT_THROW(errorMap(Image{}, Image{}), std::invalid_argument);
}

// --- render fidelity (model-viewer's score; numbers evaluated by hand from the formulas in Metrics.h) ---

ImageRgba8 rgba(int w, int h, std::uint8_t r, std::uint8_t g, std::uint8_t b, std::uint8_t a) {
  ImageRgba8 i = ImageRgba8::make(w, h);
  for (int p = 0; p < w * h; ++p) {
    i.pixels[p * 4 + 0] = r, i.pixels[p * 4 + 1] = g, i.pixels[p * 4 + 2] = b, i.pixels[p * 4 + 3] = a;
  }
  return i;
}

TEST(RenderFidelity, PureRedAgainstBlackByHand) {
  // Red (255, 0, 0) against black: dY = 255 x 0.29889531 = 76.21830405, dI = 255 x 0.59597799 =
  // 151.97438745, dQ = 255 x 0.21147017 = 53.92489335; delta = 0.5053 dY^2 + 0.299 dI^2 + 0.1957 dQ^2
  // = 2935.399 + 6905.770 + 569.078 = 10410.247. One pixel: rms = delta / 35215 = 0.295620, -5.2927 dB.
  const ImageRgba8 red = rgba(1, 1, 255, 0, 0, 255), black = rgba(1, 1, 0, 0, 0, 255);
  EXPECT_NEAR(yiqColourDelta(red.at(0, 0), black.at(0, 0)), 10410.2469, 1e-3);
  const FidelityScore s = renderFidelity(red, black);
  EXPECT_EQ(s.covered, 1u);
  EXPECT_FALSE(s.floored);
  EXPECT_NEAR(s.rms, 0.2956197, 1e-6);
  ASSERT_TRUE(s.decibels.has_value());
  EXPECT_NEAR(*s.decibels, -5.29267, 1e-4);
  // The delta is symmetric, and red against cyan is the largest there is (model-viewer's 35215).
  EXPECT_NEAR(yiqColourDelta(black.at(0, 0), red.at(0, 0)), 10410.2469, 1e-3);
  const ImageRgba8 cyan = rgba(1, 1, 0, 255, 255, 255);
  EXPECT_NEAR(yiqColourDelta(red.at(0, 0), cyan.at(0, 0)), 35214.749, 1e-2);
  EXPECT_LE(yiqColourDelta(red.at(0, 0), cyan.at(0, 0)), kFidelityMaxColourDistance);
}

TEST(RenderFidelity, WhiteAgainstBlackHasOnlyLuma) {
  // The Y weights sum to 1.00000001 and the I and Q weights to 0: grey differences are pure luma,
  // delta = 0.5053 x (255 x 1.00000001)^2 = 32857.133.
  const ImageRgba8 white = rgba(1, 1, 255, 255, 255, 255), black = rgba(1, 1, 0, 0, 0, 255);
  EXPECT_NEAR(yiqColourDelta(white.at(0, 0), black.at(0, 0)), 32857.1332, 1e-3);
}

TEST(RenderFidelity, AlphaBlendsWithWhite) {
  // Black at alpha 128: 255 + (0 - 255) x 128 / 255 = 127 per channel, so against opaque white
  // dY = 128 x 1.00000001 and delta = 0.5053 x 128^2 = 8278.835.
  const ImageRgba8 halfBlack = rgba(1, 1, 0, 0, 0, 128), white = rgba(1, 1, 255, 255, 255, 255);
  EXPECT_NEAR(yiqColourDelta(halfBlack.at(0, 0), white.at(0, 0)), 8278.8354, 1e-3);
  // Opaque grey 127 is the same colour as black at alpha 128 over white: delta 0, the floor.
  const FidelityScore s = renderFidelity(halfBlack, rgba(1, 1, 127, 127, 127, 255));
  EXPECT_TRUE(s.floored);
  EXPECT_EQ(*s.decibels, kFidelityFloorDb);
  // The golden is blended by its own alpha: a fully transparent golden is white whatever its colour.
  EXPECT_EQ(yiqColourDelta(white.at(0, 0), rgba(1, 1, 0, 0, 0, 0).at(0, 0)), 0.0);
}

TEST(RenderFidelity, OnlyTheCandidatesCoveredPixelsCount) {
  // Pixel 0: red against black (delta 10410.247); pixel 1: identical; pixel 2: candidate alpha 0 (not
  // the model) against a golden that differs as much as it can: ignored. rms = sqrt(delta^2 / 2) /
  // 35215 = 0.2090347, -6.79782 dB.
  ImageRgba8 candidate = rgba(3, 1, 0, 0, 0, 255), golden = rgba(3, 1, 0, 0, 0, 255);
  candidate.at(0, 0)[0] = 255;
  candidate.at(2, 0)[3] = 0;
  golden.at(2, 0)[0] = 255, golden.at(2, 0)[1] = 255, golden.at(2, 0)[2] = 255;
  const FidelityScore s = renderFidelity(candidate, golden);
  EXPECT_EQ(s.covered, 2u);
  EXPECT_NEAR(s.rms, 0.2090347, 1e-6);
  EXPECT_NEAR(*s.decibels, -6.79782, 1e-4);
  const Image map = fidelityDeltaMap(candidate, golden);
  EXPECT_NEAR(map.pixels[0], 10410.2469 / 35215.0, 1e-6);
  EXPECT_EQ(map.pixels[1], 0.f);
  EXPECT_EQ(map.pixels[2], 0.f);  // not scored
}

TEST(RenderFidelity, IdenticalImagesScoreTheFloorAndNoCoverageScoresNothing) {
  const ImageRgba8 a = rgba(4, 4, 10, 200, 30, 255);
  const FidelityScore same = renderFidelity(a, a);
  EXPECT_EQ(same.rms, 0.0);
  EXPECT_TRUE(same.floored);
  EXPECT_EQ(*same.decibels, -100.0);  // 10 log10(kFidelityFloorRms = 1e-10)
  const FidelityScore none = renderFidelity(rgba(4, 4, 10, 200, 30, 0), a);
  EXPECT_EQ(none.covered, 0u);
  EXPECT_FALSE(none.decibels.has_value());
}

TEST(RenderFidelity, RejectsMismatchedOrEmptyImages) {
  EXPECT_THROW(renderFidelity(rgba(2, 2, 0, 0, 0, 255), rgba(2, 3, 0, 0, 0, 255)), std::invalid_argument);
  EXPECT_THROW(renderFidelity(ImageRgba8{}, ImageRgba8{}), std::invalid_argument);
  EXPECT_THROW(fidelityDeltaMap(rgba(1, 1, 0, 0, 0, 255), ImageRgba8{}), std::invalid_argument);
}

}  // namespace
}  // namespace radiant::metrics
