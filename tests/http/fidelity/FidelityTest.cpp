// radiant bench --fidelity (issue 29) against the real radiantd on an ephemeral loopback port
// (llvmpipe): BoxTextured under chinese_garden_1k at 48 px with a reference of 16-spp seeds, so the
// test stays within seconds. The table's structure, the score against bounds computed from the frames
// themselves, the reference as the mean of its seeds (the client's tone map equal to the daemon's PNG,
// the seeds' count from the convergence rule), the contact sheet's size, and the reference cache on a
// second run.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <regex>
#include <sstream>

#include <nlohmann/json.hpp>

#include "renderer/io/ImageIO.h"
#include "renderer/metrics/Metrics.h"
#include "tests/support/DaemonProcess.h"

using nlohmann::json;
namespace fs = std::filesystem;

namespace radiant {
namespace {

constexpr int kSize = 48;
const std::string kModel = "BoxTextured", kMap = "chinese_garden_1k";

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

ImageRgba8 withAlphaOf(ImageRgba8 image, const ImageRgba8& source) {
  for (std::size_t p = 0; p < static_cast<std::size_t>(image.width) * image.height; ++p)
    image.pixels[p * 4 + 3] = source.pixels[p * 4 + 3];
  return image;
}

TEST(FidelityBench, OneModelOneMapTableScoresSheetAndCachedReference) {
  if (!fs::is_directory(fs::path(RADIANT_GLTF_SAMPLES_DIR) / kModel) ||
      !fs::exists(fs::path(RADIANT_ENVIRONMENTS_DIR) / (kMap + ".hdr")))
    GTEST_SKIP() << "no " << kModel << " in " << RADIANT_GLTF_SAMPLES_DIR << " or no " << kMap << ".hdr in "
                 << RADIANT_ENVIRONMENTS_DIR;
  const fs::path dir = testing::scratch("fidelity");
  testing::Daemon d(RADIANTD_PATH, {"--port", "0"}, {}, dir / "stderr.log");
  ASSERT_GT(d.port(), 0) << d.firstLine();
  ASSERT_TRUE(d.waitReady(std::chrono::seconds(60)));
  // --converged-db -100 is never met: the seeds double up to --max-spp (16 -> 2 seeds -> 4 seeds).
  const std::string common = "bench --fidelity --models '" + std::string(RADIANT_GLTF_SAMPLES_DIR) +
                             "' --environments '" + RADIANT_ENVIRONMENTS_DIR + "' --model " + kModel +
                             " --environment " + kMap + " --size " + std::to_string(kSize) + " --spp 16 -o out";
  const std::string args = common + " --max-spp 64 --converged-db -100";
  const testing::ProcessRun first = testing::runClient(RADIANT_CLIENT_PATH, d.url(), args, dir);
  ASSERT_EQ(first.code, 0) << first.out << first.err;

  // The table: a header, its rule and one row of 8 cells, as printed and as written.
  const std::string md = testing::slurp(dir / "out" / "fidelity.md");
  EXPECT_NE(first.out.find(md), std::string::npos);
  std::vector<std::string> table;
  for (const auto& l : lines(md))
    if (!l.empty() && l[0] == '|') table.push_back(l);
  ASSERT_EQ(table.size(), 3u) << md;
  EXPECT_EQ(table[0], "| model | environment | fidelity dB | relMSE | SSIM | default ms | reference spp | reference "
                      "noise dB |");
  std::smatch row;
  ASSERT_TRUE(std::regex_match(table[2], row,
                               std::regex(R"(\| BoxTextured \| chinese_garden_1k \| (-?[0-9.]+) \| ([0-9.]+) \| ([0-9.]+) \| )"
                                          R"(([0-9]+) \| 64 \| (-?[0-9.]+) \(not converged\) \|)")))
      << table[2];

  const json results = json::parse(testing::slurp(dir / "out" / "fidelity.json"));
  ASSERT_EQ(results["records"].size(), 1u);
  const json& r = results["records"][0];
  ASSERT_TRUE(r["fidelity_db"].is_number()) << r.dump();
  const double db = r["fidelity_db"].get<double>();
  EXPECT_NEAR(std::stod(row[1]), db, 0.05 + 1e-9);
  EXPECT_EQ(r["reference_cached"], false);
  EXPECT_GT(r["covered_pixels"].get<int>(), kSize * kSize / 10);  // the box fills much of the frame
  EXPECT_LT(r["covered_pixels"].get<int>(), kSize * kSize);       // and the background is transparent
  EXPECT_GT(r["ssim"].get<double>(), 0.0);
  // Four seeds (the rule never met), the noise estimate 3 dB under the halves' score, which a
  // 32-spp half against another lies well above the floor (-100) and below a black frame's (-5).
  EXPECT_EQ(r["reference_seeds"], 4);
  EXPECT_EQ(r["reference_spp"], 64);
  EXPECT_EQ(r["reference_converged"], false);
  ASSERT_TRUE(r["reference_halves_db"].is_number()) << r.dump();
  EXPECT_NEAR(r["reference_noise_db"].get<double>(), r["reference_halves_db"].get<double>() - 3.0103, 1e-3);
  EXPECT_LT(r["reference_halves_db"].get<double>(), -15.0);
  EXPECT_GT(r["reference_halves_db"].get<double>(), -60.0);

  // The seeds as the daemon wrote them: each PNG is the client's tone map of its linear EXR, code for
  // code (so the mean of the seeds is viewed as the daemon would write it), and the mean's EXR is
  // theirs averaged.
  std::vector<Image> seeds;
  for (const auto& e : fs::directory_iterator(dir / "out" / "fidelity" / "reference")) {
    if (e.path().extension() != ".json") continue;
    const fs::path base = e.path().parent_path() / e.path().stem();
    const Image linear = io::decodeImage(testing::slurp(base.string() + ".exr"), "reference");
    io::PngOptions aces;
    aces.toneMap = api::ToneMap::Aces;
    const ImageRgba8 daemons = io::decodePngRgba8(testing::slurp(base.string() + ".png"));
    const ImageRgba8 clients = io::decodePngRgba8(io::encodePng(linear, aces));
    ASSERT_EQ(daemons.pixels.size(), clients.pixels.size());
    int worst = 0;
    for (std::size_t i = 0; i < daemons.pixels.size(); ++i) worst = std::max(worst, std::abs(daemons.pixels[i] - clients.pixels[i]));
    EXPECT_EQ(worst, 0) << base;
    seeds.push_back(linear);
  }
  ASSERT_EQ(seeds.size(), 4u);
  std::vector<fs::path> means;
  for (const auto& e : fs::directory_iterator(dir / "out" / "fidelity" / "reference"))
    if (e.path().string().find(".mean4.exr") != std::string::npos) means.push_back(e.path());
  ASSERT_EQ(means.size(), 1u);
  const Image mean = io::decodeImage(testing::slurp(means[0]), "beauty");
  double worstMean = 0;
  for (std::size_t i = 0; i < mean.pixels.size(); ++i) {
    const std::size_t p = i / 3, c = i % 3;
    double sum = 0;
    for (const Image& s : seeds) sum += s.pixels[p * s.channels + c];
    worstMean = std::max(worstMean, std::abs(mean.pixels[i] - sum / 4.0) / std::max(1e-3, sum / 4.0));
  }
  EXPECT_LT(worstMean, 1e-5);

  // The score, recomputed here from the two frames the bench kept: the golden is the reference with the
  // default frame's alpha (the reference pass writes no coverage).
  const ImageRgba8 candidate = io::decodePngRgba8(testing::slurp(dir / "out" / "fidelity" / (kModel + "." + kMap + ".default.png")));
  const ImageRgba8 golden = withAlphaOf(
      io::decodePngRgba8(testing::slurp(dir / "out" / "fidelity" / (kModel + "." + kMap + ".reference.png"))), candidate);
  ASSERT_EQ(candidate.width, kSize);
  const metrics::FidelityScore again = metrics::renderFidelity(candidate, golden);
  EXPECT_NEAR(*again.decibels, db, 1e-9);
  EXPECT_EQ(again.covered, r["covered_pixels"].get<std::size_t>());
  // The floor: a frame scored against itself is -100 dB, not -inf.
  EXPECT_EQ(*metrics::renderFidelity(golden, golden).decibels, metrics::kFidelityFloorDb);
  // The bound: a black frame over the same pixels (what issue 29 saw for DamagedHelmet) scores about
  // -5 dB against this box (delta = 0.5053 Y^2 for luma Y ~ 150 of 255); the default frame must have
  // at most a quarter of its RMS colour difference (6 dB less). The frame's own reference at 32 spp
  // is noisy, which only raises the score, so this holds with margin (about -24 dB at 64 px).
  ImageRgba8 black = candidate;
  for (std::size_t p = 0; p < black.pixels.size(); p += 4) black.pixels[p] = black.pixels[p + 1] = black.pixels[p + 2] = 0;
  const double blackDb = *metrics::renderFidelity(black, golden).decibels;
  EXPECT_GT(blackDb, -9.0);
  EXPECT_LT(db, blackDb - 6.0) << "black frame " << blackDb << " dB";
  EXPECT_TRUE(std::isfinite(db));

  // The contact sheet: default | reference | error, each kSize wide, 2 px apart; opaque RGB.
  const ImageRgba8 sheet = io::decodePngRgba8(testing::slurp(r["contact_sheet"].get<std::string>().front() == '/'
                                                                 ? fs::path(r["contact_sheet"].get<std::string>())
                                                                 : dir / r["contact_sheet"].get<std::string>()));
  EXPECT_EQ(sheet.width, 3 * kSize + 4);
  EXPECT_EQ(sheet.height, kSize);

  // Second run: the reference comes from the cache (no new render), the score is the same frame's.
  const testing::ProcessRun second = testing::runClient(RADIANT_CLIENT_PATH, d.url(), args, dir);
  ASSERT_EQ(second.code, 0) << second.out << second.err;
  const json again2 = json::parse(testing::slurp(dir / "out" / "fidelity.json"))["records"][0];
  EXPECT_EQ(again2["reference_cached"], true);
  EXPECT_NEAR(again2["fidelity_db"].get<double>(), db, 0.05);

  // A rule met at the first pair stops there: two cached seeds, converged; one seed (--max-spp equal to
  // --spp) has no estimate.
  const testing::ProcessRun pair = testing::runClient(RADIANT_CLIENT_PATH, d.url(), common + " --converged-db 0", dir);
  ASSERT_EQ(pair.code, 0) << pair.out << pair.err;
  const json two = json::parse(testing::slurp(dir / "out" / "fidelity.json"))["records"][0];
  EXPECT_EQ(two["reference_seeds"], 2);
  EXPECT_EQ(two["reference_converged"], true);
  EXPECT_EQ(two["reference_cached"], true);
  const testing::ProcessRun one = testing::runClient(RADIANT_CLIENT_PATH, d.url(), common + " --max-spp 16", dir);
  ASSERT_EQ(one.code, 0) << one.out << one.err;
  const json single = json::parse(testing::slurp(dir / "out" / "fidelity.json"))["records"][0];
  EXPECT_EQ(single["reference_seeds"], 1);
  EXPECT_TRUE(single["reference_noise_db"].is_null());
  EXPECT_NE(testing::slurp(dir / "out" / "fidelity.md").find("| 16 | n/a |"), std::string::npos);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace radiant
