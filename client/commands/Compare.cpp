// radiant compare A B [-o diff.png] [--max E] [--exposure EV] [--aov NAME] [--json]: the metrics the
// service reports (renderer/metrics) for two images from anywhere (EXR, PNG, anything OpenImageIO reads),
// and a false-colour picture of the per-pixel error. B is the reference.
#include <iostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "client/Commands.h"
#include "renderer/io/ImageIO.h"
#include "renderer/metrics/Metrics.h"

namespace radiant::client {
namespace {

constexpr const char* kUsage =
    "usage: radiant compare TEST REFERENCE [-o error.png] [--max E] [--exposure EV] [--aov NAME] [--json]\n"
    "  Prints RMSE, relMSE, PSNR (dB, tone-mapped), SSIM, mean and max absolute error of TEST against\n"
    "  REFERENCE (the numbers of stats.metrics), for images from anywhere (EXR, PNG, ...).\n"
    "  -o FILE        write the per-pixel error (luminance of |TEST - REFERENCE|) in false colour\n"
    "                 (viridis: dark = 0, yellow = the scale); PNG\n"
    "  --max E        the error the top of the scale stands for (default: the largest error)\n"
    "  --exposure EV  exposure of the tone map used by PSNR and SSIM (default 0)\n"
    "  --aov NAME     the EXR layer to read from both files (default beauty, or the file's first layer)\n"
    "  --json         print the metrics as one JSON object\n";

}  // namespace

int cmdCompare(const GlobalOptions&, const std::vector<std::string>& args) {
  std::vector<std::string> files;
  std::string out, aov = "beauty";
  double maxError = 0.0;
  float exposure = 0.f;
  bool asJson = false;
  auto need = [&](std::size_t& i) -> const std::string& {
    if (i + 1 >= args.size()) throw UsageError(args[i] + " needs a value\n" + kUsage);
    return args[++i];
  };
  auto number = [&](const std::string& flag, const std::string& v) {
    try {
      std::size_t used = 0;
      const double d = std::stod(v, &used);
      if (used != v.size() || !std::isfinite(d)) throw std::invalid_argument(v);
      return d;
    } catch (const std::exception&) {
      throw UsageError(flag + " needs a finite number, got '" + v + "'");
    }
  };
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "-o" || a == "--output") out = need(i);
    else if (a == "--max") maxError = number(a, need(i));
    else if (a == "--exposure") exposure = static_cast<float>(number(a, need(i)));
    else if (a == "--aov") aov = need(i);
    else if (a == "--json") asJson = true;
    else if (a == "-h" || a == "--help") { std::cout << kUsage; return 0; }
    else if (!a.empty() && a[0] == '-') throw UsageError("unknown option " + a + "\n" + kUsage);
    else files.push_back(a);
  }
  if (files.size() != 2) throw UsageError(std::string("compare needs two images\n") + kUsage);
  if (maxError < 0.0) throw UsageError("--max must be positive");
  Image test, reference;
  try {
    test = io::readImage(files[0], aov);
    reference = io::readImage(files[1], aov);
  } catch (const std::exception& e) {
    throw UsageError(std::string("cannot read the images: ") + e.what());
  }
  metrics::ImageMetrics m;
  Image error;
  try {
    m = metrics::compareImages(test, reference, exposure);
    error = metrics::errorMap(test, reference);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("the images cannot be compared: ") + e.what());
  }
  double usedMax = 0.0;
  if (!out.empty()) {
    Image colour = metrics::falseColour(error, maxError, &usedMax);
    for (float& v : colour.pixels) v = io::srgbToLinear(v);  // the PNG encoder applies the sRGB transfer
    io::writeFile(out, io::encodePng(colour, 0.f));
  }
  if (asJson) {
    nlohmann::json j{{"rmse", m.rmse}, {"rel_mse", m.relMse}, {"psnr", m.psnr ? nlohmann::json(*m.psnr) : nlohmann::json(nullptr)},
                     {"ssim", m.ssim}, {"mean_abs", m.meanAbs}, {"max_abs", m.maxAbs},
                     {"width", test.width}, {"height", test.height}};
    if (!out.empty()) j["error_image"] = {{"file", out}, {"scale_max", usedMax}};
    std::cout << j.dump() << "\n";
    return 0;
  }
  std::cout << "RMSE " << m.rmse << ", relMSE " << m.relMse << ", PSNR "
            << (m.psnr ? std::to_string(*m.psnr) + " dB" : std::string("inf (identical after tone mapping)"))
            << ", SSIM " << m.ssim << ", mean |d| " << m.meanAbs << ", max |d| " << m.maxAbs << " ("
            << test.width << "x" << test.height << ")\n";
  if (!out.empty()) std::cout << "wrote " << out << " (false colour, scale 0.." << usedMax << ")\n";
  return 0;
}

}  // namespace radiant::client
