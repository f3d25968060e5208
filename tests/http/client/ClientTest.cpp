// The real `radiant` client against the real radiantd (llvmpipe) on an ephemeral loopback port:
// - `render` writes every output of a multi-output request (-o repeated, --out-dir), and each file
//   holds exactly the AOV it names, compared pixel by pixel with the same AOV of a multi-layer EXR;
// - a render (synchronous or --async) that lasts more than a second draws a bar with an ETA on a
//   pseudo-terminal (`script` gives it one), and prints plain lines when stderr is a file.
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>

#include <glm/gtc/type_ptr.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "renderer/io/ImageIO.h"
#include "renderer/io/ToneMap.h"
#include "tests/support/DaemonProcess.h"
#include "tests/support/ImageDifference.h"

namespace radiant {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

using testing::maxAbsDifference;
using testing::ProcessRun;

ProcessRun client(const std::string& server, const std::string& args, const fs::path& dir) {
  return testing::runClient(RADIANT_CLIENT_PATH, server, args, dir);
}

double maxValue(const Image& a) {
  double m = 0;
  for (float v : a.pixels) m = std::max(m, double(v));
  return m;
}

class ClientHttp : public ::testing::Test {
protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(testing::scratch("client-http"));
    daemon_ = new testing::Daemon(RADIANTD_PATH, {"--port", "0"}, {}, *dir_ / "daemon.log");
    ASSERT_GT(daemon_->port(), 0) << daemon_->firstLine();
    ASSERT_TRUE(daemon_->waitReady(std::chrono::seconds(120)));
  }
  static void TearDownTestSuite() {
    delete daemon_;
    fs::remove_all(*dir_);
    delete dir_;
  }
  static fs::path* dir_;
  static testing::Daemon* daemon_;
};
fs::path* ClientHttp::dir_ = nullptr;
testing::Daemon* ClientHttp::daemon_ = nullptr;

TEST_F(ClientHttp, RenderWritesEveryOutputOfAMultiOutputRequest) {
  const fs::path& d = *dir_;
  // One request, five outputs: --out-dir names each file after its AOVs.
  const json request{{"scene", {{"builtin", "cornell_box"}}},
                     {"width", 32},
                     {"height", 32},
                     {"outputs",
                      {{{"format", "exr"}, {"aovs", {"beauty", "albedo", "normal"}}, {"half", false}},
                       {{"format", "exr"}, {"aovs", {"beauty"}}, {"half", false}},
                       {{"format", "exr"}, {"aovs", {"albedo"}}, {"half", false}},
                       {{"format", "png"}, {"aovs", {"beauty"}}},
                       {{"format", "exr"}, {"aovs", {"normal"}}}}}};
  std::ofstream(d / "multi.json") << request.dump();
  ProcessRun r = client(daemon_->url(), "render --request multi.json --out-dir out --stats stats.json", d);
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* f : {"beauty+albedo+normal.exr", "beauty.exr", "albedo.exr", "beauty.png", "normal.exr"}) {
    EXPECT_TRUE(fs::exists(d / "out" / f)) << f;
    EXPECT_NE(r.out.find("wrote out/" + std::string(f)), std::string::npos) << r.out;
  }
  const json stats = json::parse(testing::slurp(d / "stats.json"));
  ASSERT_EQ(stats["frames"].size(), 5u);
  EXPECT_EQ(stats["request"]["outputs"], request["outputs"]) << "the request's own outputs are sent as they are";

  const fs::path all = d / "out" / "beauty+albedo+normal.exr";
  const Image beauty = io::readImage(all.string(), "beauty"), albedo = io::readImage(all.string(), "albedo"),
              normal = io::readImage(all.string(), "normal");
  ASSERT_GT(maxValue(beauty), 0.05) << "the Cornell box is lit";
  ASSERT_GT(maxValue(albedo), 0.05);
  // The same render, so float files match exactly; the half normal within half's rounding (2^-11 relative, |n| <= 1).
  EXPECT_EQ(maxAbsDifference(io::readImage((d / "out" / "beauty.exr").string(), "beauty"), beauty), 0.0);
  EXPECT_EQ(maxAbsDifference(io::readImage((d / "out" / "albedo.exr").string(), "albedo"), albedo), 0.0);
  EXPECT_LE(maxAbsDifference(io::readImage((d / "out" / "normal.exr").string(), "normal"), normal), 1.0 / 2048);
  // The PNG is sRGB(aces(beauty)) (docs/API.md: exposure 0, the default tone_map) to 8 bits: within half a
  // step, plus slack for rounding.
  const Image png = io::readImage((d / "out" / "beauty.png").string());
  Image expected = beauty;
  for (std::size_t i = 0; i + 2 < expected.pixels.size(); i += 3) {
    const glm::vec3 display = io::toneMap(api::ToneMap::Aces, glm::make_vec3(&beauty.pixels[i]), 0.f);
    for (int c = 0; c < 3; ++c) expected.pixels[i + c] = io::linearToSrgb(display[c]);
  }
  EXPECT_LE(maxAbsDifference(png, expected), 0.5 / 255 + 1e-4);
  // Each single-AOV file holds that AOV only.
  EXPECT_THROW(io::readImage((d / "out" / "albedo.exr").string(), "normal"), std::runtime_error);

  // -o repeated with as many --aov: file i holds AOV i (G-buffer AOVs are rasterised, so another
  // request gives the same pixels).
  r = client(daemon_->url(), "render --builtin cornell_box --size 32x32 --float -o a.exr -o n.exr --aov albedo --aov normal", d);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(maxAbsDifference(io::readImage((d / "a.exr").string(), "albedo"), albedo), 0.0);
  EXPECT_EQ(maxAbsDifference(io::readImage((d / "n.exr").string(), "normal"), normal), 0.0);
  EXPECT_THROW(io::readImage((d / "a.exr").string(), "normal"), std::runtime_error);
  // --out-dir with --aov: one file per AOV in --format.
  r = client(daemon_->url(), "render --builtin cornell_box --size 32x32 --out-dir aovs --aov albedo --aov normal --format exr --float", d);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(maxAbsDifference(io::readImage((d / "aovs" / "albedo.exr").string(), "albedo"), albedo), 0.0);
  EXPECT_EQ(maxAbsDifference(io::readImage((d / "aovs" / "normal.exr").string(), "normal"), normal), 0.0);

  // Usage errors before anything is sent.
  EXPECT_EQ(client(daemon_->url(), "render --builtin cornell_box -o a.exr -o b.exr --aov beauty", d).code, 2);
  EXPECT_EQ(client(daemon_->url(), "render --builtin cornell_box -o a.exr --out-dir x", d).code, 2);
  EXPECT_EQ(client(daemon_->url(), "render --request multi.json -o a.exr -o b.exr", d).code, 2) << "5 outputs, 2 files";
}

// A reference render long enough to show progress, which starts after 1 s: several seconds on
// llvmpipe even on a quiet machine (at 48x48 and 500 spp the second run took under a second in CI).
// The daemon caches a reference by its sample count among other things, so each run asks for another.
// Without --async the client submits an async job under the hood and polls it the same way, keeping the
// synchronous semantics (the request it reports, --stats, is still synchronous).
std::string slowRender(int spp, bool async) {
  return "render --builtin cornell_box --size 64x64 --pass reference --aov reference --set reference.spp=" +
         std::to_string(spp) + " -o slow.exr --stats slow.json" + (async ? " --async" : "");
}

TEST_F(ClientHttp, ProgressBarOnAPseudoTerminalAndPlainLinesWithout) {
  const fs::path& d = *dir_;
  // `script` runs the client on a new pseudo-terminal and copies what it draws to stdout.
  // A synchronous render (no --async) on the terminal.
  const std::string inner = "RADIANT_SERVER='" + daemon_->url() + "' '" RADIANT_CLIENT_PATH "' " + slowRender(1536, false);
  const std::string cmd = "cd '" + d.string() + "' && script -q -e -c \"" + inner + "\" /dev/null > tty.txt 2>&1";
  const int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << testing::slurp(d / "tty.txt");
  const std::string tty = testing::slurp(d / "tty.txt");
  // The bar is redrawn in place (carriage returns), with a percentage and, once under way, the time left.
  EXPECT_TRUE(std::regex_search(tty, std::regex(R"(\r[^\r\n]*: running \[#*\.*\] \d+%)"))) << tty;
  EXPECT_TRUE(std::regex_search(tty, std::regex(R"(\[#+\.*\] \d+% ETA \d+ s)"))) << tty;
  EXPECT_NE(tty.find(": done 100%"), std::string::npos) << tty;
  EXPECT_TRUE(fs::exists(d / "slow.exr"));
  EXPECT_EQ(json::parse(testing::slurp(d / "slow.json"))["request"]["async"], false) << "still a synchronous render";
  EXPECT_NE(tty.find("wrote slow.exr"), std::string::npos) << tty;

  // Without a terminal: whole lines, no carriage returns; synchronous and async alike.
  for (const bool async : {false, true}) {
    const ProcessRun r = client(daemon_->url(), slowRender(async ? 1500 : 1520, async), d);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(r.err.find('\r'), std::string::npos) << r.err;
    std::smatch m;
    EXPECT_TRUE(std::regex_search(r.err, m, std::regex(R"((^|\n)r-[^\n]*: running \d+%( ETA \d+ s)?\n)"))) << async << r.err;
    EXPECT_NE(r.err.find(": done 100%\n"), std::string::npos) << r.err;
    EXPECT_NE(r.out.find("wrote slow.exr"), std::string::npos) << r.out;
    EXPECT_EQ(json::parse(testing::slurp(d / "slow.json"))["request"]["async"], async);
  }
  // --quiet: a plain synchronous request, nothing on stderr.
  const ProcessRun q = client(daemon_->url(), "render --builtin cornell_box --size 16x16 -o quiet.exr -q", d);
  ASSERT_EQ(q.code, 0) << q.err;
  EXPECT_EQ(q.err, "");
  EXPECT_TRUE(fs::exists(d / "quiet.exr"));
}

}  // namespace
}  // namespace radiant
