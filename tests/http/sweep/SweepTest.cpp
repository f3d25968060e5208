// radiant sweep / report against the real radiantd on ephemeral loopback ports (llvmpipe), and the
// report of a fixed results file (tests/data/sweep_results.jsonl).
#include <gtest/gtest.h>

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <thread>

#include <httplib.h>
#include <nlohmann/json.hpp>

#include "api/Base64.h"
#include "renderer/io/ImageIO.h"
#include "renderer/metrics/Metrics.h"
#include "tests/support/ImageDifference.h"

using nlohmann::json;
namespace fs = std::filesystem;

namespace {

fs::path scratch(const std::string& name) {
  auto dir = fs::temp_directory_path() / ("radiant-sweep-" + name + "-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), {});
}

std::vector<std::string> lines(const fs::path& p) {
  std::vector<std::string> out;
  std::istringstream in(slurp(p));
  std::string l;
  while (std::getline(in, l))
    if (!l.empty()) out.push_back(l);
  return out;
}

std::vector<json> records(const fs::path& p) {
  std::vector<json> out;
  for (const auto& l : lines(p)) {
    json j = json::parse(l, nullptr, false);
    EXPECT_FALSE(j.is_discarded()) << "not a JSON line: " << l;
    out.push_back(j);
  }
  return out;
}

pid_t spawn(const std::vector<std::string>& argv, const fs::path& stdoutFile, const fs::path& stderrFile, int* outPipe,
            const std::vector<std::string>& env = {}) {
  int p[2] = {-1, -1};
  if (outPipe && pipe(p) != 0) throw std::runtime_error("pipe");
  const pid_t pid = fork();
  if (pid == 0) {
    if (outPipe) {
      dup2(p[1], STDOUT_FILENO);
      close(p[0]);
    } else {
      int fd = open(stdoutFile.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      dup2(fd, STDOUT_FILENO);
    }
    int fd = open(stderrFile.empty() ? "/dev/null" : stderrFile.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(fd, STDERR_FILENO);
    for (const auto& e : env) putenv(const_cast<char*>(e.c_str()));
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    execv(args[0], args.data());
    _exit(127);
  }
  if (outPipe) {
    close(p[1]);
    *outPipe = p[0];
  }
  return pid;
}

int waitExit(pid_t pid, std::chrono::seconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < end) {
    int status = 0;
    if (waitpid(pid, &status, WNOHANG) == pid) return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  kill(pid, SIGKILL);
  waitpid(pid, nullptr, 0);
  return -1;
}

// The real radiantd on an ephemeral port; the port comes from its first stdout line.
class Daemon {
public:
  explicit Daemon(const fs::path& log) {
    int out = -1;
    pid_ = spawn({RADIANTD_PATH, "--port", "0"}, {}, log, &out);
    std::string line;
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (line.find('\n') == std::string::npos && std::chrono::steady_clock::now() < end) {
      pollfd p{out, POLLIN, 0};
      if (poll(&p, 1, 100) > 0) {
        char buf[256];
        const ssize_t n = read(out, buf, sizeof buf);
        if (n <= 0) break;
        line.append(buf, static_cast<std::size_t>(n));
      }
    }
    close(out);
    std::smatch m;
    const std::string first = line.substr(0, line.find('\n'));
    if (std::regex_match(first, m, std::regex(R"(radiantd listening on (http://127\.0\.0\.1:(\d+)))"))) {
      url_ = m[1];
      port_ = std::stoi(m[2]);
    }
  }
  ~Daemon() { kill(); }
  void kill() {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
      pid_ = -1;
    }
  }
  bool ready() const {
    httplib::Client c("127.0.0.1", port_);
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (std::chrono::steady_clock::now() < end) {
      auto r = c.Get("/v1/ready");
      if (r && r->status == 200) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    return false;
  }
  // radiant_renders_total{result="done"} from /metrics.
  int rendersDone() const {
    httplib::Client c("127.0.0.1", port_);
    auto r = c.Get("/metrics");
    if (!r) return -1;
    std::smatch m;
    if (std::regex_search(r->body, m, std::regex(R"(radiant_renders_total\{result="done"\} (\d+))"))) return std::stoi(m[1]);
    return 0;
  }
  const std::string& url() const { return url_; }
  int port() const { return port_; }
  // GET /v1/info's device (whatever GL device this machine has: llvmpipe here, a GPU elsewhere).
  json device() const {
    httplib::Client c("127.0.0.1", port_);
    auto r = c.Get("/v1/info");
    return r ? json::parse(r->body, nullptr, false).value("device", json()) : json();
  }

private:
  pid_t pid_ = -1;
  int port_ = 0;
  std::string url_;
};

struct ProcResult {
  int code = -1;
  std::string out, err;
};

ProcResult runRadiant(const fs::path& dir, const std::vector<std::string>& args, std::chrono::seconds timeout = std::chrono::seconds(80)) {
  std::vector<std::string> argv{RADIANT_CLIENT_PATH};
  argv.insert(argv.end(), args.begin(), args.end());
  const pid_t pid = spawn(argv, dir / "client.out", dir / "client.err", nullptr);
  ProcResult r;
  r.code = waitExit(pid, timeout);
  r.out = slurp(dir / "client.out");
  r.err = slurp(dir / "client.err");
  return r;
}

// A small AO sweep: methods x samples at 32x32 on ao_creases, compared against the reference AO.
json aoSpec(const json& methods, const json& samples, int repeats = 2) {
  return {{"name", "ao-test"},
          {"base",
           {{"scene", {{"builtin", "ao_creases"}}},
            {"width", 32},
            {"height", 32},
            {"ambient", {1, 1, 1}},
            {"passes", {{"ambient_occlusion", json::object()}}}}},
          {"axes", {{"passes.ambient_occlusion.method", methods}, {"passes.ambient_occlusion.samples", samples}}},
          {"repeats", repeats},
          {"warmup", 1},
          {"compare", {{"aov", "ao"}, {"spp", 4}}}};
}

// Slow points (a path-traced reference pass per render) for the tests that stop a sweep midway.
json slowSpec(int points) {
  json seeds = json::array();
  for (int i = 0; i < points; ++i) seeds.push_back(i + 1);
  return {{"name", "slow"},
          {"base",
           {{"scene", {{"builtin", "cornell_box"}}},
            {"width", 64},
            {"height", 64},
            {"passes", {{"reference", {{"spp", 24}, {"max_bounces", 4}}}, {"photon_gi", false}}}}},
          {"axes", {{"seed", seeds}}},
          {"repeats", 2},
          {"warmup", 0}};
}

void writeJson(const fs::path& p, const json& j) { std::ofstream(p) << j.dump(2); }

}  // namespace

class SweepAgainstDaemon : public ::testing::Test {
protected:
  static void SetUpTestSuite() {
    logDir_ = scratch("daemon");
    daemon_ = new Daemon(logDir_ / "radiantd.log");
    ASSERT_FALSE(daemon_->url().empty()) << slurp(logDir_ / "radiantd.log");
    ASSERT_TRUE(daemon_->ready()) << slurp(logDir_ / "radiantd.log");
  }
  static void TearDownTestSuite() {
    delete daemon_;
    daemon_ = nullptr;
    fs::remove_all(logDir_);
  }
  static Daemon* daemon_;
  static fs::path logDir_;
};
Daemon* SweepAgainstDaemon::daemon_ = nullptr;
fs::path SweepAgainstDaemon::logDir_;

TEST_F(SweepAgainstDaemon, TwoByTwoGivesFourRecordsWithTheirParametersAndTimings) {
  const auto dir = scratch("2x2");
  writeJson(dir / "spec.json", aoSpec({"volumetric", "gtao"}, {4, 8}));
  const int rendersBefore = daemon_->rendersDone();
  ProcResult r = runRadiant(dir, {"--server", daemon_->url(), "sweep", (dir / "spec.json").string(), "-o", (dir / "r.jsonl").string()});
  ASSERT_EQ(r.code, 0) << r.err;
  // 4 points x (1 warm-up carrying compare + 2 timed repeats).
  EXPECT_EQ(daemon_->rendersDone() - rendersBefore, 12);
  const auto recs = records(dir / "r.jsonl");
  ASSERT_EQ(recs.size(), 4u);
  std::set<std::pair<std::string, int>> seen;
  for (const auto& rec : recs) {
    const std::string method = rec["params"]["passes.ambient_occlusion.method"];
    const int samples = rec["params"]["passes.ambient_occlusion.samples"];
    seen.insert({method, samples});
    // The parameters were sent.
    EXPECT_EQ(rec["request"]["passes"]["ambient_occlusion"]["method"], method);
    EXPECT_EQ(rec["request"]["passes"]["ambient_occlusion"]["samples"], samples);
    EXPECT_EQ(rec["technique"], "ambient_occlusion");
    EXPECT_EQ(rec["method"], method);
    EXPECT_EQ(rec["sweep"], "ao-test");
    EXPECT_EQ(rec["repeats"], 2);
    EXPECT_EQ(rec["server"], daemon_->url());
    EXPECT_EQ(rec["point_id"].get<std::string>().size(), 16u);
    // Non-empty timings: every pass has median/min/max over the 2 repeats, in order.
    ASSERT_FALSE(rec["passes"].empty()) << rec.dump();
    bool sawAo = false;
    double sum = 0;
    for (const auto& p : rec["passes"]) {
      EXPECT_EQ(p["gpu_ms"]["n"], 2);
      EXPECT_LE(p["gpu_ms"]["min"].get<double>(), p["gpu_ms"]["median"].get<double>());
      EXPECT_LE(p["gpu_ms"]["median"].get<double>(), p["gpu_ms"]["max"].get<double>());
      if (p["name"] == "ambient_occlusion") {
        sawAo = true;
        EXPECT_GT(p["gpu_ms"]["median"].get<double>(), 0.0);
        EXPECT_EQ(p["counters"]["samples"].get<double>(), samples);
      }
      sum += p["gpu_ms"]["median"].get<double>();
      // Each pass's prepare() too (stats.passes[].prepare_ms): over the same repeats, and within the
      // frame's sum of them (each repeat's sum holds every pass's own term).
      EXPECT_EQ(p["prepare_ms"]["n"], 2) << p.dump();
      EXPECT_GE(p["prepare_ms"]["min"].get<double>(), 0.0);
      EXPECT_LE(p["prepare_ms"]["min"].get<double>(), p["prepare_ms"]["max"].get<double>());
      EXPECT_GE(rec["frame_prepare_ms"]["max"].get<double>(), p["prepare_ms"]["min"].get<double>()) << p["name"];
    }
    EXPECT_TRUE(sawAo) << rec["passes"].dump();
    EXPECT_EQ(rec["frame_prepare_ms"]["n"], 2);
    EXPECT_GT(rec["frame_gpu_ms"]["median"].get<double>(), 0.0);
    EXPECT_EQ(rec["latency_ms"]["n"], 2);
    EXPECT_GT(rec["latency_ms"]["min"].get<double>(), 0.0);
    // End to end includes the render.
    EXPECT_GE(rec["latency_ms"]["median"].get<double>(), rec["render_ms"]["min"].get<double>() * 0.5);
    // Error metrics from the compare run, and the device.
    ASSERT_TRUE(rec["metrics"].is_object()) << rec.dump();
    EXPECT_EQ(rec["metrics"]["aov"], "ao");
    EXPECT_GT(rec["metrics"]["rmse"].get<double>(), 0.0);
    EXPECT_LT(rec["metrics"]["rmse"].get<double>(), 1.0);
    // The device the daemon rendered on (any GL device: the suite must hold on a GPU too).
    EXPECT_EQ(rec["device"]["renderer"], daemon_->device()["renderer"]) << rec["device"].dump();
    EXPECT_FALSE(rec["device"]["renderer"].get<std::string>().empty());
    // The preset table's scene variables (stats.scene.counts), which bench/presets.py fits against:
    // ao_creases has no particles and no metal or glass (no beams, no specular objects); photon_gi's
    // gather block at 32 x 32 px and the default supersampling 4 is 4 x 2 samples (api::photonGatherBlock).
    EXPECT_EQ(rec["scene_counts"], (json{{"particles", 0.0}, {"beams", 0.0}, {"specular_objects", 0.0},
                                         {"photon_gather_block", 8.0}}))
        << rec.dump();
    (void)sum;
  }
  EXPECT_EQ(seen, (std::set<std::pair<std::string, int>>{{"volumetric", 4}, {"volumetric", 8}, {"gtao", 4}, {"gtao", 8}}));
  // The CSV view: a header and one row per point.
  const auto csv = lines(dir / "r.csv");
  ASSERT_EQ(csv.size(), 5u);
  EXPECT_EQ(csv[0].rfind("point_id,sweep,technique,method,status,", 0), 0u) << csv[0];
  EXPECT_NE(csv[0].find("passes.ambient_occlusion.samples"), std::string::npos);
  EXPECT_NE(csv[0].find(",frame_prepare_ms_median,"), std::string::npos) << csv[0];
  EXPECT_NE(csv[0].find(",cpu_ms.ambient_occlusion,prepare_ms.ambient_occlusion,"), std::string::npos) << csv[0];
  fs::remove_all(dir);
}

// What scores each technique lives with the technique on the server (Technique::groundTruth): /v1/info
// serves it, the bench presets read it from there, and compare renders it with the frame's parameters.
TEST_F(SweepAgainstDaemon, BenchScoresEachTechniqueOnTheGroundTruthsInfoServes) {
  httplib::Client c(daemon_->url());
  c.set_read_timeout(120, 0);  // the render below compiles shaders and path-traces on a loaded machine
  auto res = c.Get("/v1/info");
  ASSERT_TRUE(res && res->status == 200);
  const json info = json::parse(res->body);
  std::map<std::string, json> truths;
  for (const auto& t : info["techniques"])
    if (t.value("available", false)) truths[t["name"]] = t.value("ground_truths", json());
  // At the techniques' default parameters (ambient_occlusion: radius 0.5, method volumetric;
  // env_diffuse: bounces 1, so bounces 2..2).
  EXPECT_EQ(truths["ambient_occlusion"]["ao"],
            (json{{"aov", "ao"}, {"ao_radius", 0.5}, {"ao_definition", "volumetric"}}));
  EXPECT_EQ(truths["env_diffuse"]["indirect_diffuse"], (json{{"aov", "indirect"}, {"max_bounces", 2}}));
  EXPECT_EQ(truths["direct"]["direct"], (json{{"aov", "direct"}}));
  EXPECT_EQ(truths["caustics"]["caustics"], (json{{"aov", "caustics"}}));
  ASSERT_TRUE(truths["specular"].contains("specular"));
  EXPECT_TRUE(truths["specular"]["specular"].is_null());  // the reference has no specular-only mode

  const auto dir = scratch("bench-spec");
  ProcResult r = runRadiant(dir, {"--server", daemon_->url(), "bench", "--quick", "--dry-run", "-o", (dir / "b").string()});
  ASSERT_EQ(r.code, 0) << r.err;
  std::ifstream in(dir / "b" / "bench.spec.json");
  const json spec = json::parse(in);
  std::map<std::string, json> compare, sweepOf;
  for (const auto& s : spec["sweeps"]) compare[s["technique"]] = s["compare"], sweepOf[s["technique"]] = s;
  // The axes and request fields come from each descriptor's "bench" through /v1/info (--quick values).
  EXPECT_EQ(sweepOf["ambient_occlusion"]["axes"]["passes.ambient_occlusion.method"],
            (json{"volumetric", "containment", "crytek", "gtao"}));
  EXPECT_EQ(sweepOf["ambient_occlusion"]["axes"]["passes.ambient_occlusion.samples"], (json{8}));
  EXPECT_EQ(sweepOf["ambient_occlusion"]["base"]["ambient"], (json{1, 1, 1}));
  EXPECT_EQ(sweepOf["direct"]["axes"]["passes.direct.pcf_radius"], (json{0, 2}));
  EXPECT_EQ(sweepOf["env_diffuse"]["axes"]["passes.env_diffuse.cube_resolution"], (json{32}));
  EXPECT_EQ(sweepOf["specular"]["axes"]["passes.specular.linear_steps"], (json{8}));
  EXPECT_EQ(compare["ambient_occlusion"]["aov"], "ao");
  EXPECT_FALSE(compare["ambient_occlusion"].contains("max_bounces"));
  EXPECT_EQ(compare["env_diffuse"]["aov"], "indirect_diffuse");
  EXPECT_EQ(compare["env_diffuse"]["max_bounces"], 2);
  EXPECT_EQ(compare["direct"]["aov"], "direct");
  // No ground truth for its AOV: the preset's beauty comparison.
  EXPECT_FALSE(compare["specular"].contains("aov"));
  EXPECT_EQ(compare["specular"]["max_bounces"], 5);
  // Every technique of the suite is scored on the first output that info gives a ground truth.
  for (const auto& [name, block] : compare) {
    std::string expected;
    for (const auto& t : info["techniques"])
      if (t["name"] == name)
        for (const auto& aov : t["outputs"])
          if (expected.empty() && truths[name].value(aov.get<std::string>(), json()).is_object()) expected = aov;
    EXPECT_EQ(block.value("aov", ""), expected) << name;
  }

  // The declared bounce range wins over compare.max_bounces: env_diffuse with 2 bounces is scored
  // against bounces 2..3 although the request says 8.
  const json req{{"scene", {{"builtin", "cornell_box"}}}, {"width", 16}, {"height", 16},
                 {"passes", {{"env_diffuse", {{"bounces", 2}}}, {"photon_gi", false}}},
                 {"compare", {{"aov", "indirect_diffuse"}, {"spp", 1}, {"max_bounces", 8}}}};
  res = c.Post("/v1/renders", req.dump(), "application/json");
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 200) << res->body;
  const json m = json::parse(res->body)["stats"]["metrics"];
  EXPECT_EQ(m["reference_mode"], "indirect");
  EXPECT_EQ(m["max_bounces"], 3);
}

TEST_F(SweepAgainstDaemon, ResumeSkipsDonePointsAndRepairsATornLine) {
  const auto dir = scratch("resume");
  const std::string out = (dir / "r.jsonl").string();
  writeJson(dir / "half.json", aoSpec({"volumetric", "containment"}, {4}));
  ProcResult r = runRadiant(dir, {"--server", daemon_->url(), "sweep", (dir / "half.json").string(), "-o", out});
  ASSERT_EQ(r.code, 0) << r.err;
  ASSERT_EQ(records(out).size(), 2u);
  // A writer killed mid-line leaves half a record: the next run cuts it.
  std::ofstream(out, std::ios::app) << R"({"point_id":"deadbeef","par)";
  // The full spec: the 2 done points are skipped, the other 2 run.
  writeJson(dir / "full.json", aoSpec({"volumetric", "containment"}, {4, 16}));
  const int before = daemon_->rendersDone();
  r = runRadiant(dir, {"--server", daemon_->url(), "sweep", (dir / "full.json").string(), "-o", out});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("4 points, 2 already in"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("incomplete last line"), std::string::npos) << r.err;
  EXPECT_EQ(daemon_->rendersDone() - before, 2 * 3);
  const auto recs = records(out);
  ASSERT_EQ(recs.size(), 4u);
  std::set<std::string> ids;
  for (const auto& rec : recs) ids.insert(rec["point_id"].get<std::string>());
  EXPECT_EQ(ids.size(), 4u);
  // A third run has nothing to do.
  const int before2 = daemon_->rendersDone();
  r = runRadiant(dir, {"--server", daemon_->url(), "sweep", (dir / "full.json").string(), "-o", out});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("4 points, 4 already in"), std::string::npos) << r.err;
  EXPECT_EQ(daemon_->rendersDone(), before2);
  EXPECT_EQ(records(out).size(), 4u);
  fs::remove_all(dir);
}

TEST_F(SweepAgainstDaemon, TwoServersShareThePoints) {
  const auto dir = scratch("two");
  Daemon second(dir / "second.log");
  ASSERT_FALSE(second.url().empty());
  ASSERT_TRUE(second.ready());
  writeJson(dir / "spec.json", aoSpec({"volumetric", "containment", "gtao"}, {4, 8}));
  const int before1 = daemon_->rendersDone(), before2 = second.rendersDone();
  ProcResult r = runRadiant(dir, {"sweep", (dir / "spec.json").string(), "-o", (dir / "r.jsonl").string(), "--server",
                        daemon_->url(), "--server", second.url()});
  ASSERT_EQ(r.code, 0) << r.err;
  const auto recs = records(dir / "r.jsonl");
  ASSERT_EQ(recs.size(), 6u);
  std::map<std::string, int> perServer;
  for (const auto& rec : recs) ++perServer[rec["server"].get<std::string>()];
  EXPECT_EQ(perServer.size(), 2u);
  EXPECT_GE(perServer[daemon_->url()], 1);
  EXPECT_GE(perServer[second.url()], 1);
  // Each point ran all its renders on the server its record names.
  EXPECT_EQ(daemon_->rendersDone() - before1, 3 * perServer[daemon_->url()]);
  EXPECT_EQ(second.rendersDone() - before2, 3 * perServer[second.url()]);
  fs::remove_all(dir);
}

TEST_F(SweepAgainstDaemon, ASceneFileIsUploadedOncePerServer) {
  const auto dir = scratch("file");
  // A scene file the server has never seen (a built-in with a trailing byte: another digest).
  std::ofstream(dir / "mine.gltf") << slurp(fs::path(RADIANT_SOURCE_DIR) / "scenes" / "cornell_box.gltf") << "\n";
  writeJson(dir / "spec.json", {{"base", {{"scene", {{"file", "mine.gltf"}}}, {"width", 24}, {"height", 24}}},
                                {"axes", {{"passes.direct.pcf_radius", {0, 1, 2, 3}}}},
                                {"repeats", 1},
                                {"warmup", 0}});
  ProcResult r = runRadiant(dir, {"--server", daemon_->url(), "sweep", (dir / "spec.json").string(), "-o",
                               (dir / "r.jsonl").string(), "--inflight", "3"});
  ASSERT_EQ(r.code, 0) << r.err;
  const auto recs = records(dir / "r.jsonl");
  ASSERT_EQ(recs.size(), 4u);
  std::set<std::string> digests;
  for (const auto& rec : recs) digests.insert(rec["request"]["scene"]["digest"].get<std::string>());
  ASSERT_EQ(digests.size(), 1u);
  // One upload from three workers: the daemon logged one PUT /v1/scenes that stored it.
  int puts = 0;
  std::istringstream log(slurp(logDir_ / "radiantd.log"));
  std::string line;
  while (std::getline(log, line)) {
    const json j = json::parse(line, nullptr, false);
    if (j.is_object() && j.value("method", "") == "PUT" && j.value("path", "") == "/v1/scenes") ++puts;
  }
  EXPECT_EQ(puts, 1);
  httplib::Client c(daemon_->url());
  EXPECT_EQ(c.Head(("/v1/scenes/" + *digests.begin()).c_str())->status, 200);
  fs::remove_all(dir);
}

TEST(SweepServerLoss, AServerThatDiesLeavesConsistentResultsAndAClearError) {
  const auto dir = scratch("loss");
  auto daemon = std::make_unique<Daemon>(dir / "radiantd.log");
  ASSERT_FALSE(daemon->url().empty());
  ASSERT_TRUE(daemon->ready());
  const int points = 16;
  writeJson(dir / "spec.json", slowSpec(points));
  const fs::path out = dir / "r.jsonl";
  const pid_t client = spawn({RADIANT_CLIENT_PATH, "--server", daemon->url(), "sweep", (dir / "spec.json").string(), "-o",
                              out.string()},
                             dir / "client.out", dir / "client.err", nullptr);
  // Kill the daemon once two points are recorded.
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < end && (!fs::exists(out) || lines(out).size() < 2))
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  daemon->kill();
  const int code = waitExit(client, std::chrono::seconds(60));
  const std::string err = slurp(dir / "client.err");
  EXPECT_EQ(code, 4) << err;  // unreachable
  EXPECT_NE(err.find("lost server " + daemon->url()), std::string::npos) << err;
  EXPECT_NE(err.find("not run because no server is left"), std::string::npos) << err;
  // Every line is a whole record of a whole point (both repeats), none an error record.
  const auto partial = records(out);
  ASSERT_GE(partial.size(), 2u);
  ASSERT_LT(partial.size(), static_cast<std::size_t>(points)) << "the daemon died too late to test anything";
  for (const auto& rec : partial) {
    EXPECT_FALSE(rec.contains("error")) << rec.dump();
    EXPECT_EQ(rec["latency_ms"]["n"], 2);
  }
  // A new server picks up where the dead one stopped.
  Daemon fresh(dir / "fresh.log");
  ASSERT_TRUE(fresh.ready());
  ProcResult r = runRadiant(dir, {"--server", fresh.url(), "sweep", (dir / "spec.json").string(), "-o", out.string()});
  ASSERT_EQ(r.code, 0) << r.err;
  const auto all = records(out);
  ASSERT_EQ(all.size(), static_cast<std::size_t>(points));
  std::set<int> seeds;
  for (const auto& rec : all) seeds.insert(rec["params"]["seed"].get<int>());
  EXPECT_EQ(seeds.size(), static_cast<std::size_t>(points));
  std::size_t onFresh = 0;
  for (const auto& rec : all) onFresh += rec["server"] == fresh.url();
  EXPECT_EQ(onFresh, points - partial.size());
  fs::remove_all(dir);
}

// ---------------------------------------------------------------------------------------------
// The report of a fixed results file.

namespace {

// "A displayed number is the file's number rounded to the digits shown."
::testing::AssertionResult showsNumber(const std::string& text, double value) {
  if (text.empty()) return ::testing::AssertionFailure() << "empty cell for " << value;
  double shown = 0;
  try {
    shown = std::stod(text);
  } catch (const std::exception&) {
    return ::testing::AssertionFailure() << "\"" << text << "\" is not a number";
  }
  const auto e = text.find_first_of("eE");
  const std::string mantissa = text.substr(0, e);
  const auto dot = mantissa.find('.');
  const int decimals = dot == std::string::npos ? 0 : static_cast<int>(mantissa.size() - dot - 1);
  const int exponent = e == std::string::npos ? 0 : std::stoi(text.substr(e + 1));
  const double tolerance = 0.5 * std::pow(10.0, exponent - decimals) * (1 + 1e-9);
  if (std::fabs(shown - value) <= tolerance) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "shown \"" << text << "\" but the results file has " << value;
}

// Each method's Pareto front (frame GPU median against rmse), computed from the results records.
std::vector<const json*> paretoFront(const std::vector<json>& recs) {
  std::map<std::string, std::vector<const json*>> byMethod;
  for (const auto& rec : recs)
    if (!rec.contains("error")) byMethod[rec["method"]].push_back(&rec);
  std::vector<const json*> front;
  for (auto& [m, rs] : byMethod) {
    std::sort(rs.begin(), rs.end(), [](const json* a, const json* b) {
      return (*a)["frame_gpu_ms"]["median"].get<double>() < (*b)["frame_gpu_ms"]["median"].get<double>();
    });
    double best = INFINITY;
    for (const json* rec : rs)
      if ((*rec)["metrics"]["rmse"].get<double>() < best) {
        best = (*rec)["metrics"]["rmse"].get<double>();
        front.push_back(rec);
      }
  }
  return front;
}

std::string unescape(std::string s) {
  for (auto [from, to] : std::vector<std::pair<std::string, std::string>>{{"&lt;", "<"}, {"&gt;", ">"}, {"&quot;", "\""}, {"&amp;", "&"}}) {
    std::size_t at = 0;
    while ((at = s.find(from, at)) != std::string::npos) s.replace(at, from.size(), to), at += to.size();
  }
  return s;
}

}  // namespace

TEST(Report, FromTheFixtureHasThePlotsAndTheResultsFilesNumbers) {
  const auto dir = scratch("report");
  const fs::path fixture = fs::path(RADIANT_SOURCE_DIR) / "tests" / "data" / "sweep_results.jsonl";
  ProcResult r = runRadiant(dir, {"report", fixture.string(), "-o", (dir / "out").string()});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("7 points, 1 failed, 4 plots"), std::string::npos) << r.out;
  const std::string page = slurp(dir / "out" / "report.html");
  const std::string mdText = slurp(dir / "out" / "report.md");
  const auto recs = records(fixture);
  ASSERT_EQ(recs.size(), 7u);

  // Self-contained: no scripts, no stylesheets or images fetched from elsewhere.
  EXPECT_EQ(page.find("<script"), std::string::npos);
  EXPECT_EQ(page.find("<link"), std::string::npos);
  EXPECT_EQ(page.find("src=\"http"), std::string::npos);
  EXPECT_EQ(page.find("<img"), std::string::npos);

  // The plots: each a figure with an inline gnuplot SVG.
  const std::vector<std::string> plots{"Pareto front: ambient_occlusion, ao_creases 32x32",
                                       "GPU time per pass: ambient_occlusion, ao_creases 32x32",
                                       "Cost against passes.ambient_occlusion.method: ambient_occlusion",
                                       "Cost against passes.ambient_occlusion.samples: ambient_occlusion"};
  std::map<std::string, std::string> svgOf;
  std::regex figureRe(R"re(<figure id="([^"]+)" data-plot="([^"]+)">(<svg[\s\S]*?</svg>)\s*<figcaption>)re");
  for (auto it = std::sregex_iterator(page.begin(), page.end(), figureRe); it != std::sregex_iterator(); ++it)
    svgOf[unescape((*it)[2])] = (*it)[3];
  EXPECT_EQ(svgOf.size(), plots.size());
  for (const auto& p : plots) {
    ASSERT_TRUE(svgOf.count(p)) << "missing plot " << p;
    EXPECT_NE(svgOf[p].find("Produced by GNUPLOT"), std::string::npos);
    EXPECT_NE(mdText.find("](plots/"), std::string::npos);
  }
  // Every pass of the fixture is a series of the stacked bars.
  for (const auto& pass : recs[0]["passes"])
    EXPECT_NE(svgOf[plots[1]].find(">" + pass["name"].get<std::string>() + "<"), std::string::npos) << pass["name"];

  // The Pareto front per method, computed here from the file, is what the report labels and lists.
  std::set<std::string> frontIds;
  for (const json* rec : paretoFront(recs)) {
    frontIds.insert((*rec)["point_id"].get<std::string>());
    const std::string label = "samples=" + std::to_string((*rec)["params"]["passes.ambient_occlusion.samples"].get<int>());
    EXPECT_NE(svgOf[plots[0]].find(">" + label + "<"), std::string::npos) << label;
  }
  std::set<std::string> mdFront;
  std::regex frontRow(R"(\| (\w+) \| samples=(\d+) \| ([\d.e+-]+) \| ([\d.e+-]+) \| `([0-9a-f]{16})` \|)");
  for (auto it = std::sregex_iterator(mdText.begin(), mdText.end(), frontRow); it != std::sregex_iterator(); ++it) {
    const std::string id = (*it)[5];
    mdFront.insert(id);
    for (const auto& rec : recs)
      if (rec["point_id"] == id) {
        EXPECT_EQ(rec["method"], (*it)[1].str());
        EXPECT_TRUE(showsNumber((*it)[3], rec["frame_gpu_ms"]["median"]));
        EXPECT_TRUE(showsNumber((*it)[4], rec["metrics"]["rmse"]));
      }
  }
  EXPECT_EQ(frontIds.size(), 5u) << "volumetric 1, containment 2, gtao 2 in the fixture";
  EXPECT_EQ(mdFront, frontIds);

  // The full table: one row per record; every number is the file's.
  std::map<std::string, std::map<std::string, std::string>> rows;  // point -> key -> text
  std::regex rowRe(R"re(<tr data-point="([0-9a-f]+)"[^>]*>([\s\S]*?)</tr>)re");
  std::regex cellRe(R"re(<td data-key="([^"]+)"[^>]*>([^<]*)</td>)re");
  for (auto it = std::sregex_iterator(page.begin(), page.end(), rowRe); it != std::sregex_iterator(); ++it) {
    const std::string cells = (*it)[2];
    for (auto c = std::sregex_iterator(cells.begin(), cells.end(), cellRe); c != std::sregex_iterator(); ++c)
      rows[(*it)[1]][unescape((*c)[1])] = unescape((*c)[2]);
  }
  ASSERT_EQ(rows.size(), recs.size());
  // The Markdown table, by point id in its first column.
  std::map<std::string, std::vector<std::string>> mdRows;
  std::vector<std::string> mdHead;
  {
    std::istringstream in(mdText.substr(mdText.find("## All points")));
    std::string l;
    while (std::getline(in, l)) {
      if (l.rfind("| ", 0) != 0) continue;
      std::vector<std::string> cells;
      std::size_t at = 2;
      while (at < l.size()) {
        const auto bar = l.find(" |", at);
        if (bar == std::string::npos) break;
        cells.push_back(l.substr(at, bar - at));
        at = bar + 3;
      }
      if (mdHead.empty()) mdHead = cells;
      else mdRows[cells[0]] = cells;
    }
  }
  ASSERT_EQ(mdRows.size(), recs.size());
  auto mdCell = [&](const std::string& id, const std::string& head) -> std::string {
    const auto col = std::find(mdHead.begin(), mdHead.end(), head);
    return col == mdHead.end() ? "<no column " + head + ">" : mdRows[id][col - mdHead.begin()];
  };
  int errors = 0;
  for (const auto& rec : recs) {
    const std::string id = rec["point_id"];
    ASSERT_TRUE(rows.count(id)) << id;
    auto& row = rows[id];
    EXPECT_EQ(row["technique"], "ambient_occlusion");
    EXPECT_EQ(row["scene"], "ao_creases");
    EXPECT_EQ(row["size"], "32x32");
    EXPECT_EQ(row["param:passes.ambient_occlusion.samples"], rec["params"]["passes.ambient_occlusion.samples"].dump());
    if (rec.contains("error")) {
      ++errors;
      EXPECT_NE(row["notes"].find("error 422"), std::string::npos) << row["notes"];
      EXPECT_NE(mdCell(id, "notes").find("999 is above the maximum 64"), std::string::npos);
      continue;
    }
    EXPECT_EQ(row["method"], rec["method"]);
    EXPECT_EQ(row["param:passes.ambient_occlusion.method"], rec["params"]["passes.ambient_occlusion.method"]);
    const std::vector<std::tuple<std::string, std::string, double>> numbers{
        {"frame_gpu_ms.median", "GPU ms median", rec["frame_gpu_ms"]["median"]},
        {"frame_gpu_ms.min", "GPU ms min", rec["frame_gpu_ms"]["min"]},
        {"frame_gpu_ms.max", "GPU ms max", rec["frame_gpu_ms"]["max"]},
        {"frame_cpu_ms.median", "CPU ms median", rec["frame_cpu_ms"]["median"]},
        {"render_ms.median", "render ms", rec["render_ms"]["median"]},
        {"latency_ms.median", "end-to-end ms", rec["latency_ms"]["median"]},
        {"metric:rmse", "rmse", rec["metrics"]["rmse"]},
        {"metric:psnr", "psnr", rec["metrics"]["psnr"]},
        {"metric:ssim", "ssim", rec["metrics"]["ssim"]},
        {"metric:mean_abs", "mean_abs", rec["metrics"]["mean_abs"]}};
    for (const auto& [key, head, value] : numbers) {
      EXPECT_TRUE(showsNumber(row[key], value)) << id << " " << key;
      EXPECT_TRUE(showsNumber(mdCell(id, head), value)) << id << " " << head << " (Markdown)";
    }
  }
  EXPECT_EQ(errors, 1);

  // Where the numbers come from: device, date, command.
  EXPECT_NE(page.find("llvmpipe (LLVM 15.0.6, 256 bits)"), std::string::npos);
  EXPECT_NE(page.find(recs[0]["finished"].get<std::string>().substr(0, 10)), std::string::npos);
  EXPECT_NE(page.find("radiant sweep tests/data/sweep_fixture.spec.json"), std::string::npos);
  EXPECT_NE(mdText.find("- Device: llvmpipe"), std::string::npos);
  EXPECT_NE(mdText.find("- Produced by: `radiant sweep tests/data/sweep_fixture.spec.json"), std::string::npos);

  // Bad usage exits 2.
  EXPECT_EQ(runRadiant(dir, {"report", (dir / "missing.jsonl").string(), "-o", (dir / "x").string()}).code, 2);
  EXPECT_EQ(runRadiant(dir, {"report", fixture.string()}).code, 2);
  fs::remove_all(dir);
}

TEST(SweepSpec, BadSpecsAreUsageErrorsNamingTheKey) {
  const auto dir = scratch("spec");
  writeJson(dir / "typo.json", {{"base", {{"scene", {{"builtin", "cornell_box"}}}}}, {"axis", json::object()}});
  ProcResult r = runRadiant(dir, {"--server", "http://127.0.0.1:1", "sweep", (dir / "typo.json").string(), "--dry-run"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("/axis: unknown key"), std::string::npos) << r.err;
  writeJson(dir / "zip.json", {{"base", {{"scene", {{"builtin", "cornell_box"}}}}},
                               {"zip", {{{"width", {16, 32}}, {"height", {16}}}}}});
  r = runRadiant(dir, {"sweep", (dir / "zip.json").string(), "--dry-run"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("equal lengths"), std::string::npos) << r.err;
  // Product of axes x zipped groups: 3 x 2 points.
  writeJson(dir / "ok.json", {{"base", {{"scene", {{"builtin", "cornell_box"}}}}},
                              {"axes", {{"passes.direct.pcf_radius", {0, 1, 2}}}},
                              {"zip", {{{"width", {16, 32}}, {"height", {8, 24}}}}}});
  r = runRadiant(dir, {"sweep", (dir / "ok.json").string(), "--dry-run"});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("6 points"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("height=24 pcf_radius=1 width=32"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("height=8 pcf_radius=1 width=32"), std::string::npos) << "zipped values move together";
  fs::remove_all(dir);
}

TEST(SweepInterrupt, CtrlCStopsCleanlyAndTheNextRunResumes) {
  const auto dir = scratch("sigint");
  Daemon daemon(dir / "radiantd.log");
  ASSERT_TRUE(daemon.ready());
  const int points = 12;
  writeJson(dir / "spec.json", slowSpec(points));
  const fs::path out = dir / "r.jsonl";
  const std::vector<std::string> args{RADIANT_CLIENT_PATH, "--server", daemon.url(), "sweep", (dir / "spec.json").string(),
                                      "-o", out.string()};
  const pid_t client = spawn(args, dir / "client.out", dir / "client.err", nullptr);
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < end && (!fs::exists(out) || lines(out).empty()))
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  kill(client, SIGINT);
  EXPECT_EQ(waitExit(client, std::chrono::seconds(60)), 130);
  const std::string err = slurp(dir / "client.err");
  EXPECT_NE(err.find("sweep: stopping; waiting for"), std::string::npos) << err;
  EXPECT_NE(err.find("interrupted; run the same command again to resume"), std::string::npos) << err;
  const auto partial = records(out);
  ASSERT_GE(partial.size(), 1u);
  ASSERT_LT(partial.size(), static_cast<std::size_t>(points));
  for (const auto& rec : partial) EXPECT_EQ(rec["latency_ms"]["n"], 2) << rec.dump();
  // The CSV view was written on the way out, one row per record.
  EXPECT_EQ(lines(dir / "r.csv").size(), partial.size() + 1);
  ProcResult r = runRadiant(dir, {"--server", daemon.url(), "sweep", (dir / "spec.json").string(), "-o", out.string()});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find(std::to_string(points) + " points, " + std::to_string(partial.size()) + " already in"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(records(out).size(), static_cast<std::size_t>(points));
  fs::remove_all(dir);
}

// ---------------------------------------------------------------------------------------------
// The report's pictures: the Pareto points' frames, their error maps and the reference, embedded.

namespace {

// Renders a results record's request again as a float EXR of the ao AOV (plus compare's error and
// reference layers): the frame a report pictured for that point. Returns the EXR's bytes.
std::string renderRecordAsFloatExr(httplib::Client& http, const json& rec) {
  json request = rec["request"];
  request["outputs"] = {{{"format", "exr"}, {"aovs", {"ao"}}, {"half", false}}};
  auto res = http.Post("/v1/renders", request.dump(), "application/json");
  EXPECT_TRUE(res && res->status == 200) << (res ? res->body : "no answer");
  if (!res || res->status != 200) return {};
  auto frame = http.Get(json::parse(res->body)["frames"][0]["url"].get<std::string>().c_str());
  EXPECT_TRUE(frame && frame->status == 200);
  return frame && frame->status == 200 ? frame->body : std::string();
}

// The mean of each 2x2 block: a 128 px frame's 64 px thumbnail, computed here independently.
radiant::Image halve(const radiant::Image& img) {
  radiant::Image out = radiant::Image::make(img.aov, img.width / 2, img.height / 2, img.channels);
  for (int y = 0; y < out.height; ++y)
    for (int x = 0; x < out.width; ++x)
      for (int c = 0; c < img.channels; ++c)
        out.at(x, y)[c] = (img.at(2 * x, 2 * y)[c] + img.at(2 * x + 1, 2 * y)[c] + img.at(2 * x, 2 * y + 1)[c] +
                           img.at(2 * x + 1, 2 * y + 1)[c]) / 4;
  return out;
}

radiant::Image displayed(radiant::Image img) {  // what the PNG encoder makes of linear values at exposure 0
  for (float& v : img.pixels) v = radiant::io::linearToSrgb(std::clamp(v, 0.f, 1.f));
  return img;
}

}  // namespace

TEST_F(SweepAgainstDaemon, ReportShowsTheParetoPointsFramesErrorMapsAndReference) {
  const auto dir = scratch("thumbs");
  json spec = aoSpec({"volumetric", "gtao"}, {4, 16}, 1);
  spec["base"]["width"] = 128;  // 64 px thumbnails: a 2x2 box filter
  spec["base"]["height"] = 128;
  writeJson(dir / "spec.json", spec);
  ProcResult r = runRadiant(dir, {"--server", daemon_->url(), "sweep", (dir / "spec.json").string(), "-o", (dir / "r.jsonl").string()});
  ASSERT_EQ(r.code, 0) << r.err;
  r = runRadiant(dir, {"report", (dir / "r.jsonl").string(), "-o", (dir / "out").string()});
  ASSERT_EQ(r.code, 0) << r.err;
  const auto recs = records(dir / "r.jsonl");
  ASSERT_EQ(recs.size(), 4u);
  for (const auto& rec : recs) {
    ASSERT_TRUE(rec.contains("thumbnail")) << rec.dump();
    EXPECT_EQ(rec["thumbnail"]["file"], "r.thumbs/" + rec["point_id"].get<std::string>() + ".exr");
    EXPECT_EQ(rec["thumbnail"]["aov"], "ao");
    EXPECT_LT(fs::file_size(dir / rec["thumbnail"]["file"].get<std::string>()), 64u * 1024);
  }
  const std::string page = slurp(dir / "out" / "report.html");
  EXPECT_LT(page.size(), 1u << 20) << "one offline file of reasonable size";
  EXPECT_EQ(page.find("src=\"http"), std::string::npos);

  // Every embedded picture, by point and kind.
  std::map<std::string, std::map<std::string, radiant::Image>> shown;  // kind -> point -> image
  std::regex imgRe(R"re(<img class="thumb" data-point="([0-9a-f]+)" data-kind="(\w+)" alt="[^"]*" width="128" src="data:image/png;base64,([A-Za-z0-9+/=]+)">)re");
  int images = 0;
  for (auto it = std::sregex_iterator(page.begin(), page.end(), imgRe); it != std::sregex_iterator(); ++it, ++images)
    shown[(*it)[2]][(*it)[1]] = radiant::io::decodeImage(radiant::api::base64Decode((*it)[3].str()).value_or(""));
  int imgTags = 0;
  for (std::size_t at = 0; (at = page.find("<img", at)) != std::string::npos; ++at) ++imgTags;
  EXPECT_EQ(images, imgTags)
      << "every <img> is a data-URI thumbnail";

  // The Pareto front per method, computed here from the results file, is what is pictured.
  std::set<std::string> frontIds, methods;
  for (const json* rec : paretoFront(recs)) frontIds.insert((*rec)["point_id"].get<std::string>());
  for (const auto& rec : recs) methods.insert(rec["method"].get<std::string>());
  std::set<std::string> framed, errored;
  for (const auto& [id, img] : shown["frame"]) framed.insert(id);
  for (const auto& [id, img] : shown["error"]) errored.insert(id);
  EXPECT_EQ(framed, frontIds);
  EXPECT_EQ(errored, frontIds);
  EXPECT_EQ(shown["reference"].size(), methods.size()) << "one reference per method (its AO definition's)";

  // The pictures are the frames': each front point rendered again here, with the compare block and a
  // float EXR of the AO (its error.Y and reference layers come with it), box-filtered here.
  httplib::Client http("127.0.0.1", daemon_->port());
  http.set_read_timeout(120, 0);
  std::map<std::string, radiant::Image> errors;
  std::map<std::string, radiant::Image> references;
  double scale = 0;
  for (const auto& rec : recs) {
    const std::string id = rec["point_id"];
    if (!frontIds.count(id)) continue;
    const std::string exr = renderRecordAsFloatExr(http, rec);
    ASSERT_FALSE(exr.empty());
    const radiant::Image ao = halve(radiant::io::decodeImage(exr, "ao"));
    errors[id] = halve(radiant::io::decodeImage(exr, "error"));
    references[id] = halve(radiant::io::decodeImage(exr, "reference"));
    for (float v : errors[id].pixels) scale = std::max(scale, double(v));
    ASSERT_EQ(ao.width, 64);
    // 8-bit sRGB of a half-float thumbnail: half a step of rounding, and half's 2^-11 through the sRGB slope.
    EXPECT_LE(radiant::testing::maxAbsDifference(shown["frame"][id], displayed(ao)), 1.0 / 255) << id;
  }
  for (const auto& [id, img] : shown["reference"]) {
    ASSERT_TRUE(references.count(id)) << "a reference shown under a point that is not on the front: " << id;
    EXPECT_LE(radiant::testing::maxAbsDifference(img, displayed(references[id])), 1.0 / 255) << id;
  }
  ASSERT_GT(scale, 0.0);
  // The error maps: viridis over one scale for the section, the largest error among the pictured points.
  for (const auto& [id, err] : errors) {
    radiant::Image colour = radiant::metrics::falseColour(err, scale);
    EXPECT_LE(radiant::testing::maxAbsDifference(shown["error"][id], colour), 1.5 / 255) << id;
  }

  // The numbers beside the pictures are the results file's.
  for (const auto& rec : recs) {
    if (!frontIds.count(rec["point_id"])) continue;
    const std::string label = "samples=" + std::to_string(rec["params"]["passes.ambient_occlusion.samples"].get<int>());
    std::smatch m;
    const std::regex head("<th>" + rec["method"].get<std::string>() + " " + label +
                          R"re(<br><span class="n" data-key="frame_gpu_ms.median">([^<]+)</span> ms, rmse <span class="n" data-key="metric">([^<]+)</span></th>)re");
    ASSERT_TRUE(std::regex_search(page, m, head)) << label;
    EXPECT_TRUE(showsNumber(m[1], rec["frame_gpu_ms"]["median"]));
    EXPECT_TRUE(showsNumber(m[2], rec["metrics"]["rmse"]));
  }
  fs::remove_all(dir);
}

// `radiant bench` end to end on a tiny configuration (--quick, one technique, one scene: 4 AO methods
// x 2 sizes): the HTML it writes pictures, per section (scene and size), exactly each method's Pareto
// points of the results file; the pictures are those points' frames, error maps and reference, and the
// numbers beside them are the results file's.
TEST_F(SweepAgainstDaemon, BenchReportShowsEachSectionsParetoPointsFramesAndTheirNumbers) {
  const auto dir = scratch("bench-thumbs");
  ProcResult r = runRadiant(dir,
                            {"--server", daemon_->url(), "bench", "--quick", "--technique", "ambient_occlusion", "--scene",
                             "ao_creases", "-q", "-o", (dir / "b").string()},
                            std::chrono::seconds(280));
  ASSERT_EQ(r.code, 0) << r.err << r.out;
  const auto recs = records(dir / "b" / "results.jsonl");
  ASSERT_EQ(recs.size(), 8u) << "4 methods x sizes 32 and 64";
  // The front of each section, from the results file (the report's sections: technique x scene x size).
  std::set<std::string> frontIds;
  std::map<int, std::vector<json>> bySize;
  for (const auto& rec : recs) {
    EXPECT_EQ(rec["technique"], "ambient_occlusion");
    EXPECT_EQ(rec["request"]["scene"]["builtin"], "ao_creases");
    bySize[rec["request"]["width"].get<int>()].push_back(rec);
  }
  ASSERT_EQ(bySize.size(), 2u);
  for (const auto& [size, group] : bySize)
    for (const json* rec : paretoFront(group)) frontIds.insert((*rec)["point_id"].get<std::string>());

  const std::string page = slurp(dir / "b" / "report.html");
  EXPECT_EQ(page.find("src=\"http"), std::string::npos) << "one offline file";
  // Per thumbnail figure: the header cells' numbers and the frames, in the same order.
  const std::regex imgRe(R"re(<img class="thumb" data-point="([0-9a-f]+)" data-kind="(\w+)" alt="[^"]*" width="128" src="data:image/png;base64,([A-Za-z0-9+/=]+)">)re");
  const std::regex headRe(R"re(<th>[^<]*<br><span class="n" data-key="frame_gpu_ms.median">([^<]+)</span> ms, rmse <span class="n" data-key="metric">([^<]+)</span></th>)re");
  std::map<std::string, std::map<std::string, radiant::Image>> shown;  // kind -> point -> image
  std::set<std::string> pictured;
  int figures = 0;
  for (std::size_t at = 0; (at = page.find("<figure id=\"thumbs-", at)) != std::string::npos; ++figures) {
    const std::size_t end = page.find("</figure>", at);
    ASSERT_NE(end, std::string::npos);
    const std::string fig = page.substr(at, end - at);
    at = end;
    std::vector<std::pair<std::string, std::string>> heads;
    for (auto it = std::sregex_iterator(fig.begin(), fig.end(), headRe); it != std::sregex_iterator(); ++it)
      heads.push_back({(*it)[1], (*it)[2]});
    std::vector<std::string> frames;
    for (auto it = std::sregex_iterator(fig.begin(), fig.end(), imgRe); it != std::sregex_iterator(); ++it) {
      shown[(*it)[2]][(*it)[1]] = radiant::io::decodeImage(radiant::api::base64Decode((*it)[3].str()).value_or(""));
      if ((*it)[2] == "frame") frames.push_back((*it)[1]);
    }
    ASSERT_EQ(heads.size(), frames.size());
    for (std::size_t i = 0; i < frames.size(); ++i) {
      pictured.insert(frames[i]);
      const auto rec = std::find_if(recs.begin(), recs.end(), [&](const json& j) { return j["point_id"] == frames[i]; });
      ASSERT_NE(rec, recs.end()) << frames[i];
      EXPECT_TRUE(showsNumber(heads[i].first, (*rec)["frame_gpu_ms"]["median"])) << frames[i];
      EXPECT_TRUE(showsNumber(heads[i].second, (*rec)["metrics"]["rmse"])) << frames[i];
    }
  }
  EXPECT_EQ(figures, 2) << "one thumbnail figure per section (size)";
  EXPECT_EQ(pictured, frontIds);

  // The pictures are the frames': each pictured point rendered again here with its compare block, as a
  // float EXR (the sizes are at most 64 px, so a thumbnail is the frame itself).
  httplib::Client http("127.0.0.1", daemon_->port());
  http.set_read_timeout(120, 0);
  for (const auto& rec : recs) {
    const std::string id = rec["point_id"];
    if (!pictured.count(id)) continue;
    const std::string exr = renderRecordAsFloatExr(http, rec);
    ASSERT_FALSE(exr.empty());
    const radiant::Image ao = radiant::io::decodeImage(exr, "ao");
    ASSERT_EQ(ao.width, rec["request"]["width"].get<int>());
    EXPECT_LE(radiant::testing::maxAbsDifference(shown["frame"][id], displayed(ao)), 1.0 / 255) << id;
    if (shown["reference"].count(id)) {
      const radiant::Image reference = radiant::io::decodeImage(exr, "reference");
      EXPECT_LE(radiant::testing::maxAbsDifference(shown["reference"][id], displayed(reference)), 1.0 / 255) << id;
    }
  }
  EXPECT_GE(shown["reference"].size(), 2u) << "a reference per section at least";
  fs::remove_all(dir);
}
