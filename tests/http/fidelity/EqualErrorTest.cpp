// radiant bench --equal-error (issue 32) against the real radiantd on an ephemeral loopback port
// (llvmpipe): cornell_box at 16 px, a 64-spp truth and a 16/64/256-spp ladder, so the test stays within
// seconds. The reference's error against an independent truth is a / spp + b with b = the truth's own
// variance, which is the same estimator's per-sample variance a over the truth's spp: the fitted b must
// come out near a / 64. The table's structure and the record's arithmetic.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <sstream>

#include <nlohmann/json.hpp>

#include "tests/support/DaemonProcess.h"

using nlohmann::json;
namespace fs = std::filesystem;

namespace radiant {
namespace {

TEST(EqualErrorBench, TruthNoiseFitsTheEstimatorsVarianceAndTheSpeedUpIsTheTimeRatio) {
  const fs::path dir = testing::scratch("equal-error");
  testing::Daemon d(RADIANTD_PATH, {"--port", "0"}, {}, dir / "stderr.log");
  ASSERT_GT(d.port(), 0) << d.firstLine();
  ASSERT_TRUE(d.waitReady(std::chrono::seconds(60)));
  const testing::ProcessRun run = testing::runClient(
      RADIANT_CLIENT_PATH, d.url(), "bench --equal-error --scene cornell_box --size 16 --truth-spp 64 --ladder 16,64,256 -o out", dir);
  ASSERT_EQ(run.code, 0) << run.out << run.err;

  const std::string md = testing::slurp(dir / "out" / "equal_error.md");
  EXPECT_NE(run.out.find(md), std::string::npos) << "the table is printed as written";
  EXPECT_NE(md.find("| scene | default frame RMSE (own) | frame ms | truth noise | reference RMSE at 16, 64, 256 spp | "
                    "reference spp at equal error | its ms | speed-up |"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("| cornell_box | "), std::string::npos) << md;

  const json all = json::parse(testing::slurp(dir / "out" / "equal_error.json"));
  EXPECT_EQ(all["truth_spp"], 64);
  ASSERT_EQ(all["records"].size(), 1u);
  const json& r = all["records"][0];
  ASSERT_FALSE(r.contains("error")) << r.dump();
  const json& ref = r["reference"];
  ASSERT_EQ(ref.size(), 3u);
  // Each rung is closer to the truth than the one before (4x the samples).
  EXPECT_GT(ref[0]["rmse"].get<double>(), ref[1]["rmse"].get<double>());
  EXPECT_GT(ref[1]["rmse"].get<double>(), ref[2]["rmse"].get<double>());
  // b, the truth's noise, is the estimator's variance per sample (a) over the truth's 64 samples. Measured
  // 0.83-1.15 of it at 16 and 24 px with two truth and ladder choices.
  const double a = r["fit"]["a"].get<double>(), b = r["fit"]["b"].get<double>();
  ASSERT_GT(a, 0.0);
  EXPECT_GT(b / (a / 64.0), 0.5);
  EXPECT_LT(b / (a / 64.0), 2.0);
  // The fit passes near its three points (MSE within 20%).
  for (const json& p : ref) {
    const double mse = p["rmse"].get<double>() * p["rmse"].get<double>();
    EXPECT_NEAR(a / p["spp"].get<double>() + b, mse, 0.2 * mse) << p.dump();
  }
  // The record's arithmetic: the frame's own error is what is left after the truth's noise; the reference
  // reaches it at a / own samples; the speed-up is the ratio of the two times.
  const double frame = r["frame_rmse"].get<double>();
  EXPECT_NEAR(r["truth_noise_rmse"].get<double>(), std::sqrt(b), 1e-9);
  if (r["truth_limited"].get<bool>()) {
    EXPECT_LE(frame * frame, b);
  } else {
    const double own = frame * frame - b;
    EXPECT_NEAR(r["frame_own_rmse"].get<double>(), std::sqrt(own), 1e-9);
    EXPECT_NEAR(r["reference_spp_at_equal_error"].get<double>(), a / own, 1e-6 * a / own);
    EXPECT_NEAR(r["speed_up"].get<double>(),
                r["reference_ms_at_equal_error"].get<double>() / r["frame_ms"].get<double>(), 1e-9);
  }
}

}  // namespace
}  // namespace radiant
