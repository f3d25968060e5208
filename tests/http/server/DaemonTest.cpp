// Real processes on ephemeral loopback ports: the daemon's process shell (port line, signals, flags,
// token file) with the fake backend, the real radiantd with the GL renderer when it is built, and
// the real `radiant` client against both.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <future>
#include <regex>
#include <thread>

#include <httplib.h>
#include <nlohmann/json.hpp>

#include "api/Sha256.h"
#include "tests/support/DaemonProcess.h"

using nlohmann::json;
namespace fs = std::filesystem;

namespace {

using radiant::testing::Daemon;
using radiant::testing::scratch;
using radiant::testing::slurp;

using radiant::testing::ProcessRun;

// Runs the radiant client with RADIANT_SERVER=server.
ProcessRun client(const std::string& server, const std::string& args, const fs::path& dir) {
  return radiant::testing::runClient(RADIANT_CLIENT_PATH, server, args, dir);
}

json fakeFrame(const std::string& bytes) {
  EXPECT_EQ(bytes.rfind("FAKEFRAME ", 0), 0u) << bytes.substr(0, 100);
  return json::parse(bytes.substr(10));
}

}  // namespace

TEST(FakeDaemon, PrintsItsPortAndServesOnLoopback) {
  Daemon d(FAKE_RADIANTD_PATH, {"--port", "0"});
  ASSERT_GT(d.port(), 0) << "first stdout line: " << d.firstLine();
  auto r = d.client().Get("/v1/health");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
  EXPECT_TRUE(d.waitReady(std::chrono::seconds(10)));
  d.signal(SIGINT);
  EXPECT_EQ(d.wait(), 0);
}

TEST(FakeDaemon, SigtermFinishesInFlightRefusesNewAndExitsZero) {
  const auto dir = scratch("sigterm");
  Daemon d(FAKE_RADIANTD_PATH, {"--port", "0"}, {"FAKE_RENDER_DELAY_MS=800"}, dir / "stderr.log");
  ASSERT_GT(d.port(), 0);
  ASSERT_TRUE(d.waitReady(std::chrono::seconds(10)));
  auto inflight = std::async(std::launch::async, [&d] {
    auto c = d.client();
    auto r = c.Post("/v1/renders", R"({"scene":{"builtin":"tiny"},"width":4,"height":4,"seed":3})", "application/json");
    return r ? std::make_pair(r->status, r->body) : std::make_pair(-1, std::string());
  });
  // Signal only once the render is on the render thread.
  for (int i = 0; i < 1000; ++i) {
    auto m = d.client().Get("/metrics");
    if (m && m->body.find("radiant_jobs_active 1") != std::string::npos) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  d.signal(SIGTERM);
  for (int i = 0; i < 1000; ++i) {  // until the daemon has taken the signal
    auto r = d.client().Get("/v1/ready");
    if (r && r->status == 503) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  auto refused = d.client().Post("/v1/renders", R"({"scene":{"builtin":"tiny"}})", "application/json");
  ASSERT_TRUE(refused);
  EXPECT_EQ(refused->status, 503) << refused->body;
  auto [status, body] = inflight.get();
  EXPECT_EQ(status, 200) << body;
  EXPECT_EQ(d.wait(), 0);
  // One JSON log line per request on stderr, with the render timings.
  std::istringstream log(slurp(dir / "stderr.log"));
  std::string line;
  bool sawRender = false;
  while (std::getline(log, line)) {
    json j = json::parse(line, nullptr, false);
    ASSERT_FALSE(j.is_discarded()) << "not JSON: " << line;
    if (j.value("path", "") == "/v1/renders" && j.value("status", 0) == 200) {
      sawRender = true;
      EXPECT_TRUE(j["id"].is_string());
      EXPECT_EQ(j["method"], "POST");
      EXPECT_GE(j["render_ms"].get<double>(), 700.0);
      EXPECT_TRUE(j["queue_ms"].is_number());
      EXPECT_TRUE(j["encode_ms"].is_number());
    }
  }
  EXPECT_TRUE(sawRender);
  fs::remove_all(dir);
}

TEST(FakeDaemon, BadFlagsExitTwoAndTheTokenIsNeverAFlag) {
  {
    Daemon d(FAKE_RADIANTD_PATH, {"--bogus"});
    EXPECT_EQ(d.wait(), 2);
  }
  {
    Daemon d(FAKE_RADIANTD_PATH, {"--token", "abc"});
    EXPECT_EQ(d.wait(), 2);
  }
  {
    Daemon d(FAKE_RADIANTD_PATH, {"--port", "0", "--token-file", "/nonexistent/token"});
    EXPECT_EQ(d.wait(), 2);
  }
}

// A second daemon on a port already in use exits 1 naming the port, and the first keeps it alone:
// with cpp-httplib's default SO_REUSEPORT both bound it and the kernel split the connections between
// them (a render on one, its frame fetched from the other: 404).
TEST(FakeDaemon, ASecondDaemonOnAPortInUseExitsAndTheFirstKeepsIt) {
  Daemon first(FAKE_RADIANTD_PATH, {"--port", "0"});
  ASSERT_GT(first.port(), 0) << first.firstLine();
  const auto dir = scratch("port-in-use");
  Daemon second(FAKE_RADIANTD_PATH, {"--port", std::to_string(first.port())}, {}, dir / "stderr.log");
  EXPECT_EQ(second.port(), 0) << "it said: " << second.firstLine();
  EXPECT_EQ(second.wait(), 1);
  const std::string log = slurp(dir / "stderr.log");
  EXPECT_NE(log.find("cannot bind 127.0.0.1:" + std::to_string(first.port())), std::string::npos) << log;
  for (int i = 0; i < 8; ++i) {  // every connection reaches the first daemon
    auto r = first.client().Get("/v1/health");
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 200);
  }
  first.signal(SIGTERM);
  EXPECT_EQ(first.wait(), 0);
}

TEST(FakeDaemon, TokenFileAndConfigFile) {
  const auto dir = scratch("token");
  std::ofstream(dir / "token") << "hunter2\n";
  std::ofstream(dir / "config.json") << R"({"max_width": 32, "max_queue": 3})";
  Daemon d(FAKE_RADIANTD_PATH, {"--port", "0", "--token-file", (dir / "token").string(), "--config",
                                (dir / "config.json").string()});
  ASSERT_GT(d.port(), 0);
  auto c = d.client();
  EXPECT_EQ(c.Get("/v1/info")->status, 401);
  auto info = c.Get("/v1/info", {{"Authorization", "Bearer hunter2"}});
  ASSERT_EQ(info->status, 200);
  EXPECT_EQ(json::parse(info->body)["limits"]["max_width"], 32);
  EXPECT_EQ(json::parse(info->body)["limits"]["max_queue"], 3);
  ProcessRun r = client(d.url(), "--token-file '" + (dir / "token").string() + "' info", dir);
  EXPECT_EQ(r.code, 0) << r.err;
  r = client(d.url(), "info", dir);
  EXPECT_EQ(r.code, 3) << "401 is a server-reported error";
  d.signal(SIGTERM);
  EXPECT_EQ(d.wait(), 0);
  fs::remove_all(dir);
}

TEST(Client, RenderInfoScenesAndExitCodes) {
  const auto dir = scratch("client");
  Daemon d(FAKE_RADIANTD_PATH, {"--port", "0"});
  ASSERT_GT(d.port(), 0);

  ProcessRun r = client(d.url(), "info", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("pcf_radius"), std::string::npos) << r.out;
  r = client(d.url(), "scenes", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("tiny"), std::string::npos) << r.out;

  // --set values are typed from the schema: pcf_radius is an integer, shadow_bias a number.
  r = client(d.url(),
             "render --builtin tiny -o out.png --size 12x6 --seed 7 --exposure 1.5 --set direct.pcf_radius=2 "
             "--set shadow_maps.shadow_bias=0.5 --stats stats.json",
             dir);
  ASSERT_EQ(r.code, 0) << r.err;
  json frame = fakeFrame(slurp(dir / "out.png"));
  EXPECT_EQ(frame["value"], 7.25);
  EXPECT_EQ(frame["width"], 12);
  EXPECT_EQ(frame["height"], 6);
  EXPECT_EQ(frame["format"], "png");
  EXPECT_EQ(frame["exposure"], 1.5);
  json stats = json::parse(slurp(dir / "stats.json"));
  EXPECT_TRUE(stats["request"]["passes"]["direct"]["pcf_radius"].is_number_integer());
  EXPECT_EQ(stats["request"]["passes"]["direct"]["pcf_radius"], 2);
  EXPECT_TRUE(stats["request"]["passes"]["shadow_maps"]["shadow_bias"].is_number_float());
  EXPECT_EQ(stats["stats"]["passes"][0]["name"], "fake_pass");

  // A scene file: uploaded the first time only (digest computed locally, HEAD first).
  std::ofstream(dir / "scene.gltf") << R"({"asset":{"version":"2.0"},"extras":{"client":1}})";
  r = client(d.url(), "render scene.gltf -o a.exr", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("uploaded scene.gltf as sha256:"), std::string::npos) << r.err;
  EXPECT_EQ(fakeFrame(slurp(dir / "a.exr"))["format"], "exr");
  r = client(d.url(), "render scene.gltf -o b.exr --async", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("already on the server"), std::string::npos) << r.err;
  EXPECT_EQ(fakeFrame(slurp(dir / "b.exr"))["aovs"], json::array({"beauty"}));
  const std::string digest = radiant::api::sceneDigest(slurp(dir / "scene.gltf"));
  EXPECT_EQ(d.client().Head(("/v1/scenes/" + digest).c_str())->status, 200);

  // 3: the server rejects the value, and the client prints the pointer.
  r = client(d.url(), "render --builtin tiny -o x.png --set direct.pcf_radius=9", dir);
  EXPECT_EQ(r.code, 3);
  EXPECT_NE(r.err.find("/passes/direct/pcf_radius"), std::string::npos) << r.err;
  r = client(d.url(), "render --builtin nope -o x.png", dir);
  EXPECT_EQ(r.code, 3);
  EXPECT_NE(r.err.find("404"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("/scene/builtin"), std::string::npos) << r.err;
  // 2: usage errors, caught before anything is sent.
  EXPECT_EQ(client(d.url(), "render --builtin tiny -o x.png --set direct.pcf_radius=abc", dir).code, 2);
  EXPECT_EQ(client(d.url(), "render --builtin tiny -o x.tiff", dir).code, 2);
  EXPECT_EQ(client(d.url(), "render -o x.png", dir).code, 2);
  EXPECT_EQ(client(d.url(), "frobnicate", dir).code, 2);
  EXPECT_EQ(client(d.url(), "render missing.gltf -o x.png", dir).code, 2);
  // 4: nothing listens there.
  d.signal(SIGTERM);
  EXPECT_EQ(d.wait(), 0);
  r = client(d.url(), "info", dir);
  EXPECT_EQ(r.code, 4) << r.err;
  fs::remove_all(dir);
}

#ifdef RADIANTD_PATH
// The real daemon with the GL renderer (llvmpipe in CI).
TEST(RealDaemon, RendersBuiltinsRejectsBadInputAndStopsCleanly) {
  const auto dir = scratch("real");
  Daemon d(RADIANTD_PATH, {"--port", "0", "--cache-dir", (dir / "cache").string()}, {}, dir / "stderr.log");
  ASSERT_GT(d.port(), 0) << d.firstLine();
  ASSERT_TRUE(d.waitReady(std::chrono::seconds(120))) << slurp(dir / "stderr.log");
  auto c = d.client();

  auto scenes = json::parse(c.Get("/v1/scenes")->body);
  ASSERT_FALSE(scenes["builtins"].empty());
  const std::string builtin = scenes["builtins"][0]["name"];

  json req{{"scene", {{"builtin", builtin}}}, {"width", 64}, {"height", 48},
           {"outputs", {{{"format", "png"}}, {{"format", "exr"}, {"aovs", {"beauty"}}}}}};
  auto r = c.Post("/v1/renders", req.dump(), "application/json");
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  json out = json::parse(r->body);
  ASSERT_EQ(out["frames"].size(), 2u);
  const std::string png = c.Get(out["frames"][0]["url"].get<std::string>().c_str())->body;
  ASSERT_GE(png.size(), 8u);
  EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  const std::string exr = c.Get(out["frames"][1]["url"].get<std::string>().c_str())->body;
  ASSERT_GE(exr.size(), 4u);
  EXPECT_EQ(exr.substr(0, 4), std::string("\x76\x2f\x31\x01", 4));
  EXPECT_FALSE(out["stats"]["passes"].empty());

  req["passes"] = {{"shadow_maps", {{"shadow_map_size", 10}}}};
  r = c.Post("/v1/renders", req.dump(), "application/json");
  EXPECT_EQ(r->status, 422);
  EXPECT_EQ(json::parse(r->body)["pointer"], "/passes/shadow_maps/shadow_map_size");
  EXPECT_EQ(c.Post("/v1/renders", R"({"scene":{"builtin":"no_such_scene"}})", "application/json")->status, 404);
  // Participating media: above the server's particle limit (65536 by default) is 422 at the count.
  req.erase("passes");
  req["media"] = json::array({{{"kind", "smoke"}, {"generator", {{"count", 70000}}}}});
  r = c.Post("/v1/renders", req.dump(), "application/json");
  EXPECT_EQ(r->status, 422);
  EXPECT_EQ(json::parse(r->body)["type"], "https://radiant.dev/problems/limit-exceeded");
  EXPECT_EQ(json::parse(r->body)["pointer"], "/media/0/generator/count");
  req.erase("media");
  // What no frame of the scene could render is the POST's 422 before the job is queued (Renderer::check),
  // even for an async request: not a 202 and a failed job.
  req["async"] = true;
  req["passes"] = {{"env_diffuse", {{"receivers", "no_such_node"}}}};
  r = c.Post("/v1/renders", req.dump(), "application/json");
  EXPECT_EQ(r->status, 422) << r->body;
  EXPECT_EQ(json::parse(r->body)["pointer"], "/passes/env_diffuse/receivers");
  req["passes"] = {{"photon_gi", json::object()}, {"env_diffuse", json::object()}};
  r = c.Post("/v1/renders", req.dump(), "application/json");
  EXPECT_EQ(r->status, 422) << r->body;
  EXPECT_EQ(json::parse(r->body)["type"], "https://radiant.dev/problems/conflicting-passes");
  req.erase("passes");
  req.erase("async");

  // Eight concurrent clients, each with its own image size: every PNG has its own request's size.
  std::vector<std::future<std::string>> concurrent;
  for (int i = 0; i < 8; ++i)
    concurrent.push_back(std::async(std::launch::async, [&d, &builtin, i]() -> std::string {
      auto c = d.client();
      json q{{"scene", {{"builtin", builtin}}}, {"width", 16 + i}, {"height", 8 + 2 * i}};
      auto res = c.Post("/v1/renders", q.dump(), "application/json");
      if (!res || res->status != 200) return "render " + std::to_string(i) + " failed: " + (res ? res->body : "no response");
      const std::string bytes = c.Get(json::parse(res->body)["frames"][0]["url"].get<std::string>().c_str())->body;
      if (bytes.size() < 24 || bytes.compare(12, 4, "IHDR") != 0) return "not a PNG";
      auto be32 = [&](std::size_t o) -> unsigned {
        return unsigned((unsigned char)bytes[o]) << 24 | unsigned((unsigned char)bytes[o + 1]) << 16 |
               unsigned((unsigned char)bytes[o + 2]) << 8 | unsigned((unsigned char)bytes[o + 3]);
      };
      if (be32(16) != 16u + i || be32(20) != 8u + 2 * i)
        return "frame " + std::to_string(i) + " is " + std::to_string(be32(16)) + "x" + std::to_string(be32(20));
      return "";
    }));
  for (auto& f : concurrent) EXPECT_EQ(f.get(), "");

  ProcessRun cli = client(d.url(), "render --builtin " + builtin + " -o cli.png --size 32x32", dir);
  EXPECT_EQ(cli.code, 0) << cli.err;
  EXPECT_EQ(slurp(dir / "cli.png").substr(0, 4), std::string("\x89PNG", 4));

  // A scene file through the client: uploaded once (the loader accepts it), then found by digest.
  const std::string gltf = slurp(fs::path(RADIANT_SOURCE_DIR) / "scenes" / (builtin + ".gltf")) + "\n ";
  std::ofstream(dir / "mine.gltf") << gltf;
  cli = client(d.url(), "render mine.gltf -o mine.png --size 24x24", dir);
  EXPECT_EQ(cli.code, 0) << cli.err;
  EXPECT_NE(cli.err.find("uploaded mine.gltf"), std::string::npos) << cli.err;
  cli = client(d.url(), "render mine.gltf -o mine.exr --size 24x24", dir);
  EXPECT_EQ(cli.code, 0) << cli.err;
  EXPECT_NE(cli.err.find("already on the server"), std::string::npos) << cli.err;
  EXPECT_EQ(slurp(dir / "mine.exr").substr(0, 4), std::string("\x76\x2f\x31\x01", 4));
  // A file the loader refuses is not stored.
  const std::string junk = std::string("glTF\x02\x00\x00\x00\x10\x00\x00\x00", 12) + "junk";
  auto bad = c.Put("/v1/scenes", junk, "model/gltf-binary");
  EXPECT_EQ(bad->status, 422) << bad->body;
  EXPECT_EQ(json::parse(bad->body)["type"], "https://radiant.dev/problems/invalid-scene");
  EXPECT_EQ(c.Head(("/v1/scenes/" + radiant::api::sceneDigest(junk)).c_str())->status, 404);

  d.signal(SIGTERM);
  EXPECT_EQ(d.wait(), 0);
  // The upload survives a restart through the cache directory.
  Daemon again(RADIANTD_PATH, {"--port", "0", "--cache-dir", (dir / "cache").string()});
  ASSERT_GT(again.port(), 0);
  EXPECT_EQ(again.client().Head(("/v1/scenes/" + radiant::api::sceneDigest(gltf)).c_str())->status, 200);
  again.signal(SIGTERM);
  EXPECT_EQ(again.wait(), 0);
  fs::remove_all(dir);
}
#endif
