// `radiant compare` and the image reader it stands on: layers picked by name, the service's metrics on
// two files, and the false-colour error picture.
#include <gtest/gtest.h>

#include <filesystem>

#include <unistd.h>

#include <glm/glm.hpp>

#include <nlohmann/json.hpp>

#include "client/Cli.h"
#include "renderer/io/ImageIO.h"
#include "renderer/metrics/Metrics.h"

namespace radiant {
namespace {

namespace fs = std::filesystem;

// A command line through the CLI's one definition, run in this process.
int runCommand(const std::vector<std::string>& args) {
  client::GlobalOptions g;
  return client::parseCommandLine(g, args)();
}

Image constant(const std::string& aov, int w, int h, glm::vec3 v) {
  Image img = Image::make(aov, w, h, 3);
  for (int i = 0; i < w * h; ++i)
    for (int c = 0; c < 3; ++c) img.pixels[static_cast<std::size_t>(i) * 3 + c] = v[c];
  return img;
}

fs::path tempDir() {
  fs::path d = fs::temp_directory_path() / ("radiant-compare-" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}

TEST(ReadImage, PicksLayersByNameNotByPosition) {
  // EXR keeps channels in alphabetical order (B, G, R): reading by position would swap red and blue.
  const fs::path dir = tempDir();
  const std::string two = (dir / "two.exr").string(), one = (dir / "one.exr").string();
  io::writeFile(two, io::encodeExr({constant("beauty", 4, 2, {1, 2, 3}), constant("reference", 4, 2, {4, 5, 6})}, false));
  io::writeFile(one, io::encodeExr({constant("reference", 4, 2, {4, 5, 6})}, false));
  const Image b = io::readImage(two, "beauty"), r = io::readImage(two, "reference"), only = io::readImage(one);
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(b.at(3, 1)[c], 1.f + c);
    EXPECT_EQ(r.at(3, 1)[c], 4.f + c);
    EXPECT_EQ(only.at(0, 0)[c], 4.f + c);  // a file with one layer: that layer, whatever its name
  }
  EXPECT_THROW(io::readImage(two, "depth"), std::runtime_error);
}

TEST(Compare, PrintsTheServiceMetricsAndWritesTheFalseColourError) {
  const fs::path dir = tempDir();
  const std::string a = (dir / "a.exr").string(), b = (dir / "b.exr").string(), png = (dir / "err.png").string();
  io::writeFile(a, io::encodeExr({constant("beauty", 8, 4, glm::vec3(1.1f))}, false));
  io::writeFile(b, io::encodeExr({constant("beauty", 8, 4, glm::vec3(1.0f))}, false));
  ::testing::internal::CaptureStdout();
  EXPECT_EQ(runCommand({"compare", a, b, "-o", png, "--json"}), 0);
  const nlohmann::json j = nlohmann::json::parse(::testing::internal::GetCapturedStdout());
  EXPECT_NEAR(j["rmse"].get<double>(), 0.1, 1e-5);
  EXPECT_NEAR(j["mean_abs"].get<double>(), 0.1, 1e-5);
  EXPECT_NEAR(j["error_image"]["scale_max"].get<double>(), 0.1, 1e-5);
  // Every pixel has the largest error: the top of viridis, (0.993, 0.906, 0.144) in display sRGB.
  const Image e = io::readImage(png);
  ASSERT_EQ(e.width, 8);
  ASSERT_EQ(e.height, 4);
  EXPECT_NEAR(e.at(5, 2)[0], 0.993f, 2.f / 255);
  EXPECT_NEAR(e.at(5, 2)[1], 0.906f, 2.f / 255);
  EXPECT_NEAR(e.at(5, 2)[2], 0.144f, 2.f / 255);
  // A scale twice the error puts it in the middle of the map.
  const Image half = metrics::falseColour(metrics::errorMap(io::readImage(a), io::readImage(b)), 0.2);
  EXPECT_NEAR(half.at(0, 0)[1], 0.567f, 0.01f);
  // Images of different sizes are a usage error, not a crash.
  const std::string small = (dir / "small.exr").string();
  io::writeFile(small, io::encodeExr({constant("beauty", 2, 2, glm::vec3(1.f))}, false));
  EXPECT_THROW(runCommand({"compare", a, small}), client::UsageError);
  EXPECT_THROW(runCommand({"compare", a}), client::UsageError);
}

}  // namespace
}  // namespace radiant
