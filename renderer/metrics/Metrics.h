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
// - renderFidelity: the score of the glTF render-fidelity comparisons (google/model-viewer,
//   packages/render-fidelity-tools: common.ts ImageComparator::analyze and pixelmatch's colorDelta), on
//   the 8-bit display images, not on linear values; see there.
#include <cstddef>
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

// model-viewer's render-fidelity score of a candidate against a golden image, both 8-bit RGBA of the
// same size (PNG codes, straight alpha):
//  1. each channel is blended with white by its own image's alpha: c' = 255 + (c - 255) a / 255;
//  2. both are taken to YIQ with pixelmatch's coefficients (yiqColourDelta below), and the pixel's
//     delta = 0.5053 dY^2 + 0.299 dI^2 + 0.1957 dQ^2 (Kotsarenko and Ramos 2010, "Measuring perceived
//     colour difference using YIQ NTSC transmission colour space in mobile applications", eq. 4: already
//     a squared distance, at most kFidelityMaxColourDistance: red against cyan);
//  3. only pixels where the CANDIDATE's alpha is not 0 count (the model's pixels);
//  4. rms = sqrt(sum delta^2 / covered) / kFidelityMaxColourDistance (the delta is squared once more,
//     as model-viewer does), and the score is 10 log10(rms) dB: lower is better, model-viewer's
//     regression threshold is kFidelityThresholdDb.
// Two cases model-viewer leaves undefined (it divides by zero or takes log10(0)):
//  - identical images (rms 0, -inf dB): rms is clamped to kFidelityFloorRms, so the score is
//    kFidelityFloorDb = -100 dB and `floored` is set;
//  - no covered pixel: nothing to score; decibels is nullopt (and rms 0).
// Throws std::invalid_argument when the sizes differ or an image is empty or malformed.
inline constexpr double kFidelityMaxColourDistance = 35215.0;
inline constexpr double kFidelityFloorRms = 1e-10;
inline constexpr double kFidelityFloorDb = -100.0;
inline constexpr double kFidelityThresholdDb = -22.0;

struct FidelityScore {
  std::optional<double> decibels;  // 10 log10(max(rms, kFidelityFloorRms)); nullopt when covered == 0
  double rms = 0.0;                // sqrt(sum delta^2 / covered) / kFidelityMaxColourDistance
  std::size_t covered = 0;         // pixels with candidate alpha != 0
  bool floored = false;            // rms was below kFidelityFloorRms (identical on the covered pixels)
};

// pixelmatch's colorDelta of two 8-bit RGBA pixels (steps 1 and 2 above): in [0, 35215].
double yiqColourDelta(const std::uint8_t* candidate, const std::uint8_t* golden);
FidelityScore renderFidelity(const ImageRgba8& candidate, const ImageRgba8& golden);
// The per-pixel delta / kFidelityMaxColourDistance as a one-channel image (aov "fidelity_delta"); 0
// where the candidate's alpha is 0 (not scored). Same argument checks as renderFidelity.
Image fidelityDeltaMap(const ImageRgba8& candidate, const ImageRgba8& golden);

// The tone map used by psnr and ssim: sRGB transfer (IEC 61966-2-1) of clamp(v * 2^exposureEV, 0, 1).
double toneMap(double linear, float exposureEV);

}  // namespace radiant::metrics
