// The viewer (/ui/) in a real browser: headless Chromium (Debian's `chromium`, scripts/setup.sh)
// driven through its DevTools protocol over a pipe (--remote-debugging-pipe: JSON messages ended by
// NUL on fds 3 and 4), against the real radiantd on llvmpipe or a GPU. The test opens a built-in
// scene in the page, waits for the refined frame and checks that the page shows exactly the daemon's
// PNG; drags the mouse and checks the camera of the next frame's stats; moves the quality slider and
// checks the session's configuration; and checks the event stream's order and that it ends with the
// session. It records the time from a camera change to its first frame on screen (docs/PERFORMANCE.md).
// And 500 sessions against the same daemon leave neither resident nor GL memory behind.
// Without Chromium it skips, and says so.
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <httplib.h>
#include <nlohmann/json.hpp>

#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>

#include "tests/support/DaemonProcess.h"

namespace radiant {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

std::string chromiumPath() {
  if (const char* p = std::getenv("RADIANT_CHROMIUM")) return p;
  for (const char* p : {"/usr/bin/chromium", "/usr/bin/chromium-browser", "/usr/bin/google-chrome"})
    if (fs::exists(p)) return p;
  return "";
}

// A browser and one page, spoken to with the DevTools protocol over a pipe.
class Browser {
public:
  Browser(const std::string& exe, const fs::path& profile) {
    int toChrome[2], fromChrome[2];
    if (pipe(toChrome) != 0 || pipe(fromChrome) != 0) throw std::runtime_error("pipe");
    pid_ = fork();
    if (pid_ == 0) {
      // fds 3 (commands in) and 4 (answers out); moved high first so that dup2 cannot clobber them.
      const int in = fcntl(toChrome[0], F_DUPFD, 10), out = fcntl(fromChrome[1], F_DUPFD, 10);
      dup2(in, 3);
      dup2(out, 4);
      const int devnull = ::open("/dev/null", O_WRONLY);
      dup2(devnull, 1);
      dup2(devnull, 2);
      for (int fd = 5; fd < 256; ++fd) close(fd);
      const std::string dir = "--user-data-dir=" + profile.string();
      execl(exe.c_str(), exe.c_str(), "--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
            "--disable-extensions", "--disable-background-networking", "--remote-debugging-pipe",
            "--window-size=1400,1000", dir.c_str(), "about:blank", static_cast<char*>(nullptr));
      _exit(127);
    }
    close(toChrome[0]);
    close(fromChrome[1]);
    out_ = toChrome[1];
    in_ = fromChrome[0];
  }
  ~Browser() {
    if (pid_ > 0) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
    close(out_);
    close(in_);
  }

  // Sends a command (to the page once attached) and returns its result; throws on an error answer.
  json call(const std::string& method, json params = json::object(), double timeoutS = 60) {
    const int id = next_++;
    json msg{{"id", id}, {"method", method}, {"params", std::move(params)}};
    if (!session_.empty()) msg["sessionId"] = session_;
    const std::string text = msg.dump() + std::string(1, '\0');
    if (write(out_, text.data(), text.size()) != static_cast<ssize_t>(text.size())) throw std::runtime_error("write to chromium");
    const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(static_cast<long>(timeoutS * 1000));
    for (;;) {
      const json m = read(end);
      if (m.value("id", -1) != id) continue;  // an event, or another command's answer
      if (m.contains("error")) throw std::runtime_error(method + ": " + m["error"].dump());
      return m.value("result", json::object());
    }
  }
  void open(const std::string& url) {
    const std::string target = call("Target.createTarget", {{"url", url}})["targetId"];
    session_ = call("Target.attachToTarget", {{"targetId", target}, {"flatten", true}})["sessionId"];
  }
  // Evaluates an expression in the page (a promise is awaited) and returns its value.
  json eval(const std::string& expression, double timeoutS = 60) {
    const json r = call("Runtime.evaluate", {{"expression", expression}, {"awaitPromise", true}, {"returnByValue", true}}, timeoutS);
    if (r.contains("exceptionDetails")) throw std::runtime_error("page: " + r["exceptionDetails"].dump());
    return r["result"].value("value", json());
  }
  // Polls `predicate` (a JavaScript expression) every 20 ms in the page, for up to timeoutS.
  // While the page is still loading its context can go away under an evaluation: tried again then.
  bool waitFor(const std::string& predicate, double timeoutS) {
    for (int attempt = 0;; ++attempt) {
      try {
        return waitOnce(predicate, timeoutS);
      } catch (const std::runtime_error& e) {
        if (attempt >= 50 || std::string(e.what()).find("context") == std::string::npos) throw;
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
      }
    }
  }
  bool waitOnce(const std::string& predicate, double timeoutS) {
    return eval("new Promise((done) => { const t0 = performance.now(); (function check() { let ok = false; "
                "try { ok = !!(" + predicate + "); } catch (e) {} if (ok) done(true); else if (performance.now() - t0 > " +
                    std::to_string(timeoutS * 1000) + ") done(false); else setTimeout(check, 20); })(); })",
                timeoutS + 30) == true;
  }
  void mouse(const std::string& type, double x, double y) {
    call("Input.dispatchMouseEvent", {{"type", type}, {"x", x}, {"y", y}, {"button", "left"},
                                      {"buttons", type == "mouseReleased" ? 0 : 1}, {"clickCount", type == "mouseMoved" ? 0 : 1}});
  }

private:
  json read(std::chrono::steady_clock::time_point end) {
    for (;;) {
      if (auto nul = buffer_.find('\0'); nul != std::string::npos) {
        const std::string text = buffer_.substr(0, nul);
        buffer_.erase(0, nul + 1);
        return json::parse(text);
      }
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(end - std::chrono::steady_clock::now()).count();
      if (left <= 0) throw std::runtime_error("chromium did not answer in time");
      pollfd p{in_, POLLIN, 0};
      if (poll(&p, 1, static_cast<int>(left)) <= 0) continue;
      char buf[65536];
      const ssize_t n = ::read(in_, buf, sizeof buf);
      if (n <= 0) throw std::runtime_error("chromium closed its pipe");
      buffer_.append(buf, static_cast<std::size_t>(n));
    }
  }
  pid_t pid_ = -1;
  int out_ = -1, in_ = -1, next_ = 1;
  std::string session_, buffer_;
};

double angleDiff(double a, double b) { return std::remainder(a - b, 360.0); }

// theta (about +Y from +Z towards +X) and phi (from +Y) of the eye around the target, degrees.
std::pair<double, double> orbitOf(const json& camera) {
  double d[3];
  for (int i = 0; i < 3; ++i) d[i] = camera["position"][i].get<double>() - camera["target"][i].get<double>();
  const double r = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  return {std::atan2(d[0], d[2]) * 180 / M_PI, std::acos(d[1] / r) * 180 / M_PI};
}

TEST(Viewer, ThePageShowsTheDaemonsFramesFollowsTheMouseAndTheSliders) {
  const std::string exe = chromiumPath();
  if (exe.empty()) GTEST_SKIP() << "Chromium is not installed (scripts/setup.sh installs Debian's chromium): the viewer is untested here";
  const fs::path dir = testing::scratch("viewer");
  testing::Daemon daemon(RADIANTD_PATH, {"--port", "0"}, {}, dir / "daemon.log");
  ASSERT_GT(daemon.port(), 0) << daemon.firstLine();
  ASSERT_TRUE(daemon.waitReady(std::chrono::seconds(120)));
  const std::string base = "http://127.0.0.1:" + std::to_string(daemon.port());

  Browser browser(exe, dir / "profile");
  browser.open(base + "/ui/");
  ASSERT_TRUE(browser.waitFor("document.getElementById('status').textContent.startsWith('ready')", 60))
      << browser.eval("document.getElementById('status').textContent");
  EXPECT_EQ(browser.eval("document.getElementById('reports').hidden"), true) << "no --reports-dir: no link";

  // Open the Cornell box at 64x64 (RADIANT_VIEWER_SIZE: another size, for docs/PERFORMANCE.md),
  // refining 4 batches.
  const int size = std::getenv("RADIANT_VIEWER_SIZE") ? std::atoi(std::getenv("RADIANT_VIEWER_SIZE")) : 64;
  std::string open = R"(
    document.getElementById('scene').value = 'cornell_box';
    const size = document.getElementById('size');
    size.appendChild(new Option('SIZE', 'SIZE'));
    size.value = 'SIZE';
    document.getElementById('batches').value = '4';
    document.getElementById('open').click();
    true)";
  for (std::size_t at; (at = open.find("SIZE")) != std::string::npos;) open.replace(at, 4, std::to_string(size));
  browser.eval(open);
  ASSERT_TRUE(browser.waitFor("radiantViewer.state.done && radiantViewer.state.drawn && "
                              "radiantViewer.state.drawn.batches === radiantViewer.state.done.batches", 120))
      << browser.eval("JSON.stringify({status: document.getElementById('status').textContent, events: radiantViewer.state.events})");
  const std::string id = browser.eval("radiantViewer.state.session.id");

  // The canvas holds exactly the daemon's PNG of the refined frame.
  auto http = daemon.client();
  auto png = http.Get(("/v1/sessions/" + id + "/frame").c_str());
  ASSERT_EQ(png->status, 200) << png->body;
  EXPECT_EQ(png->get_header_value("X-Radiant-Batches"), "4");
  int w = 0, h = 0, channels = 0;
  unsigned char* pixels = stbi_load_from_memory(reinterpret_cast<const unsigned char*>(png->body.data()),
                                                static_cast<int>(png->body.size()), &w, &h, &channels, 4);
  ASSERT_NE(pixels, nullptr);
  ASSERT_EQ(w, size);
  ASSERT_EQ(h, size);
  const json canvas = browser.eval(R"((() => {
    const c = document.getElementById('frame');
    return Array.from(c.getContext('2d').getImageData(0, 0, c.width, c.height).data); })())");
  ASSERT_EQ(canvas.size(), std::size_t(size * size * 4));
  int maxDiff = 0;
  double sum = 0;
  for (std::size_t i = 0; i < canvas.size(); ++i) {
    if (i % 4 == 3) continue;  // alpha
    maxDiff = std::max(maxDiff, std::abs(canvas[i].get<int>() - int(pixels[i])));
    sum += pixels[i];
  }
  stbi_image_free(pixels);
  EXPECT_EQ(maxDiff, 0) << "the page's image differs from the daemon's PNG";
  EXPECT_GT(sum / (size * size * 3), 10.0) << "the frame is lit";

  // Drag 40 px to the right: the orbit turns by -0.5 degrees per pixel, so theta by -20 degrees.
  const json before = browser.eval("radiantViewer.state.lastFrame.stats.camera");
  const auto [theta0, phi0] = orbitOf(before);
  const int generation0 = browser.eval("radiantViewer.state.generation");
  const json box = browser.eval("(() => { const r = document.getElementById('frame').getBoundingClientRect(); return [r.x, r.y, r.width, r.height]; })()");
  const double x = box[0].get<double>() + box[2].get<double>() / 2, y = box[1].get<double>() + box[3].get<double>() / 2;
  browser.mouse("mousePressed", x, y);
  browser.mouse("mouseMoved", x + 10, y);
  // While the mouse is down the frames come at a quarter of the size (32 px at least).
  ASSERT_TRUE(browser.waitFor("radiantViewer.state.drawn.generation > " + std::to_string(generation0), 60));
  EXPECT_EQ(browser.eval("radiantViewer.state.drawn.width"), std::max(32, size / 4)) << "moving: a quarter of the size";
  for (int step = 2; step <= 4; ++step) browser.mouse("mouseMoved", x + 10 * step, y);
  browser.mouse("mouseReleased", x + 40, y);
  // The release sends the last change (full size); its frame is the one to check.
  ASSERT_TRUE(browser.waitFor("radiantViewer.state.drawn.generation > " + std::to_string(generation0) +
                              " && radiantViewer.state.lastFrame.generation === radiantViewer.state.generation"
                              " && radiantViewer.state.lastFrame.stats.camera.source.startsWith('request')"
                              " && radiantViewer.state.done && radiantViewer.state.done.generation === radiantViewer.state.generation", 120))
      << browser.eval("JSON.stringify(radiantViewer.state.events.slice(-10))");
  const json after = browser.eval("radiantViewer.state.lastFrame.stats.camera");
  const auto [theta1, phi1] = orbitOf(after);
  EXPECT_NEAR(angleDiff(theta1, theta0), -20.0, 0.5) << before << " -> " << after;
  EXPECT_NEAR(phi1, phi0, 0.5) << before << " -> " << after;
  EXPECT_EQ(browser.eval("radiantViewer.state.drawn.width"), size) << "at rest the frame is full size again";
  const json firstFrames = browser.eval("radiantViewer.state.firstFrameMs");
  ASSERT_FALSE(firstFrames.empty());

  // The quality slider: draft. The session's request says so, and the next generation renders it.
  const int generation1 = browser.eval("radiantViewer.state.generation");
  browser.eval(R"((() => { const q = document.getElementById('quality'); q.value = '1';
    q.dispatchEvent(new Event('input')); q.dispatchEvent(new Event('change')); return true; })())");
  ASSERT_TRUE(browser.waitFor("radiantViewer.state.generation > " + std::to_string(generation1) +
                              " && radiantViewer.state.lastFrame.generation === radiantViewer.state.generation", 120));
  const json session = json::parse(http.Get(("/v1/sessions/" + id).c_str())->body);
  EXPECT_EQ(session["request"].value("quality", ""), "draft") << session["request"].dump();
  EXPECT_FALSE(session["request"].contains("time_budget_ms")) << session["request"].dump();
  const json config = browser.eval("radiantViewer.state.lastFrame.stats.budget || null");
  EXPECT_EQ(config.is_object() ? config.value("quality", "") : "", "draft") << config.dump();

  // The session ends (DELETE, as the page does on leaving): the stream's last event is `ended`.
  ASSERT_EQ(http.Delete(("/v1/sessions/" + id).c_str())->status, 200);
  ASSERT_TRUE(browser.waitFor("radiantViewer.state.ended === 'deleted'", 30));
  const json events = browser.eval("radiantViewer.state.events");
  ASSERT_GE(events.size(), 8u);
  EXPECT_EQ(events.front()["event"], "session");
  EXPECT_EQ(events.back()["event"], "ended");
  int lastGeneration = 0;
  for (std::size_t i = 0; i < events.size(); ++i) {
    EXPECT_EQ(events[i]["id"], int(i + 1)) << events.dump();
    if (events[i]["generation"].is_number()) {
      EXPECT_GE(events[i]["generation"].get<int>(), lastGeneration);
      lastGeneration = events[i]["generation"];
    }
  }
  // For docs/PERFORMANCE.md: camera change -> its first frame on screen, as the page measured it.
  std::cout << "[viewer] GL " << json::parse(http.Get("/v1/info")->body)["device"].value("renderer", "?")
            << "; change -> first frame on screen (ms; " << size << " px, a quarter of that while dragging): " << firstFrames.dump() << "\n";
  fs::remove_all(dir);
}

long residentKiB(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
  return 0;
}

// A .gltf chosen with its .bin and image is packed into a GLB by the page and renders exactly as the
// sample's own .glb does (same request, same frame bytes); the two uploads are different files.
TEST(Viewer, AGltfWithItsFilesIsPackedByThePageAndRendersAsItsGlb) {
  const std::string exe = chromiumPath();
  if (exe.empty()) GTEST_SKIP() << "Chromium is not installed (scripts/setup.sh installs Debian's chromium): the viewer is untested here";
  const fs::path sample = fs::path(RADIANT_GLTF_SAMPLES_DIR) / "BoxTextured";
  if (!fs::exists(sample / "glTF" / "BoxTextured.gltf")) GTEST_SKIP() << "no BoxTextured sample in " << RADIANT_GLTF_SAMPLES_DIR;
  const fs::path dir = testing::scratch("viewer-upload");
  testing::Daemon daemon(RADIANTD_PATH, {"--port", "0"}, {}, dir / "daemon.log");
  ASSERT_GT(daemon.port(), 0) << daemon.firstLine();
  ASSERT_TRUE(daemon.waitReady(std::chrono::seconds(120)));
  auto http = daemon.client();
  Browser browser(exe, dir / "profile");
  browser.open("http://127.0.0.1:" + std::to_string(daemon.port()) + "/ui/");
  ASSERT_TRUE(browser.waitFor("document.getElementById('status').textContent.startsWith('ready')", 60));
  browser.eval(R"(const size = document.getElementById('size'); size.appendChild(new Option('64', '64')); size.value = '64';
    document.getElementById('batches').value = '2'; true)");
  // Chooses files in the page's file input (as a user would) and waits for that session's refined frame.
  auto render = [&](const std::vector<std::string>& files) -> std::pair<std::string, std::string> {
    const std::string before = browser.eval("radiantViewer.state.session ? radiantViewer.state.session.id : ''");
    const int root = browser.call("DOM.getDocument")["root"]["nodeId"];
    const int input = browser.call("DOM.querySelector", {{"nodeId", root}, {"selector", "#file"}})["nodeId"];
    browser.call("DOM.setFileInputFiles", {{"nodeId", input}, {"files", files}});
    EXPECT_TRUE(browser.waitFor("radiantViewer.state.session && radiantViewer.state.session.id !== '" + before +
                                "' && radiantViewer.state.done && radiantViewer.state.drawn && "
                                "radiantViewer.state.drawn.batches === radiantViewer.state.done.batches", 120))
        << browser.eval("document.getElementById('status').textContent");
    const std::string id = browser.eval("radiantViewer.state.session.id");
    const json session = json::parse(http.Get(("/v1/sessions/" + id).c_str())->body);
    return {session["request"]["scene"].value("digest", ""), http.Get(("/v1/sessions/" + id + "/frame").c_str())->body};
  };
  const fs::path gltf = sample / "glTF";
  const auto [packedDigest, packedFrame] = render({(gltf / "BoxTextured.gltf").string(), (gltf / "BoxTextured0.bin").string(),
                                                   (gltf / "CesiumLogoFlat.png").string()});
  const auto [glbDigest, glbFrame] = render({(sample / "glTF-Binary" / "BoxTextured.glb").string()});
  ASSERT_FALSE(packedDigest.empty());
  EXPECT_NE(packedDigest, glbDigest) << "two different files were uploaded";
  ASSERT_GT(packedFrame.size(), 100u);
  EXPECT_TRUE(packedFrame == glbFrame) << "the packed .gltf renders differently from the sample's .glb";
  // A .gltf without the files it names: a message naming the missing file, no session.
  const std::string before = browser.eval("radiantViewer.state.session.id");
  const int root = browser.call("DOM.getDocument")["root"]["nodeId"];
  const int input = browser.call("DOM.querySelector", {{"nodeId", root}, {"selector", "#file"}})["nodeId"];
  browser.call("DOM.setFileInputFiles", {{"nodeId", input}, {"files", {(gltf / "BoxTextured.gltf").string()}}});
  EXPECT_TRUE(browser.waitFor("document.getElementById('status').textContent.includes('BoxTextured0.bin')", 30))
      << browser.eval("document.getElementById('status').textContent");
  EXPECT_EQ(browser.eval("radiantViewer.state.session.id"), before);
  fs::remove_all(dir);
}

// 500 sessions on the real daemon, each opened, changed and ended; every tenth renders to its end with
// a camera of its own. The daemon's resident set and the GL memory its frames report
// (stats.memory.resource_bytes) do not grow between the 50th and the 500th.
TEST(Viewer, FiveHundredSessionsOnTheDaemonLeaveNeitherRssNorGlMemoryBehind) {
  const fs::path dir = testing::scratch("sessions500");
  testing::Daemon daemon(RADIANTD_PATH, {"--port", "0"}, {}, dir / "daemon.log");
  ASSERT_GT(daemon.port(), 0) << daemon.firstLine();
  ASSERT_TRUE(daemon.waitReady(std::chrono::seconds(120)));
  auto http = daemon.client();
  http.set_read_timeout(120, 0);
  long rss50 = 0;
  double gl50 = 0, glLast = 0;
  for (int i = 0; i < 500; ++i) {
    const json request = {{"scene", {{"builtin", "cornell_box"}}}, {"width", 16}, {"height", 16},
                          {"camera", {{"orbit", {{"theta_deg", (i * 37) % 360 - 180}, {"phi_deg", 60 + i % 40}}}}},
                          {"refine", {{"max_batches", 2}}}};
    auto r = http.Post("/v1/sessions", request.dump(), "application/json");
    ASSERT_TRUE(r && r->status == 201) << (r ? r->body : "no answer");
    const std::string id = json::parse(r->body)["id"];
    ASSERT_EQ(http.Patch(("/v1/sessions/" + id).c_str(), R"({"seed": 1})", "application/merge-patch+json")->status, 200);
    if (i % 10 == 9) {
      json session;
      for (int k = 0; k < 3000; ++k) {
        session = json::parse(http.Get(("/v1/sessions/" + id).c_str())->body);
        if (session["render"]["state"] == "done" || session["render"]["state"] == "failed") break;
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
      }
      ASSERT_EQ(session["render"]["state"], "done") << session.dump();
      glLast = session["render"]["stats"]["memory"].value("resource_bytes", 0.0);
    }
    ASSERT_EQ(http.Delete(("/v1/sessions/" + id).c_str())->status, 200);
    if (i == 49) {
      rss50 = residentKiB(daemon.pid());
      gl50 = glLast;
    }
  }
  const long rss500 = residentKiB(daemon.pid());
  std::cout << "[sessions] RSS " << rss50 << " -> " << rss500 << " KiB, GL resources " << gl50 << " -> " << glLast << " bytes\n";
  EXPECT_GT(gl50, 0);
  EXPECT_LE(glLast, gl50 * 1.05 + 1e6) << "GL memory grew over 450 sessions";
  EXPECT_LT(rss500 - rss50, 32 * 1024) << "KiB of resident growth over 450 sessions";
  EXPECT_EQ(json::parse(http.Get("/v1/sessions")->body)["open"], 0);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace radiant
