#include "renderer/metrics/Metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace radiant::metrics {
namespace {

void checkCompatible(const Image& test, const Image& reference, const char* who) {
  auto describe = [](const Image& i) {
    return std::to_string(i.width) + "x" + std::to_string(i.height) + "x" + std::to_string(i.channels);
  };
  if (test.width <= 0 || test.height <= 0 || test.channels <= 0 ||
      test.pixels.size() != static_cast<size_t>(test.width) * test.height * test.channels)
    throw std::invalid_argument(std::string(who) + ": test image is empty or malformed (" + describe(test) + ")");
  if (reference.pixels.size() != static_cast<size_t>(reference.width) * reference.height * reference.channels)
    throw std::invalid_argument(std::string(who) + ": reference image is malformed (" + describe(reference) + ")");
  if (test.width != reference.width || test.height != reference.height || test.channels != reference.channels)
    throw std::invalid_argument(std::string(who) + ": test is " + describe(test) + " but reference is " +
                                describe(reference));
}

int colorChannels(const Image& i) { return i.channels >= 3 ? 3 : 1; }

// Tone-mapped luma of every pixel (the SSIM input).
std::vector<double> toneMappedLuma(const Image& img, float ev) {
  std::vector<double> y(static_cast<size_t>(img.width) * img.height);
  for (int py = 0; py < img.height; ++py)
    for (int px = 0; px < img.width; ++px) {
      const float* p = img.at(px, py);
      double v;
      if (img.channels >= 3)
        v = 0.2126 * toneMap(p[0], ev) + 0.7152 * toneMap(p[1], ev) + 0.0722 * toneMap(p[2], ev);
      else
        v = toneMap(p[0], ev);
      y[static_cast<size_t>(py) * img.width + px] = v;
    }
  return y;
}

// Wang et al. 2004, eq. 13, with Gaussian-weighted local statistics (eqs. 14-16).
double ssim(const std::vector<double>& x, const std::vector<double>& y, int w, int h) {
  const int radius = kSsimWindow / 2;
  double kernel[kSsimWindow];
  double ksum = 0.0;
  for (int i = 0; i < kSsimWindow; ++i) {
    const double d = i - radius;
    kernel[i] = std::exp(-d * d / (2.0 * kSsimSigma * kSsimSigma));
    ksum += kernel[i];
  }
  for (double& k : kernel) k /= ksum;
  const double c1 = (kSsimK1 * 1.0) * (kSsimK1 * 1.0), c2 = (kSsimK2 * 1.0) * (kSsimK2 * 1.0);
  const bool valid = w >= kSsimWindow && h >= kSsimWindow;
  const int x0 = valid ? radius : 0, x1 = valid ? w - radius : w;
  const int y0 = valid ? radius : 0, y1 = valid ? h - radius : h;
  double total = 0.0;
  long count = 0;
  for (int cy = y0; cy < y1; ++cy)
    for (int cx = x0; cx < x1; ++cx) {
      double wsum = 0.0, mx = 0.0, my = 0.0, sxx = 0.0, syy = 0.0, sxy = 0.0;
      for (int dy = -radius; dy <= radius; ++dy) {
        const int yy = cy + dy;
        if (yy < 0 || yy >= h) continue;
        for (int dx = -radius; dx <= radius; ++dx) {
          const int xx = cx + dx;
          if (xx < 0 || xx >= w) continue;
          const double k = kernel[dy + radius] * kernel[dx + radius];
          const double a = x[static_cast<size_t>(yy) * w + xx], b = y[static_cast<size_t>(yy) * w + xx];
          wsum += k;
          mx += k * a;
          my += k * b;
          sxx += k * a * a;
          syy += k * b * b;
          sxy += k * a * b;
        }
      }
      mx /= wsum; my /= wsum;
      const double varX = std::max(0.0, sxx / wsum - mx * mx);
      const double varY = std::max(0.0, syy / wsum - my * my);
      const double covXY = sxy / wsum - mx * my;
      total += ((2.0 * mx * my + c1) * (2.0 * covXY + c2)) / ((mx * mx + my * my + c1) * (varX + varY + c2));
      ++count;
    }
  return count > 0 ? total / count : 1.0;
}

}  // namespace

double toneMap(double linear, float exposureEV) {
  double v = linear * std::exp2(static_cast<double>(exposureEV));
  if (!(v > 0.0)) return 0.0;  // also maps NaN to 0
  v = std::min(v, 1.0);
  return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
}

void writeMetricsJson(const ImageMetrics& e, nlohmann::json& out) {
  out["rmse"] = e.rmse;
  out["rel_mse"] = e.relMse;
  out["psnr"] = e.psnr ? nlohmann::json(*e.psnr) : nlohmann::json(nullptr);
  out["ssim"] = e.ssim;
  out["mean_abs"] = e.meanAbs;
  out["max_abs"] = e.maxAbs;
}

ImageMetrics compareImages(const Image& test, const Image& reference, float exposureEV) {
  checkCompatible(test, reference, "compareImages()");
  const int nc = colorChannels(test);
  const size_t pixels = static_cast<size_t>(test.width) * test.height;

  ImageMetrics m;
  // Every sum in double: a difference of two finite floats (up to 2 x FLT_MAX) and its square are
  // finite there, so any finite input gives finite metrics (OpenImageIO's compare, used before, failed
  // outright on frames holding values near FLT_MAX: a 500 for a request within the API's ranges).
  double absSum = 0.0, sqSum = 0.0, relSum = 0.0, toneSum = 0.0;
  for (size_t i = 0; i < pixels; ++i)
    for (int c = 0; c < nc; ++c) {
      const double t = test.pixels[i * test.channels + c], r = reference.pixels[i * reference.channels + c];
      const double d = t - r;
      absSum += std::abs(d);
      sqSum += d * d;
      m.maxAbs = std::max(m.maxAbs, std::abs(d));
      relSum += d * d / (r * r + kRelMseEpsilon);
      const double dt = toneMap(t, exposureEV) - toneMap(r, exposureEV);
      toneSum += dt * dt;
    }
  const double n = static_cast<double>(pixels) * nc;
  m.rmse = std::sqrt(sqSum / n);
  m.meanAbs = absSum / n;
  m.relMse = relSum / n;
  const double toneMse = toneSum / n;
  if (toneMse > 0.0) m.psnr = 10.0 * std::log10(1.0 / toneMse);
  m.ssim = ssim(toneMappedLuma(test, exposureEV), toneMappedLuma(reference, exposureEV), test.width, test.height);
  return m;
}

Image falseColour(const Image& error, double maxError, double* usedMax) {
  static constexpr float kViridis[5][3] = {{0.267f, 0.005f, 0.329f}, {0.229f, 0.322f, 0.546f},
                                           {0.128f, 0.567f, 0.551f}, {0.369f, 0.789f, 0.383f},
                                           {0.993f, 0.906f, 0.144f}};
  if (!(maxError > 0.0) || !std::isfinite(maxError)) {
    maxError = 0.0;
    for (std::size_t i = 0; i < error.pixels.size(); i += std::max(1, error.channels))
      if (std::isfinite(error.pixels[i])) maxError = std::max(maxError, static_cast<double>(error.pixels[i]));
  }
  if (usedMax) *usedMax = maxError;
  Image out = Image::make("error_colour", error.width, error.height, 3);
  for (int y = 0; y < error.height; ++y)
    for (int x = 0; x < error.width; ++x) {
      const double e = error.at(x, y)[0];
      const double t = maxError > 0.0 && std::isfinite(e) ? std::clamp(e / maxError, 0.0, 1.0) : (std::isfinite(e) ? 0.0 : 1.0);
      const double s = t * 4.0;
      const int i = std::min(3, static_cast<int>(s));
      const float f = static_cast<float>(s - i);
      float* o = out.at(x, y);
      for (int c = 0; c < 3; ++c) o[c] = kViridis[i][c] + f * (kViridis[i + 1][c] - kViridis[i][c]);
    }
  return out;
}

namespace {

void checkCompatible(const ImageRgba8& candidate, const ImageRgba8& golden, const char* who) {
  auto ok = [](const ImageRgba8& i) {
    return i.width > 0 && i.height > 0 && i.pixels.size() == static_cast<size_t>(i.width) * i.height * 4;
  };
  if (!ok(candidate) || !ok(golden))
    throw std::invalid_argument(std::string(who) + ": an image is empty or malformed");
  if (candidate.width != golden.width || candidate.height != golden.height)
    throw std::invalid_argument(std::string(who) + ": candidate is " + std::to_string(candidate.width) + "x" +
                                std::to_string(candidate.height) + " but golden is " + std::to_string(golden.width) +
                                "x" + std::to_string(golden.height));
}

// pixelmatch's blend: the colour over a white backdrop by its straight alpha in [0, 1].
double blendWithWhite(double c, double a) { return 255.0 + (c - 255.0) * a; }

// NTSC YIQ of an sRGB-coded colour, pixelmatch's coefficients (rgb2y, rgb2i, rgb2q).
void rgbToYiq(double r, double g, double b, double yiq[3]) {
  yiq[0] = 0.29889531 * r + 0.58662247 * g + 0.11448223 * b;
  yiq[1] = 0.59597799 * r - 0.27417610 * g - 0.32180189 * b;
  yiq[2] = 0.21147017 * r - 0.52261711 * g + 0.31114694 * b;
}

}  // namespace

double yiqColourDelta(const std::uint8_t* candidate, const std::uint8_t* golden) {
  double a[3], b[3];
  const double ac = candidate[3] / 255.0, ag = golden[3] / 255.0;
  rgbToYiq(blendWithWhite(candidate[0], ac), blendWithWhite(candidate[1], ac), blendWithWhite(candidate[2], ac), a);
  rgbToYiq(blendWithWhite(golden[0], ag), blendWithWhite(golden[1], ag), blendWithWhite(golden[2], ag), b);
  const double dy = a[0] - b[0], di = a[1] - b[1], dq = a[2] - b[2];
  // Kotsarenko and Ramos eq. 4: a weighted squared distance in YIQ.
  return 0.5053 * dy * dy + 0.299 * di * di + 0.1957 * dq * dq;
}

FidelityScore renderFidelity(const ImageRgba8& candidate, const ImageRgba8& golden) {
  checkCompatible(candidate, golden, "renderFidelity()");
  FidelityScore s;
  double sum = 0.0;
  for (size_t p = 0; p < static_cast<size_t>(candidate.width) * candidate.height; ++p) {
    if (candidate.pixels[p * 4 + 3] == 0) continue;  // not the model: model-viewer skips it
    const double delta = yiqColourDelta(&candidate.pixels[p * 4], &golden.pixels[p * 4]);
    sum += delta * delta;
    ++s.covered;
  }
  if (s.covered == 0) return s;
  s.rms = std::sqrt(sum / static_cast<double>(s.covered)) / kFidelityMaxColourDistance;
  s.floored = s.rms < kFidelityFloorRms;
  s.decibels = 10.0 * std::log10(std::max(s.rms, kFidelityFloorRms));
  return s;
}

Image fidelityDeltaMap(const ImageRgba8& candidate, const ImageRgba8& golden) {
  checkCompatible(candidate, golden, "fidelityDeltaMap()");
  Image out = Image::make("fidelity_delta", candidate.width, candidate.height, 1);
  for (size_t p = 0; p < static_cast<size_t>(candidate.width) * candidate.height; ++p)
    if (candidate.pixels[p * 4 + 3] != 0)
      out.pixels[p] = static_cast<float>(yiqColourDelta(&candidate.pixels[p * 4], &golden.pixels[p * 4]) /
                                         kFidelityMaxColourDistance);
  return out;
}

Image errorMap(const Image& test, const Image& reference) {
  checkCompatible(test, reference, "errorMap()");
  Image out = Image::make("error", test.width, test.height, 1);
  for (int y = 0; y < test.height; ++y)
    for (int x = 0; x < test.width; ++x) {
      const float* t = test.at(x, y);
      const float* r = reference.at(x, y);
      // In double, stored clamped to the largest float: |FLT_MAX - (-FLT_MAX)| is not a float.
      auto diff = [&](int c) { return std::abs(double(t[c]) - double(r[c])); };
      const double e = test.channels >= 3 ? 0.2126 * diff(0) + 0.7152 * diff(1) + 0.0722 * diff(2) : diff(0);
      *out.at(x, y) = static_cast<float>(std::min(e, double(std::numeric_limits<float>::max())));
    }
  return out;
}

}  // namespace radiant::metrics
