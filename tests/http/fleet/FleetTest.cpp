// Three radiantd behind nginx on loopback (deploy/nginx/radiant.conf as shipped, with the daemons'
// ephemeral ports put into its two daemon files): a sweep through the proxy, scene affinity, async
// jobs on any daemon, bad routing input, and failover when a daemon dies mid-sweep.
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <signal.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include <iostream>
#include <map>
#include <memory>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "api/Sha256.h"
#include "tests/support/DaemonProcess.h"

using nlohmann::json;
using radiant::testing::Daemon;
using radiant::testing::scratch;
using radiant::testing::slurp;
namespace fs = std::filesystem;

namespace {

constexpr const char* kIds[] = {"d0", "d1", "d2"};

int freePort() {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = 0;
  bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a);
  socklen_t len = sizeof a;
  getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
  close(fd);
  return ntohs(a.sin_port);
}

pid_t spawn(const std::vector<std::string>& argv, const fs::path& out, const fs::path& err) {
  const pid_t pid = fork();
  if (pid == 0) {
    int o = open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    int e = open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(o, STDOUT_FILENO);
    dup2(e, STDERR_FILENO);
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    execv(args[0], args.data());
    _exit(127);
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

std::string replaceAll(std::string s, const std::string& from, const std::string& to) {
  std::size_t at = 0, n = 0;
  while ((at = s.find(from, at)) != std::string::npos) s.replace(at, from.size(), to), at += to.size(), ++n;
  EXPECT_GT(n, 0u) << "\"" << from << "\" not in the shipped config";
  return s;
}

std::vector<json> records(const fs::path& p) {
  std::vector<json> out;
  std::istringstream in(slurp(p));
  std::string l;
  while (std::getline(in, l))
    if (!l.empty()) out.push_back(json::parse(l, nullptr, false));
  return out;
}

// radiant_renders_total{result="done"} of one daemon, from its own /metrics.
int rendersDone(const Daemon& d) {
  auto r = d.client().Get("/metrics");
  if (!r) return -1;
  std::smatch m;
  if (std::regex_search(r->body, m, std::regex(R"(radiant_renders_total\{result="done"\} (\d+))"))) return std::stoi(m[1]);
  return 0;
}

std::string problemType(const httplib::Result& r) {
  if (!r) return "<no answer>";
  const json p = json::parse(r->body, nullptr, false);
  if (!p.is_object() || r->get_header_value("Content-Type") != "application/problem+json")
    return "<not problem+json: " + r->get_header_value("Content-Type") + ": " + r->body.substr(0, 200) + ">";
  const std::string t = p.value("type", "");
  return t.substr(t.rfind('/') + 1);
}

// The shipped scene with k trailing newlines: another file, another digest.
std::string sceneVariant(int k) {
  return slurp(fs::path(RADIANT_SOURCE_DIR) / "scenes" / "cornell_box.gltf") + std::string(static_cast<std::size_t>(k + 1), '\n');
}

json pngRequest(const std::string& digest, int pcfRadius) {
  return {{"scene", {{"digest", digest}}},
          {"width", 32},
          {"height", 32},
          {"passes", {{"photon_gi", false}, {"direct", {{"pcf_radius", pcfRadius}}}}},
          {"outputs", {{{"format", "png"}, {"aovs", {"beauty"}}}}}};
}

class Fleet : public ::testing::Test {
protected:
  static constexpr int kScenes = 8;

  static void SetUpTestSuite() {
    dir_ = new fs::path(scratch("fleet"));
    const fs::path& d = *dir_;
    for (int i = 0; i < 3; ++i) {
      daemons_[i] = new Daemon(RADIANTD_PATH, {"--port", "0", "--daemon-id", kIds[i]}, {},
                               d / ("radiantd-" + std::string(kIds[i]) + ".log"));
      ASSERT_GT(daemons_[i]->port(), 0) << daemons_[i]->firstLine();
    }
    // The shipped config: only the listen port and the daemons' addresses change.
    const fs::path shipped = fs::path(RADIANT_SOURCE_DIR) / "deploy" / "nginx";
    port_ = freePort();
    std::ofstream(d / "radiant.conf") << replaceAll(slurp(shipped / "radiant.conf"), "listen 8080;",
                                                    "listen 127.0.0.1:" + std::to_string(port_) + ";");
    std::string fleetConf = slurp(shipped / "radiant.fleet"), daemonsConf = slurp(shipped / "radiant.daemons");
    for (int i = 0; i < 3; ++i) {
      const std::string from = "127.0.0.1:" + std::to_string(8081 + i), to = "127.0.0.1:" + std::to_string(daemons_[i]->port());
      fleetConf = replaceAll(fleetConf, from, to);
      daemonsConf = replaceAll(daemonsConf, from, to);
    }
    std::ofstream(d / "radiant.fleet") << fleetConf;
    std::ofstream(d / "radiant.daemons") << daemonsConf;
    const std::string p = d.string();
    std::ofstream(d / "nginx.conf") << "pid " << p << "/nginx.pid;\nerror_log " << p << "/error.log warn;\n"
                                    << "daemon off;\nmaster_process off;\nevents { worker_connections 512; }\n"
                                    << "http {\n  log_format up '$request_method $uri $status $upstream_addr $upstream_status';\n"
                                    << "  access_log " << p << "/access.log up;\n"
                                    << "  client_body_temp_path " << p << "/body;\n  proxy_temp_path " << p << "/proxy;\n"
                                    << "  fastcgi_temp_path " << p << "/fcgi;\n  uwsgi_temp_path " << p << "/uwsgi;\n"
                                    << "  scgi_temp_path " << p << "/scgi;\n  include radiant.conf;\n}\n";
    nginx_ = spawn({NGINX_PATH, "-p", p, "-c", p + "/nginx.conf"}, d / "nginx.out", d / "nginx.err");
    for (auto* dm : daemons_) ASSERT_TRUE(dm->waitReady(std::chrono::seconds(120)));
    httplib::Client c = proxy();
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    bool up = false;
    while (!up && std::chrono::steady_clock::now() < end) {
      auto r = c.Get("/v1/ready");
      up = r && r->status == 200;
      if (!up) std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    ASSERT_TRUE(up) << slurp(d / "nginx.err") << slurp(d / "error.log");
    for (int k = 0; k < kScenes; ++k) {
      scenes_[k] = sceneVariant(k);
      digests_[k] = radiant::api::sceneDigest(scenes_[k]);
      std::ofstream(d / ("scene" + std::to_string(k) + ".gltf"), std::ios::binary) << scenes_[k];
    }
  }
  static void TearDownTestSuite() {
    if (nginx_ > 0) {
      kill(nginx_, SIGTERM);
      waitExit(nginx_, std::chrono::seconds(10));
    }
    for (auto*& dm : daemons_) delete dm, dm = nullptr;
    if (!::testing::Test::HasFailure()) fs::remove_all(*dir_);
    delete dir_;
  }

  static httplib::Client proxy() {
    httplib::Client c("127.0.0.1", port_);
    c.set_read_timeout(300, 0);
    c.set_connection_timeout(10, 0);
    return c;
  }
  static std::string proxyUrl() { return "http://127.0.0.1:" + std::to_string(port_); }
  static int indexOf(const std::string& id) {
    for (int i = 0; i < 3; ++i)
      if (id == kIds[i]) return i;
    return -1;
  }

  // A render request through the proxy (routed on its scene), and its first frame fetched through it.
  static std::pair<json, std::string> renderThroughProxy(const json& request) {
    auto c = proxy();
    auto r = c.Post("/v1/renders", {{"X-Radiant-Scene", request["scene"]["digest"].get<std::string>()}}, request.dump(),
                    "application/json");
    if (!r || r->status != 200) {
      ADD_FAILURE() << "render through the proxy: " << (r ? r->body : "no answer");
      return {};
    }
    const json result = json::parse(r->body);
    auto f = c.Get(result["frames"][0]["url"].get<std::string>());
    EXPECT_TRUE(f && f->status == 200);
    return {result, f ? f->body : ""};
  }

  static inline Daemon* daemons_[3] = {};
  static inline pid_t nginx_ = -1;
  static inline int port_ = 0;
  static inline fs::path* dir_ = nullptr;
  static inline std::string scenes_[kScenes], digests_[kScenes];
};

// A spec of kScenes files x 3 settings of `axis` (24 points), one render each.
json fleetSpec(const std::string& name, const std::string& filePrefix, const json& base, const std::string& axis,
               const json& values) {
  json files = json::array();
  for (int k = 0; k < 8; ++k) files.push_back(filePrefix + std::to_string(k) + ".gltf");
  return {{"name", name}, {"base", base}, {"axes", {{"scene.file", files}, {axis, values}}}, {"repeats", 1}, {"warmup", 0}};
}

}  // namespace

TEST_F(Fleet, SweepThroughTheProxyMatchesOneDaemonAndKeepsEachSceneOnOneDaemon) {
  const fs::path& d = *dir_;
  json base = pngRequest("", 0);
  base.erase("scene");
  base["scene"] = {{"file", "scene0.gltf"}};
  std::ofstream(d / "sweep.json") << fleetSpec("fleet", "scene", base, "passes.direct.pcf_radius", {0, 1, 2}).dump(2);
  int before[3];
  for (int i = 0; i < 3; ++i) before[i] = rendersDone(*daemons_[i]);
  const pid_t client = spawn({RADIANT_CLIENT_PATH, "--server", proxyUrl(), "sweep", (d / "sweep.json").string(), "-o",
                              (d / "sweep.jsonl").string(), "--inflight", "3"},
                             d / "sweep.out", d / "sweep.err");
  ASSERT_EQ(waitExit(client, std::chrono::seconds(240)), 0) << slurp(d / "sweep.err");
  const auto recs = records(d / "sweep.jsonl");
  ASSERT_EQ(recs.size(), 24u) << slurp(d / "sweep.err");
  std::set<std::string> ids;
  std::map<std::string, std::set<std::string>> daemonsOfScene;
  int perDaemon[3] = {0, 0, 0};
  for (const auto& rec : recs) {
    ASSERT_FALSE(rec.contains("error")) << rec.dump();
    ids.insert(rec["point_id"].get<std::string>());
    EXPECT_EQ(rec["server"], proxyUrl());
    ASSERT_EQ(rec["daemons"].size(), 1u) << rec.dump();
    const std::string daemon = rec["daemons"][0];
    ASSERT_GE(indexOf(daemon), 0) << daemon;
    ++perDaemon[indexOf(daemon)];
    daemonsOfScene[rec["request"]["scene"]["digest"].get<std::string>()].insert(daemon);
  }
  EXPECT_EQ(ids.size(), 24u);
  // Affinity: every scene rendered on one daemon; the 8 scenes spread over more than one (all on one
  // daemon by chance: 3 x 3^-8 = 0.05%).
  ASSERT_EQ(daemonsOfScene.size(), 8u);
  std::set<std::string> used;
  for (const auto& [digest, ds] : daemonsOfScene) {
    EXPECT_EQ(ds.size(), 1u) << digest;
    used.insert(ds.begin(), ds.end());
  }
  EXPECT_GE(used.size(), 2u);
  // Each daemon's own /metrics counts exactly the renders the records put on it.
  for (int i = 0; i < 3; ++i) EXPECT_EQ(rendersDone(*daemons_[i]) - before[i], perDaemon[i]) << kIds[i];

  // Every point's frame through the proxy equals the same request rendered by d0 directly.
  auto direct = daemons_[0]->client();
  for (int k = 0; k < kScenes; ++k) direct.Put("/v1/scenes", scenes_[k], "model/gltf+json");
  for (const auto& rec : recs) {
    const json request = rec["request"];
    const auto [viaProxy, proxyFrame] = renderThroughProxy(request);
    auto r = direct.Post("/v1/renders", request.dump(), "application/json");
    ASSERT_TRUE(r && r->status == 200) << (r ? r->body : "");
    auto f = direct.Get(json::parse(r->body)["frames"][0]["url"].get<std::string>());
    ASSERT_TRUE(f && f->status == 200);
    ASSERT_GT(proxyFrame.size(), 8u);
    EXPECT_EQ(proxyFrame.substr(1, 3), "PNG");
    EXPECT_TRUE(proxyFrame == f->body) << rec["params"].dump() << ": the frame through the proxy (" << proxyFrame.size()
                                       << " bytes) differs from d0's (" << f->body.size() << " bytes)";
  }
}

TEST_F(Fleet, AsyncJobsOnAnyDaemonArePolledFetchedAndCanceledThroughTheProxy) {
  auto c = proxy();
  std::set<std::string> owners;
  for (int k = 0; k < kScenes; ++k) {
    ASSERT_EQ(c.Put("/v1/scenes", {{"X-Radiant-Scene", digests_[k]}}, scenes_[k], "model/gltf+json")->status / 100, 2);
    json request = pngRequest(digests_[k], 1);
    request["async"] = true;
    auto r = c.Post("/v1/renders", {{"X-Radiant-Scene", digests_[k]}}, request.dump(), "application/json");
    ASSERT_TRUE(r && r->status == 202) << (r ? r->body : "");
    const std::string id = json::parse(r->body)["id"];
    std::smatch m;
    ASSERT_TRUE(std::regex_match(id, m, std::regex(R"((d[0-2])-r-[0-9a-f]{16})"))) << id;
    const std::string owner = m[1];
    owners.insert(owner);
    EXPECT_EQ(r->get_header_value("X-Radiant-Daemon"), owner);
    const std::string location = r->get_header_value("Location");
    EXPECT_EQ(location, "/v1/renders/" + id);
    json job;
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(120);
    do {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      auto g = c.Get(location);
      ASSERT_TRUE(g && g->status == 200) << (g ? g->body : "");
      EXPECT_EQ(g->get_header_value("X-Radiant-Daemon"), owner);
      job = json::parse(g->body);
    } while (job["state"] != "done" && job["state"] != "failed" && std::chrono::steady_clock::now() < end);
    ASSERT_EQ(job["state"], "done") << job.dump();
    const std::string url = job["frames"][0]["url"];
    auto viaProxy = c.Get(url);
    auto fromOwner = daemons_[indexOf(owner)]->client().Get(url);
    ASSERT_TRUE(viaProxy && viaProxy->status == 200 && fromOwner && fromOwner->status == 200);
    EXPECT_EQ(viaProxy->get_header_value("Content-Type"), "image/png");
    EXPECT_TRUE(viaProxy->body == fromOwner->body) << url;
    // The same hex under another daemon's prefix: that daemon's own 404, never this job or its frames.
    const std::string other = kIds[(indexOf(owner) + 1) % 3];
    const std::string forged = other + id.substr(owner.size());
    EXPECT_EQ(problemType(c.Get("/v1/renders/" + forged)), "unknown-render");
    auto ff = c.Get("/v1/frames/" + forged + "/" + job["frames"][0]["name"].get<std::string>());
    EXPECT_EQ(problemType(ff), "unknown-frame");
    EXPECT_EQ(ff ? ff->status : 0, 404);
    EXPECT_EQ(ff ? ff->get_header_value("X-Radiant-Daemon") : "", other);
    EXPECT_EQ(c.Delete(location)->status, 200);  // forget it (frames freed)
  }
  EXPECT_GE(owners.size(), 2u) << "8 scenes all hashed to one daemon (chance 0.05%)";

  // Cancel: a long reference render, canceled through the proxy while it runs or waits.
  json slow = pngRequest(digests_[0], 1);
  slow["width"] = slow["height"] = 128;
  slow["passes"] = {{"photon_gi", false}, {"reference", {{"spp", 4096}, {"max_bounces", 8}}}};
  slow["async"] = true;
  auto r = c.Post("/v1/renders", {{"X-Radiant-Scene", digests_[0]}}, slow.dump(), "application/json");
  ASSERT_TRUE(r && r->status == 202) << (r ? r->body : "");
  const std::string location = r->get_header_value("Location");
  auto del = c.Delete(location);
  ASSERT_TRUE(del && (del->status == 200 || del->status == 202)) << (del ? del->body : "");
  EXPECT_EQ(json::parse(del->body).value("deleted", false), false) << "the render finished before the cancel";
  json job;
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  do {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    auto g = c.Get(location);
    if (g && g->status == 404) break;  // canceled while queued: removed at once
    ASSERT_TRUE(g && g->status == 200);
    job = json::parse(g->body);
  } while ((job["state"] == "queued" || job["state"] == "running" || job["state"] == "encoding") &&
           std::chrono::steady_clock::now() < end);
  // Canceled while queued: removed (404); while rendering: "canceled" with the 409 "canceled" problem,
  // whether the renderer stopped between passes or finished first.
  if (!job.is_null()) {
    EXPECT_EQ(job["state"], "canceled") << job.dump();
    EXPECT_EQ(job["error"]["status"], 409) << job.dump();
    EXPECT_EQ(job["error"]["type"], "https://radiant.dev/problems/canceled") << job.dump();
  }
}

TEST_F(Fleet, BadRoutingInputGetsAProblemNeverAnotherDaemonsJob) {
  auto c = proxy();
  // Unknown daemon ids, and ids without one.
  for (const std::string path : {"/v1/renders/d9-r-0123456789abcdef", "/v1/frames/d9-r-0123456789abcdef/beauty.png",
                                 "/v1/renders/r-0123456789abcdef", "/v1/frames/zz/beauty.exr"}) {
    auto r = c.Get(path);
    ASSERT_TRUE(r) << path;
    EXPECT_EQ(r->status, 404) << path;
    EXPECT_EQ(problemType(r), "unknown-daemon") << path;
  }
  EXPECT_EQ(problemType(c.Delete("/v1/renders/d9-r-0123456789abcdef")), "unknown-daemon");
  // A malformed digest header: refused by the proxy before any daemon sees it.
  const json request = pngRequest(digests_[0], 1);
  auto r = c.Post("/v1/renders", {{"X-Radiant-Scene", "sha256:not-a-digest"}}, request.dump(), "application/json");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 400);
  EXPECT_EQ(problemType(r), "invalid-scene-header");
  // A well-formed digest of another scene: the daemon it reaches refuses it (it would strand the scene
  // on a daemon its renders never reach).
  ASSERT_EQ(c.Put("/v1/scenes", {{"X-Radiant-Scene", digests_[0]}}, scenes_[0], "model/gltf+json")->status / 100, 2);
  r = c.Post("/v1/renders", {{"X-Radiant-Scene", digests_[1]}}, request.dump(), "application/json");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 400);
  EXPECT_EQ(problemType(r), "scene-header-mismatch");
  EXPECT_EQ(json::parse(r->body).value("pointer", ""), "/scene");
  r = c.Put("/v1/scenes", {{"X-Radiant-Scene", digests_[1]}}, scenes_[2], "model/gltf+json");
  EXPECT_EQ(r->status, 400);
  EXPECT_EQ(problemType(r), "scene-header-mismatch");
  r = c.Head("/v1/scenes/" + digests_[0], {{"X-Radiant-Scene", digests_[1]}});
  EXPECT_EQ(r->status, 400);
  // Without the header a HEAD still routes to the scene's daemon (on the digest in its path).
  r = c.Head("/v1/scenes/" + digests_[0]);
  EXPECT_EQ(r->status, 200);
}

// It kills a daemon: last when the binary runs whole (gtest keeps the order); under CTest each test
// runs in its own process with its own fleet.
TEST_F(Fleet, ZFailoverADaemonKilledMidSweepLosesNoPoint) {
  const fs::path& d = *dir_;
  json base = pngRequest("", 0);
  base["scene"] = {{"file", "scene0.gltf"}};
  base["width"] = base["height"] = 48;
  base["passes"] = {{"photon_gi", false}, {"reference", {{"spp", 48}, {"max_bounces", 3}}}};
  // Scenes no daemon has yet (test 1 gave d0 all of its own).
  for (int k = 0; k < kScenes; ++k)
    std::ofstream(d / ("fo" + std::to_string(k) + ".gltf"), std::ios::binary) << sceneVariant(kScenes + k);
  // The axis sorts before "scene.file", so the scene varies fastest: by the kill, every scene has been
  // uploaded to its daemon, and the victim's must be uploaded again where they move.
  std::ofstream(d / "failover.json") << fleetSpec("failover", "fo", base, "passes.reference.max_bounces", {2, 3, 4}).dump(2);
  const fs::path out = d / "failover.jsonl";
  const pid_t client = spawn({RADIANT_CLIENT_PATH, "--server", proxyUrl(), "sweep", (d / "failover.json").string(), "-o",
                              out.string(), "--inflight", "2"},
                             d / "failover.out", d / "failover.err");
  // Kill the daemon that rendered the first recorded point, once 10 points are in. The client is
  // stopped (SIGSTOP) around the kill, so that on a machine fast enough to finish the sweep between two
  // polls the kill still lands mid-sweep: what is recorded at the stop is all there is until SIGCONT.
  // The deadlines (100 s + 170 s) stay within the test's CTest timeout (300 s).
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(100);
  while (std::chrono::steady_clock::now() < end && (!fs::exists(out) || records(out).size() < 10))
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ::kill(client, SIGSTOP);
  const auto early = records(out);
  ASSERT_GE(early.size(), 10u) << slurp(d / "failover.err");
  const std::string victim = early[0]["daemons"][0];
  Daemon* dead = daemons_[indexOf(victim)];
  dead->signal(SIGKILL);
  dead->wait();
  const std::size_t atKill = records(out).size();
  ::kill(client, SIGCONT);
  ASSERT_LT(atKill, 24u) << "the sweep finished before the kill: nothing tested";
  ASSERT_EQ(waitExit(client, std::chrono::seconds(170)), 0) << slurp(d / "failover.err");
  const std::string err = slurp(d / "failover.err");
  const auto recs = records(out);
  ASSERT_EQ(recs.size(), 24u) << err;
  std::set<std::string> ids;
  std::set<std::pair<std::string, int>> points;
  std::size_t onVictim = 0;
  for (const auto& rec : recs) {
    EXPECT_FALSE(rec.contains("error")) << rec.dump();
    ids.insert(rec["point_id"].get<std::string>());
    points.insert({rec["request"]["scene"]["digest"].get<std::string>(), rec["params"]["passes.reference.max_bounces"].get<int>()});
    onVictim += rec["daemons"][0] == victim;
  }
  EXPECT_EQ(ids.size(), 24u) << "a point recorded twice";
  EXPECT_EQ(points.size(), 24u);
  // Points finished on the victim were in before it died (2 more may have been answered, not yet written).
  EXPECT_LE(onVictim, atKill + 2);
  // Its scenes moved to the others, which did not have them: the client uploaded them again.
  EXPECT_NE(err.find("re-uploaded"), std::string::npos) << err;
  // What the failover took (for the record, not asserted): re-uploads, and from nginx's log the answers
  // it passed on to another daemon ("addr1, addr2") and the 502s the client saw and retried.
  int reuploads = 0, passedOn = 0, badGateway = 0;
  for (std::size_t at = 0; (at = err.find("re-uploaded", at)) != std::string::npos; ++at) ++reuploads;
  std::istringstream log(slurp(d / "access.log"));
  for (std::string l; std::getline(log, l);) {
    passedOn += l.find(", ") != std::string::npos;
    badGateway += l.find(" 502 ") != std::string::npos;
  }
  std::cout << "failover: killed " << victim << " after " << atKill << " of 24 points; " << onVictim
            << " points on it in all; " << reuploads << " scene re-uploads; nginx passed " << passedOn
            << " requests on to another daemon and answered 502 to " << badGateway << "\n";
}

// Sessions through the proxy: opened on the daemon holding the scene, and every session URL (the event
// stream included, passed on as it comes: X-Accel-Buffering) routed to the daemon that owns it.
TEST_F(Fleet, SessionsAreRoutedToTheirDaemonAndTheirEventsStreamThroughTheProxy) {
  auto c = proxy();
  ASSERT_EQ(c.Put("/v1/scenes", {{"X-Radiant-Scene", digests_[3]}}, scenes_[3], "model/gltf+json")->status / 100, 2);
  const json request = {{"scene", {{"digest", digests_[3]}}}, {"width", 16}, {"height", 16}, {"refine", {{"max_batches", 2}}}};
  auto r = c.Post("/v1/sessions", {{"X-Radiant-Scene", digests_[3]}}, request.dump(), "application/json");
  ASSERT_TRUE(r && r->status == 201) << (r ? r->body : "");
  const std::string id = json::parse(r->body)["id"];
  std::smatch m;
  ASSERT_TRUE(std::regex_match(id, m, std::regex(R"((d[0-2])-s-[0-9a-f]{16})"))) << id;
  const std::string owner = m[1];
  EXPECT_EQ(r->get_header_value("X-Radiant-Daemon"), owner);
  // The stream delivers `done` while it is still open: nginx does not hold the events back.
  std::string events;
  auto stream = proxy();
  stream.set_read_timeout(120, 0);
  auto sr = stream.Get("/v1/sessions/" + id + "/events", [&](const char* data, std::size_t n) {
    events.append(data, n);
    return events.find("event: done") == std::string::npos;
  });
  EXPECT_NE(events.find("event: frame"), std::string::npos) << events;
  EXPECT_NE(events.find("event: done"), std::string::npos) << events;
  auto frame = c.Get("/v1/sessions/" + id + "/frame");
  ASSERT_TRUE(frame && frame->status == 200) << (frame ? frame->body : "");
  EXPECT_EQ(frame->get_header_value("Content-Type"), "image/png");
  EXPECT_EQ(frame->get_header_value("X-Radiant-Daemon"), owner);
  auto changed = c.Patch("/v1/sessions/" + id, R"({"seed": 3})", "application/merge-patch+json");
  ASSERT_TRUE(changed && changed->status == 200) << (changed ? changed->body : "");
  EXPECT_EQ(json::parse(changed->body)["generation"], 1);
  // Another daemon's prefix on the same hex: that daemon's own 404.
  const std::string other = kIds[(indexOf(owner) + 1) % 3];
  auto forged = c.Get("/v1/sessions/" + other + id.substr(owner.size()));
  EXPECT_EQ(problemType(forged), "unknown-session");
  EXPECT_EQ(forged ? forged->get_header_value("X-Radiant-Daemon") : "", other);
  EXPECT_EQ(c.Delete("/v1/sessions/" + id)->status, 200);
  EXPECT_EQ(problemType(c.Get("/v1/sessions/" + id)), "unknown-session");
}

// A single `radiant render` through the proxy survives the loss of its daemon in the middle of the
// render: the proxy answers 502, the client sends the render again, the next daemon on the ring lacks
// the scene (404 unknown-scene), the client uploads it there, and the frame is the one the same request
// gives on a daemon directly.
TEST_F(Fleet, SingleRenderSurvivesItsDaemonDyingMidRender) {
  const fs::path& d = *dir_;
  const std::string scene = sceneVariant(40);
  const std::string digest = radiant::api::sceneDigest(scene);
  std::ofstream(d / "rf.gltf", std::ios::binary) << scene;
  auto c = proxy();
  auto put = c.Put("/v1/scenes", {{"X-Radiant-Scene", digest}}, scene, "model/gltf+json");
  ASSERT_TRUE(put);
  ASSERT_EQ(put->status / 100, 2) << put->body;
  const std::string owner = put->get_header_value("X-Radiant-Daemon");
  ASSERT_GE(indexOf(owner), 0) << owner;
  Daemon* victim = daemons_[indexOf(owner)];
  // Long enough to be killed in the middle of: the reference at 48x48 takes seconds on llvmpipe.
  const json options = {{"width", 48},
                        {"height", 48},
                        {"passes", {{"photon_gi", false}, {"reference", {{"spp", 256}, {"max_bounces", 3}}}}}};
  std::ofstream(d / "rf.json") << options.dump();
  const std::vector<std::string> args = {RADIANT_CLIENT_PATH, "--server", proxyUrl(), "render", (d / "rf.gltf").string(),
                                         "--request", (d / "rf.json").string(), "-o", (d / "rf.png").string()};
  const pid_t client = spawn(args, d / "rf.out", d / "rf.err");
  bool rendering = false;
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (!rendering && std::chrono::steady_clock::now() < end) {
    auto m = victim->client().Get("/metrics");
    rendering = m && m->body.find("\nradiant_jobs_active 1") != std::string::npos;
    if (!rendering) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_TRUE(rendering) << "the render never started on " << owner << ": " << slurp(d / "rf.err");
  victim->signal(SIGKILL);
  victim->wait();
  ASSERT_EQ(waitExit(client, std::chrono::seconds(300)), 0) << slurp(d / "rf.err");
  const std::string err = slurp(d / "rf.err");
  EXPECT_NE(err.find("sending the render again"), std::string::npos) << err;
  EXPECT_NE(err.find("uploading it again"), std::string::npos) << err;
  // The same request (the client's own, from --dry-run) on a surviving daemon, directly.
  std::vector<std::string> dry = args;
  dry.push_back("--dry-run");
  ASSERT_EQ(waitExit(spawn(dry, d / "rf-dry.out", d / "rf-dry.err"), std::chrono::seconds(60)), 0) << slurp(d / "rf-dry.err");
  const json request = json::parse(slurp(d / "rf-dry.out"));
  Daemon* survivor = daemons_[(indexOf(owner) + 1) % 3];
  auto direct = survivor->client();
  direct.set_read_timeout(300, 0);
  ASSERT_EQ(direct.Put("/v1/scenes", scene, "model/gltf+json")->status / 100, 2);
  auto r = direct.Post("/v1/renders", request.dump(), "application/json");
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  auto frame = direct.Get(json::parse(r->body)["frames"][0]["url"].get<std::string>());
  ASSERT_TRUE(frame);
  EXPECT_TRUE(frame->body == slurp(d / "rf.png")) << "the failed-over frame differs from the direct render";
}
