// radiant compare A B [-o diff.png] [--max E] [--exposure EV] [--aov NAME] [--json]: the metrics the
// service reports (renderer/metrics) for two images from anywhere (EXR, PNG, anything OpenImageIO reads),
// and a false-colour picture of the per-pixel error. B is the reference.
#include <iostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "client/Cli.h"
#include "renderer/io/ImageIO.h"
#include "renderer/metrics/Metrics.h"

namespace radiant::client {
namespace {

struct CompareOptions {
  std::vector<std::string> files;
  std::string out, aov = "beauty";
  double maxError = 0.0, exposure = 0.0;
  bool asJson = false;
};

int runCompare(const CompareOptions& o) {
  const auto& files = o.files;
  const std::string& out = o.out;
  const double maxError = o.maxError;
  const float exposure = static_cast<float>(o.exposure);
  const bool asJson = o.asJson;
  const std::string& aov = o.aov;
  if (files.size() != 2) throw UsageError("compare needs two images");
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

}  // namespace

void addCompareCommand(CLI::App& root, const GlobalOptions&, Action& action) {
  auto o = std::make_shared<CompareOptions>();
  CLI::App* c = root.add_subcommand("compare", "metrics and a false-colour error image of two images from anywhere");
  c->footer(
      "Prints RMSE, relMSE, PSNR (dB, tone-mapped), SSIM, mean and max absolute error of TEST against\n"
      "REFERENCE (the numbers of stats.metrics), for images from anywhere (EXR, PNG, ...). Needs no server.");
  c->add_option("images", o->files, "TEST then REFERENCE")->type_name("TEST REFERENCE")->expected(2);
  c->add_option("-o,--output", o->out,
                "write the per-pixel error (luminance of |TEST - REFERENCE|) in false colour (viridis: dark = 0, "
                "yellow = the scale); PNG")
      ->type_name("error.png");
  c->add_option("--max", o->maxError, "the error the top of the scale stands for (default: the largest error)")
      ->type_name("E")
      ->check(CLI::NonNegativeNumber);
  c->add_option("--exposure", o->exposure, "exposure of the tone map used by PSNR and SSIM (default 0)")->type_name("EV");
  c->add_option("--aov", o->aov, "the EXR layer to read from both files (default beauty, or the file's first layer)")
      ->type_name("NAME");
  c->add_flag("--json", o->asJson, "print the metrics as one JSON object");
  c->callback([&action, o] { action = [o] { return runCompare(*o); }; });
}

}  // namespace radiant::client
