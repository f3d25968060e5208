#pragma once
// Image error metrics: how far a GPU technique's image is from the reference renderer's.
//
// All metrics run over the colour channels: the first three channels of an image with >= 3 channels
// (alpha and extra channels are ignored), or channel 0 of a single-channel image. Both images must have
// the same size and channel count.
//
// - rmse, meanAbs, maxAbs: on linear values, over all pixels and colour channels (computed by
//   OpenImageIO's ImageBufAlgo::compare).
// - relMse: relative MSE, mean over pixels and colour channels of (t - r)^2 / (r^2 + eps), eps = 0.01
//   (Rousselle et al. 2011's relMSE; eps keeps black reference pixels from dominating).
// - psnr: on tone-mapped values, v' = sRGB(clamp(v * 2^exposureEV, 0, 1)), peak 1:
//   PSNR = 10 log10(1 / MSE'); nullopt when MSE' == 0 (identical after tone mapping).
// - ssim: Wang et al. 2004 ("Image quality assessment: from error visibility to structural
//   similarity"), eq. 13, on the tone-mapped luma Y' = 0.2126 R' + 0.7152 G' + 0.0722 B' (Rec. 709
//   weights on the tone-mapped channels), with an 11x11 Gaussian window of sigma 1.5 (normalised),
//   C1 = (K1 L)^2, C2 = (K2 L)^2, K1 = 0.01, K2 = 0.03, L = 1. The SSIM map is evaluated where the
//   window fits inside the image ("valid" region, as in the authors' reference code) and averaged.
//   Images smaller than 11 pixels in a dimension use the window clipped at the border and renormalised.
#include <optional>

#include <nlohmann/json_fwd.hpp>

#include "renderer/Image.h"

namespace radiant::metrics {

inline constexpr double kRelMseEpsilon = 0.01;
inline constexpr int kSsimWindow = 11;
inline constexpr double kSsimSigma = 1.5;
inline constexpr double kSsimK1 = 0.01, kSsimK2 = 0.03;

struct ImageMetrics {
  double rmse = 0.0;
  double relMse = 0.0;
  std::optional<double> psnr;  // dB; nullopt when the tone-mapped images are identical
  double ssim = 1.0;
  double meanAbs = 0.0;
  double maxAbs = 0.0;
};

// Sets out's rmse, rel_mse, psnr (null when identical), ssim, mean_abs and max_abs: the names of
// stats.metrics (docs/API.md, compare), for a frame's compare block and a refined job's mean alike.
void writeMetricsJson(const ImageMetrics& e, nlohmann::json& out);

// Throws std::invalid_argument when the sizes or channel counts differ or an image is empty.
ImageMetrics compareImages(const Image& test, const Image& reference, float exposureEV = 0.f);

// Per-pixel error: Rec. 709 luminance of the per-channel absolute difference |t - r| (linear),
// one channel, aov "error". Same argument checks as compareImages.
Image errorMap(const Image& test, const Image& reference);

// A false-colour picture of a one-channel error image: viridis (matplotlib's perceptually uniform map,
// five stops interpolated linearly in display sRGB) of clamp(error / maxError, 0, 1); RGB values are
// display-referred sRGB in [0, 1] (decode them before writing a linear image). maxError <= 0 or
// non-finite picks the image's largest finite error (all black-purple when that is 0).
Image falseColour(const Image& error, double maxError = 0.0, double* usedMax = nullptr);

// The tone map used by psnr and ssim: sRGB transfer (IEC 61966-2-1) of clamp(v * 2^exposureEV, 0, 1).
double toneMap(double linear, float exposureEV);

}  // namespace radiant::metrics
