// Progressive sessions (server/Sessions.h, docs/API.md "Sessions") in-process over the fake backend,
// whose beauty is seed + 0.25 everywhere: a generation refining batches with seeds s, s+1, ... has the
// mean s + (n-1)/2 + 0.25 after n batches, so every frame proves which request and batch it is.
// The event stream, merge patches (a refused one changes nothing), the limits (sessions, idle, body
// size), a flood of changes, 500 sessions without growth, shutdown, and the viewer page's headers.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <httplib.h>
#include <nlohmann/json.hpp>

#include "FakeBackend.h"
#include "TestServer.h"
#include "server/Config.h"
#include "server/HttpServer.h"
#include "server/RenderService.h"

using nlohmann::json;
using radiant::server::HttpServer;
using radiant::server::ServerConfig;
using radiant::test::FakeControl;

namespace {

// The shared in-process server, up and ready (a server that requires a token is only up: /v1/ready is
// then 401 without it).
struct TestServer : radiant::test::TestServer {
  explicit TestServer(ServerConfig config = {}) : radiant::test::TestServer(config) {
    if (config.token.empty()) waitReady();
  }
};

struct Event {
  long id = 0;
  std::string name;
  json data;
};

// Reads a session's event stream on its own thread until `ended` or stop().
class EventReader {
public:
  EventReader(int port, const std::string& sessionId) : client_("127.0.0.1", port) {
    thread_ = std::thread([this, port, sessionId] {
      httplib::Client& c = client_;
      c.set_read_timeout(30, 0);
      std::string buffer;
      auto r = c.Get(("/v1/sessions/" + sessionId + "/events").c_str(), [&](const char* data, std::size_t n) {
        buffer.append(data, n);
        for (std::size_t end; (end = buffer.find("\n\n")) != std::string::npos;) {
          const std::string block = buffer.substr(0, end);
          buffer.erase(0, end + 2);
          Event e;
          std::size_t at = 0;
          while (at < block.size()) {
            std::size_t nl = block.find('\n', at);
            if (nl == std::string::npos) nl = block.size();
            const std::string line = block.substr(at, nl - at);
            at = nl + 1;
            if (line.rfind("id: ", 0) == 0) e.id = std::stol(line.substr(4));
            else if (line.rfind("event: ", 0) == 0) e.name = line.substr(7);
            else if (line.rfind("data: ", 0) == 0) e.data = json::parse(line.substr(6));
          }
          if (e.name.empty()) continue;  // a comment
          std::lock_guard lock(m_);
          events_.push_back(e);
        }
        return !stop_;
      });
      std::lock_guard lock(m_);
      status_ = r ? r->status : -1;
      contentType_ = r ? r->get_header_value("Content-Type") : "";
      closed_ = true;
    });
  }
  ~EventReader() {
    stop();
    thread_.join();
  }
  std::vector<Event> events() {
    std::lock_guard lock(m_);
    return events_;
  }
  // Waits (up to 10 s) for an event matching `pred`; returns it, or an empty Event.
  template <class P>
  Event waitFor(P pred) {
    for (int i = 0; i < 1000; ++i) {
      for (const Event& e : events())
        if (pred(e)) return e;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return {};
  }
  bool closed() {
    std::lock_guard lock(m_);
    return closed_;
  }
  std::string contentType() {
    std::lock_guard lock(m_);
    return contentType_;
  }
  void stop() {
    stop_ = true;
    client_.stop();  // the stream may be waiting for the next event
  }

private:
  std::mutex m_;
  std::vector<Event> events_;
  std::atomic<bool> stop_{false};
  bool closed_ = false;
  int status_ = 0;
  std::string contentType_;
  httplib::Client client_;
  std::thread thread_;
};

json sessionBody(std::uint64_t seed, int batches = 3) {
  return json{{"scene", {{"builtin", "tiny"}}}, {"width", 8}, {"height", 4}, {"seed", seed},
              {"refine", {{"max_batches", batches}}}};
}

httplib::Result post(httplib::Client& c, const json& body) {
  return c.Post("/v1/sessions", body.dump(), "application/json");
}
httplib::Result patch(httplib::Client& c, const std::string& id, const json& body) {
  return c.Patch(("/v1/sessions/" + id).c_str(), body.dump(), "application/merge-patch+json");
}

// The fake encoder writes "FAKEFRAME {json}" with the beauty's value.
double frameValue(const std::string& bytes) { return json::parse(bytes.substr(bytes.find('{')))["value"].get<double>(); }

void expectProblem(const httplib::Result& r, int status, const std::string& type, const std::string& pointer) {
  ASSERT_TRUE(r) << "no response";
  EXPECT_EQ(r->status, status) << r->body;
  EXPECT_EQ(r->get_header_value("Content-Type"), "application/problem+json") << r->body;
  const json p = json::parse(r->body, nullptr, false);
  ASSERT_TRUE(p.is_object()) << r->body;
  EXPECT_EQ(p["type"], "https://radiant.dev/problems/" + type) << r->body;
  EXPECT_EQ(p.value("pointer", ""), pointer) << r->body;
}

long residentKiB() {
  std::ifstream in("/proc/self/status");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
  return 0;
}

TEST(Sessions, EventsFollowEachGenerationInOrderAndFramesAreItsMeans) {
  TestServer s;
  // Each batch lasts 250 ms, so that the stream (which shows the session's state as it changes and
  // skips what a reader was too slow for) sees every batch.
  s.control.delayMs = 250;
  auto c = s.client();
  auto r = post(c, sessionBody(10));
  ASSERT_EQ(r->status, 201) << r->body;
  const json created = json::parse(r->body);
  const std::string id = created["id"];
  EXPECT_EQ(r->get_header_value("Location"), "/v1/sessions/" + id);
  EXPECT_EQ(created["generation"], 0);
  EXPECT_EQ(created["request"]["seed"], 10);
  EventReader events(s.port, id);
  const Event done0 = events.waitFor([](const Event& e) { return e.name == "done" && e.data["generation"] == 0; });
  ASSERT_EQ(done0.name, "done");
  EXPECT_EQ(done0.data["batches"], 3);
  EXPECT_EQ(done0.data["stopped_by"], "max_batches");
  // The frame is the mean of the three batches: seeds 10, 11, 12.
  auto f = c.Get(("/v1/sessions/" + id + "/frame").c_str());
  ASSERT_EQ(f->status, 200) << f->body;
  EXPECT_EQ(f->get_header_value("X-Radiant-Generation"), "0");
  EXPECT_EQ(f->get_header_value("X-Radiant-Batches"), "3");
  EXPECT_NEAR(frameValue(f->body), 11.25, 1e-5);

  // A change: the next generation renders the patched request (seed 20) from its first batch.
  r = patch(c, id, {{"seed", 20}});
  ASSERT_EQ(r->status, 200) << r->body;
  EXPECT_EQ(json::parse(r->body)["generation"], 1);
  const Event done1 = events.waitFor([](const Event& e) { return e.name == "done" && e.data["generation"] == 1; });
  ASSERT_EQ(done1.name, "done");
  f = c.Get(("/v1/sessions/" + id + "/frame").c_str());
  EXPECT_EQ(f->get_header_value("X-Radiant-Generation"), "1");
  EXPECT_NEAR(frameValue(f->body), 21.25, 1e-5);

  // A change that names no seed starts from the last batch's seed (its photons are on the GPU), then
  // goes on from the request's seed without it: batches 22 and 20 (a restart would be 20 and 21).
  r = patch(c, id, {{"width", 16}, {"refine", {{"max_batches", 2}}}});
  ASSERT_EQ(r->status, 200) << r->body;
  EXPECT_EQ(json::parse(r->body)["request"]["seed"], 20) << "the session's request keeps the seed it was given";
  ASSERT_EQ(events.waitFor([](const Event& e) { return e.name == "done" && e.data["generation"] == 2; }).name, "done");
  EXPECT_NEAR(frameValue(c.Get(("/v1/sessions/" + id + "/frame").c_str())->body), 21.25, 1e-5);
  EXPECT_EQ(events.waitFor([](const Event& e) { return e.name == "done" && e.data["generation"] == 2; }).data["batches"], 2);

  ASSERT_EQ(c.Delete(("/v1/sessions/" + id).c_str())->status, 200);
  const Event ended = events.waitFor([](const Event& e) { return e.name == "ended"; });
  EXPECT_EQ(ended.data["reason"], "deleted");
  for (int i = 0; i < 200 && !events.closed(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  EXPECT_TRUE(events.closed()) << "the stream ends with the session";
  EXPECT_EQ(events.contentType(), "text/event-stream");

  // In order: ids 1, 2, 3, ... without a gap; session first, ended last; per generation: generation,
  // frames with batches 1, 2, 3, done.
  const std::vector<Event> all = events.events();
  ASSERT_GE(all.size(), 16u);
  for (std::size_t i = 0; i < all.size(); ++i) EXPECT_EQ(all[i].id, long(i + 1)) << all[i].name;
  EXPECT_EQ(all.front().name, "session");
  EXPECT_EQ(all.back().name, "ended");
  std::vector<std::string> names;
  for (const Event& e : all)
    names.push_back(e.name + (e.name == "frame" ? std::to_string(e.data["batches"].get<int>()) : "") +
                    (e.data.contains("generation") ? "@" + std::to_string(e.data["generation"].get<int>()) : ""));
  const std::vector<std::string> expected{"session@0", "generation@0", "frame1@0", "frame2@0", "frame3@0", "done@0",
                                          "generation@1", "frame1@1",  "frame2@1", "frame3@1", "done@1",
                                          "generation@2", "frame1@2",  "frame2@2", "done@2", "ended"};
  EXPECT_EQ(names, expected);
  // A frame event carries what the viewer draws and plots.
  for (const Event& e : all)
    if (e.name == "frame") {
      EXPECT_TRUE(e.data["url"].get<std::string>().rfind("/v1/sessions/" + id + "/frame?", 0) == 0) << e.data;
      EXPECT_TRUE(e.data["stats"].is_object()) << e.data;
      EXPECT_TRUE(e.data.contains("estimated_rmse")) << e.data;
    }
  expectProblem(c.Get(("/v1/sessions/" + id).c_str()), 404, "unknown-session", "");
}

TEST(Sessions, BatchSeedsStartWithTheFirstSeedAndStayDistinct) {
  using radiant::server::batchSeed;
  const std::uint64_t m = 9007199254740992ull;
  EXPECT_EQ(batchSeed(10, std::nullopt, 3, m), 13u);
  EXPECT_EQ(batchSeed(m - 1, std::nullopt, 2, m), 1u);  // wraps at the schema's bound
  // First 12, then 10, 11, 13, 14 (12 skipped); a first seed outside the run skips nothing.
  std::vector<std::uint64_t> seeds;
  for (int k = 0; k < 5; ++k) seeds.push_back(batchSeed(10, 12, k, m));
  EXPECT_EQ(seeds, (std::vector<std::uint64_t>{12, 10, 11, 13, 14}));
  EXPECT_EQ(batchSeed(10, 5, 1, m), 10u);
  EXPECT_EQ(batchSeed(10, 5, 3, m), 12u);
  // Across the wrap: seed m-2, first 0: 0, m-2, m-1, 1.
  seeds.clear();
  for (int k = 0; k < 4; ++k) seeds.push_back(batchSeed(m - 2, 0, k, m));
  EXPECT_EQ(seeds, (std::vector<std::uint64_t>{0, m - 2, m - 1, 1}));
}

TEST(Sessions, ARefusedRequestOrChangeNamesItsFieldAndChangesNothing) {
  TestServer s;
  auto c = s.client();
  expectProblem(post(c, {{"scene", {{"builtin", "tiny"}}}, {"width", 0}}), 422, "out-of-range", "/width");
  expectProblem(post(c, {{"scene", {{"builtin", "tiny"}}}, {"bogus", 1}}), 422, "unknown-field", "/bogus");
  expectProblem(post(c, {{"scene", {{"inline_glb", "Z2xURg=="}}}}), 422, "invalid-value", "/scene");
  expectProblem(post(c, {{"scene", {{"builtin", "tiny"}}}, {"async", false}}), 422, "invalid-value", "/async");
  expectProblem(c.Post("/v1/sessions", "[1,2]", "application/json"), 422, "invalid-type", "");
  expectProblem(c.Post("/v1/sessions", "{\"scene\":", "application/json"), 400, "malformed-json", "");
  expectProblem(c.Post("/v1/sessions", "{}", "text/plain"), 415, "unsupported-media-type", "");
  expectProblem(c.Post("/v1/sessions", std::string(2u << 20, ' '), "application/json"), 413, "payload-too-large", "");

  auto r = post(c, sessionBody(5));
  ASSERT_EQ(r->status, 201) << r->body;
  const std::string id = json::parse(r->body)["id"];
  // Non-finite or absurd cameras, unknown keys, a wrong type: refused at their pointer.
  expectProblem(c.Patch(("/v1/sessions/" + id).c_str(), R"({"camera": {"position": [0, 1e400, 0]}})", "application/merge-patch+json"),
                422, "out-of-range", "/camera/position/1");
  expectProblem(patch(c, id, {{"camera", {{"position", {0, 2e9, 0}}}}}), 422, "out-of-range", "/camera/position/1");
  expectProblem(patch(c, id, {{"camera", {{"orbit", {{"theta_deg", 10}, {"phi_deg", 400}}}}}}), 422, "out-of-range",
                "/camera/orbit/phi_deg");
  expectProblem(patch(c, id, {{"passes", {{"no_such_pass", true}}}}), 422, "unknown-field", "/passes/no_such_pass");
  expectProblem(patch(c, id, {{"width", "wide"}}), 400, "type-mismatch", "/width");
  expectProblem(c.Patch(("/v1/sessions/" + id).c_str(), "7", "application/merge-patch+json"), 422, "invalid-type", "");
  const json after = json::parse(c.Get(("/v1/sessions/" + id).c_str())->body);
  EXPECT_EQ(after["generation"], 0) << "a refused change starts no generation";
  EXPECT_EQ(after["request"]["seed"], 5);
  EXPECT_FALSE(after["request"].contains("camera")) << after.dump();
  // null removes a member (RFC 7386), and the request is whole again.
  r = patch(c, id, {{"seed", nullptr}, {"width", 16}});
  ASSERT_EQ(r->status, 200) << r->body;
  const json changed = json::parse(r->body);
  EXPECT_EQ(changed["generation"], 1);
  EXPECT_FALSE(changed["request"].contains("seed"));
  EXPECT_EQ(changed["request"]["width"], 16);
  expectProblem(patch(c, "s-0000000000000000", {{"seed", 1}}), 404, "unknown-session", "");
  expectProblem(c.Get(("/v1/sessions/" + id + "/frame?format=tiff").c_str()), 400, "invalid-query", "");
  expectProblem(c.Get(("/v1/sessions/" + id + "/frame?layer=reference").c_str()), 409, "no-reference", "");
}

TEST(Sessions, TheSessionLimitIs503AndIdleSessionsEnd) {
  ServerConfig config;
  config.maxSessions = 2;
  config.sessionIdleS = 0.5;
  TestServer s(config);
  auto c = s.client();
  const std::string a = json::parse(post(c, sessionBody(1))->body)["id"];
  const std::string b = json::parse(post(c, sessionBody(2))->body)["id"];
  auto full = post(c, sessionBody(3));
  expectProblem(full, 503, "sessions-full", "");
  EXPECT_FALSE(full->get_header_value("Retry-After").empty());
  // b keeps an event stream open; a is left alone and ends after 0.5 s untouched.
  EventReader events(s.port, b);
  // Each stream holds a worker: four per session, a fifth is 429.
  std::vector<std::unique_ptr<EventReader>> more;
  for (int i = 0; i < 3; ++i) more.push_back(std::make_unique<EventReader>(s.port, b));
  for (auto& m : more) m->waitFor([](const Event& e) { return e.name == "session"; });
  expectProblem(c.Get(("/v1/sessions/" + b + "/events").c_str()), 429, "too-many-streams", "");
  more.clear();
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  expectProblem(c.Get(("/v1/sessions/" + a).c_str()), 404, "unknown-session", "");
  EXPECT_EQ(c.Get(("/v1/sessions/" + b).c_str())->status, 200) << "a session with an open stream is not idle";
  EXPECT_EQ(post(c, sessionBody(4))->status, 201) << "the idle session's slot is free again";
  EXPECT_NE(c.Get("/metrics")->body.find("\nradiant_sessions_open 2\n"), std::string::npos);
  events.stop();
}

TEST(Sessions, AFloodOfChangesKeepsOneJobPerSessionAndEndsOnTheLast) {
  TestServer s;
  s.control.delayMs = 20;  // each batch takes 20 ms: most changes land while one renders
  auto c = s.client();
  const std::string id = json::parse(post(c, sessionBody(0, 4))->body)["id"];
  EventReader events(s.port, id);
  int maxQueued = 0;
  for (int i = 1; i <= 200; ++i) {
    ASSERT_EQ(patch(c, id, {{"seed", i}})->status, 200);
    const std::string m = c.Get("/metrics")->body;
    const auto at = m.find("\nradiant_queue_depth ");
    maxQueued = std::max(maxQueued, std::stoi(m.substr(at + 21)));
  }
  EXPECT_LE(maxQueued, 1) << "a change replaces the queued generation instead of queueing behind it";
  const Event done = events.waitFor([](const Event& e) { return e.name == "done" && e.data["generation"] == 200; });
  ASSERT_EQ(done.name, "done");
  auto f = c.Get(("/v1/sessions/" + id + "/frame").c_str());
  EXPECT_NEAR(frameValue(f->body), 200 + 1.5 + 0.25, 1e-5) << "the last change is what the session shows";
  // Generations only go up in the stream.
  int last = -1;
  for (const Event& e : events.events())
    if (e.data.contains("generation")) {
      EXPECT_GE(e.data["generation"].get<int>(), last) << e.name;
      last = e.data["generation"];
    }
}

TEST(Sessions, AClientThatNeverReadsItsStreamBlocksNoOne) {
  TestServer s;
  s.control.delayMs = 1;  // a thousand batches, each a frame event
  auto c = s.client();
  const std::string id = json::parse(post(c, sessionBody(1, 1000))->body)["id"];
  // A raw connection that asks for the stream and never reads a byte of it.
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<std::uint16_t>(s.port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
  const int small = 4096;
  setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &small, sizeof small);
  const std::string get = "GET /v1/sessions/" + id + "/events HTTP/1.1\r\nHost: x\r\n\r\n";
  ASSERT_EQ(write(fd, get.data(), get.size()), static_cast<ssize_t>(get.size()));
  // Meanwhile a reading client sees the session refine to its end, and changes are taken.
  EventReader events(s.port, id);
  const Event done = events.waitFor([](const Event& e) { return e.name == "done"; });
  EXPECT_EQ(done.data.value("batches", 0), 1000);
  ASSERT_EQ(patch(c, id, {{"refine", {{"max_batches", 2}}}})->status, 200);
  EXPECT_EQ(events.waitFor([](const Event& e) { return e.name == "done" && e.data["generation"] == 1; }).name, "done");
  // (The stalled stream holds no queue by construction: pumpEvents writes the session's state when
  // the socket takes it. This process's RSS would count the reading client's thousand events too.)
  close(fd);
  EXPECT_EQ(c.Get(("/v1/sessions/" + id).c_str())->status, 200);
}

TEST(Sessions, FiveHundredSessionsLeaveNoJobsAndNoGrowth) {
  ServerConfig config;
  config.maxSessions = 4;
  TestServer s(config);
  auto c = s.client();
  long rssAfterWarmUp = 0;
  for (int i = 0; i < 500; ++i) {
    auto r = post(c, sessionBody(i, 2));
    ASSERT_EQ(r->status, 201) << r->body;
    const std::string id = json::parse(r->body)["id"];
    if (i % 2 == 0) patch(c, id, {{"seed", i + 1}});
    ASSERT_EQ(c.Delete(("/v1/sessions/" + id).c_str())->status, 200);
    if (i == 49) rssAfterWarmUp = residentKiB();
  }
  // Retired jobs are forgotten within the reaper's tick once they end.
  std::string metrics;
  for (int i = 0; i < 200; ++i) {
    metrics = c.Get("/metrics")->body;
    if (metrics.find("\nradiant_jobs_active 0") != std::string::npos && metrics.find("\nradiant_queue_depth 0") != std::string::npos) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_NE(metrics.find("\nradiant_queue_depth 0"), std::string::npos) << metrics;
  EXPECT_EQ(json::parse(c.Get("/v1/sessions")->body)["open"], 0);
  EXPECT_LT(residentKiB() - rssAfterWarmUp, 8 * 1024) << "KiB of growth over 450 sessions";
}

TEST(Sessions, ShutdownEndsEverySessionAndItsStream) {
  TestServer s;
  auto c = s.client();
  const std::string id = json::parse(post(c, sessionBody(1, 1000))->body)["id"];
  EventReader events(s.port, id);
  ASSERT_EQ(events.waitFor([](const Event& e) { return e.name == "frame"; }).name, "frame");
  std::thread stopper([&] { s.stop(); });
  const Event ended = events.waitFor([](const Event& e) { return e.name == "ended"; });
  stopper.join();
  EXPECT_EQ(ended.data["reason"], "shutdown");
}

TEST(Sessions, SweepReportsAreServedReadOnlyFromTheReportsFolderOnly) {
  const auto root = std::filesystem::temp_directory_path() / ("radiant-reports-" + std::to_string(::getpid()));
  std::filesystem::remove_all(root);
  std::filesystem::create_directories(root / "reports" / "sweep-a" / "plots");
  std::filesystem::create_directories(root / "reports" / "not-a-report");
  std::ofstream(root / "reports" / "sweep-a" / "report.html") << "<html><body><img src=\"plots/p.svg\"></body></html>";
  std::ofstream(root / "reports" / "sweep-a" / "plots" / "p.svg") << "<svg xmlns=\"http://www.w3.org/2000/svg\"/>";
  std::ofstream(root / "reports" / "sweep-a" / "results.bin") << "x";
  std::ofstream(root / "secret.html") << "TOP-SECRET-CONTENT";
  std::filesystem::create_symlink(root / "secret.html", root / "reports" / "sweep-a" / "link.html");
  {
    TestServer off;
    auto c = off.client();
    expectProblem(c.Get("/reports/"), 404, "reports-off", "");
  }
  ServerConfig config;
  config.reportsDir = (root / "reports").string();
  TestServer s(config);
  auto c = s.client();
  auto list = c.Get("/reports/");
  ASSERT_EQ(list->status, 200) << list->body;
  EXPECT_NE(list->body.find("href=\"sweep-a/report.html\""), std::string::npos) << list->body;
  EXPECT_EQ(list->body.find("not-a-report"), std::string::npos) << "a folder without report.html is not listed";
  EXPECT_NE(list->get_header_value("Content-Security-Policy").find("default-src 'none'"), std::string::npos);
  auto page = c.Get("/reports/sweep-a/report.html");
  ASSERT_EQ(page->status, 200);
  EXPECT_EQ(page->get_header_value("Content-Type"), "text/html; charset=utf-8");
  EXPECT_EQ(page->get_header_value("Content-Security-Policy").find("script-src"), std::string::npos) << "no scripts run";
  auto plot = c.Get("/reports/sweep-a/plots/p.svg");
  ASSERT_EQ(plot->status, 200);
  EXPECT_EQ(plot->get_header_value("Content-Type"), "image/svg+xml");
  // Outside the folder, through a symlink, hidden, of an unknown type, or with '..': 404.
  for (const std::string path : {"/reports/sweep-a/link.html", "/reports/sweep-a/results.bin", "/reports/../secret.html",
                                 "/reports/sweep-a/..%2f..%2fsecret.html", "/reports/sweep-a/plots/../../../secret.html",
                                 "/reports/.hidden/report.html", "/reports/sweep-a/missing.html"}) {
    auto r = c.Get(path.c_str());
    ASSERT_TRUE(r) << path;
    EXPECT_EQ(r->status, 404) << path << ": " << r->body;
    EXPECT_EQ(r->body.find("TOP-SECRET-CONTENT"), std::string::npos) << path;
  }
  std::filesystem::remove_all(root);
}

TEST(Sessions, TheViewerIsSameOriginWithAStrictPolicyAndOffWhenExposedWithoutAToken) {
  {
    TestServer s;
    auto c = s.client();
    auto page = c.Get("/ui/");
    ASSERT_EQ(page->status, 200) << page->body;
    EXPECT_EQ(page->get_header_value("Content-Type"), "text/html; charset=utf-8");
    const std::string csp = page->get_header_value("Content-Security-Policy");
    EXPECT_NE(csp.find("default-src 'none'"), std::string::npos) << csp;
    EXPECT_NE(csp.find("script-src 'self'"), std::string::npos) << csp;
    EXPECT_NE(csp.find("frame-ancestors 'none'"), std::string::npos) << csp;
    EXPECT_FALSE(page->has_header("Access-Control-Allow-Origin"));
    EXPECT_NE(page->body.find("viewer.js"), std::string::npos);
    EXPECT_EQ(c.Get("/ui/viewer.js")->get_header_value("Content-Type"), "text/javascript; charset=utf-8");
    EXPECT_EQ(c.Get("/ui")->status, 308);
    // No page loads code from elsewhere: every src and href is relative.
    for (const std::string attr : {"src=\"http", "href=\"http", "src=\"//", "href=\"//"})
      EXPECT_EQ(page->body.find(attr), std::string::npos) << attr;
  }
  {
    ServerConfig exposed;
    exposed.host = "0.0.0.0";
    EXPECT_FALSE(radiant::server::uiServed(exposed));
    exposed.token = "secret";
    EXPECT_TRUE(radiant::server::uiServed(exposed));
    exposed.ui = false;
    EXPECT_FALSE(radiant::server::uiServed(exposed));
  }
  {
    // Behind a token the page loads without one (it asks for it), the API does not.
    ServerConfig guarded;
    guarded.token = "secret";
    TestServer s(guarded);
    auto c = s.client();
    EXPECT_EQ(c.Get("/ui/")->status, 200);
    EXPECT_EQ(post(c, sessionBody(1))->status, 401);
  }
}

}  // namespace
