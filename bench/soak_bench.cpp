// Soak benchmark (issue 13; not a test, not in CI): starts radiantd and sends N mixed requests on
// one keep-alive client: synchronous renders with each pass, scene uploads (a new digest each
// time), inline scenes, async renders cancelled at once, and bad requests of every hardening class.
// The daemon's RSS is sampled every 500 requests. Goal: RSS flat within 5% after warm-up, no 5xx,
// every accepted job's frames downloadable.
//   build/bench/soak_bench [--requests N] [--warmup N]
// Figures go into docs/PERFORMANCE.md ("Soak").
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <httplib.h>
#include <nlohmann/json.hpp>

#include "tests/support/DaemonProcess.h"
#include "tests/unit/scene/GltfTestBuilder.h"

using nlohmann::json;

namespace {

double rssMiB(pid_t pid, const char* key) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind(key, 0) == 0) return std::stod(line.substr(std::strlen(key))) / 1024.0;
  return -1;
}

std::string uniqueScene(int i) {
  radiant::test::GltfBuilder b;
  const float s = 1.f + float(i) * 1e-3f;  // a new digest every time
  const std::vector<glm::vec3> p = {{-s, 0, -s}, {s, 0, -s}, {0, s, -s}};
  const int m = b.mesh(json::array({radiant::test::trianglePrimitive<std::uint8_t>(b, p, {0, 1, 2})}));
  b.scene({b.node({{"mesh", m}})});
  return b.glb();
}

}  // namespace

int main(int argc, char** argv) {
  int requests = 10000, warmup = 2000;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (std::string(argv[i]) == "--requests") requests = std::atoi(argv[i + 1]);
    if (std::string(argv[i]) == "--warmup") warmup = std::atoi(argv[i + 1]);
  }
  const auto dir = radiant::testing::scratch("soak");
  radiant::testing::Daemon d(RADIANTD_PATH, {"--port", "0", "--max-scene-bytes", "4194304", "--frame-ttl", "30"}, {},
                             dir / "stderr.log");
  if (d.port() <= 0 || !d.waitReady(std::chrono::seconds(60))) {
    std::fprintf(stderr, "soak: radiantd did not start: %s\n", d.firstLine().c_str());
    return 1;
  }
  auto c = d.client();
  c.set_keep_alive(true);

  const std::vector<std::pair<std::string, json>> passes = {
      {"direct", json::object()},
      {"ambient_occlusion", {{"samples", 4}}},
      {"gbuffer", json::object()},
      {"shadow_maps", json::object()},
      {"specular", json::object()},
      {"env_diffuse", {{"cube_resolution", 16}, {"downsample", 2}}},
      {"reference", {{"spp", 1}, {"max_bounces", 2}}}};
  const std::vector<std::string> scenes = {"cornell_box", "cornell_mirror", "cornell_glass", "ao_creases"};
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"{\"scene\":", "malformed"},
      {std::string(5000, '['), "deep"},
      {R"({"scene":{"builtin":"cornell_box"},"exposure":1e400})", "overflow"},
      {R"({"scene":{"builtin":"cornell_box"},"camera":{"position":[1e308,0,0]}})", "camera"},
      {"{\"scene\":{\"builtin\":\"cornell\xff\"}}", "utf8"},
      {R"({"scene":{"builtin":"cornell_box"},"outputs":[{"format":"exr","aovs":["beauty","beauty"]}]})", "duplicate"}};

  std::map<std::string, int> counts;
  int fiveHundreds = 0, otherFailures = 0, framesMissing = 0, framesFetched = 0;
  std::vector<std::pair<int, double>> samples;
  const auto t0 = std::chrono::steady_clock::now();
  auto fetchFrames = [&](const json& job) {
    for (const auto& f : job.value("frames", json::array())) {
      auto r = c.Get(f["url"].get<std::string>().c_str());
      if (r && r->status == 200 && !r->body.empty()) ++framesFetched;
      else ++framesMissing;
    }
  };
  auto note = [&](const httplib::Result& r, const std::string& what, bool expect2xx) {
    ++counts[what];
    if (!r) { ++otherFailures; return json(); }
    if (r->status >= 500) {
      ++fiveHundreds;
      std::fprintf(stderr, "soak: %s -> %d %s\n", what.c_str(), r->status, r->body.substr(0, 300).c_str());
    } else if (expect2xx != (r->status < 300)) {
      ++otherFailures;
      std::fprintf(stderr, "soak: %s -> %d %s\n", what.c_str(), r->status, r->body.substr(0, 300).c_str());
    }
    return json::parse(r->body, nullptr, false);
  };

  for (int i = 0; i < requests; ++i) {
    const int kind = i % 20;
    if (kind < 12) {  // renders: each pass in turn, on each built-in scene
      const auto& [pass, params] = passes[std::size_t(i / 20 + kind) % passes.size()];
      json body = {{"scene", {{"builtin", scenes[std::size_t(i) % scenes.size()]}}}, {"width", 16}, {"height", 16},
                   {"seed", i}, {"passes", {{pass, params}}}};
      if (pass == "gbuffer") body["outputs"] = {{{"format", "exr"}, {"aovs", {"beauty", "normal", "depth"}}}};
      const json job = note(c.Post("/v1/renders", body.dump(), "application/json"), "render " + pass, true);
      if (job.is_object()) fetchFrames(job);
    } else if (kind < 14) {  // uploads, then a render of the upload by digest
      const json up = note(c.Put("/v1/scenes", uniqueScene(i), "model/gltf-binary"), "upload", true);
      if (up.is_object()) {
        const json job = note(c.Post("/v1/renders", json{{"scene", {{"digest", up["digest"]}}}, {"width", 16}, {"height", 16}}.dump(),
                                     "application/json"),
                              "render uploaded", true);
        if (job.is_object()) fetchFrames(job);
      }
    } else if (kind == 14) {  // inline GLB
      const json body = {{"scene", {{"inline_glb", radiant::test::base64(uniqueScene(-i))}}}, {"width", 16}, {"height", 16}};
      const json job = note(c.Post("/v1/renders", body.dump(), "application/json"), "render inline", true);
      if (job.is_object()) fetchFrames(job);
    } else if (kind < 17) {  // async, cancelled at once; if it finished first, its frames must be there
      const json accepted = note(c.Post("/v1/renders", json{{"scene", {{"builtin", "cornell_box"}}}, {"width", 32}, {"height", 32},
                                                          {"async", true}, {"passes", {{"reference", {{"spp", 4}}}}}}.dump(),
                                        "application/json"),
                                 "async", true);
      if (!accepted.is_object()) continue;
      const std::string url = "/v1/renders/" + accepted["id"].get<std::string>();
      c.Delete(url.c_str());
      for (int k = 0; k < 400; ++k) {
        auto r = c.Get(url.c_str());
        const json job = r ? json::parse(r->body, nullptr, false) : json();
        if (!job.is_object()) break;
        const std::string state = job.value("state", "");
        if (state == "done") { fetchFrames(job); break; }
        if (state == "canceled" || state == "failed" || job.contains("deleted") || r->status == 404) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      }
    } else {  // bad requests: 4xx, never 5xx
      const auto& [text, what] = bad[std::size_t(i) % bad.size()];
      note(c.Post("/v1/renders", text, "application/json"), "bad " + what, false);
    }
    if (rssMiB(d.pid(), "VmRSS:") < 0) {
      std::printf("soak: the daemon is gone after %d requests\n", i + 1);
      ++otherFailures;
      break;
    }
    if ((i + 1) % 500 == 0) {
      samples.emplace_back(i + 1, rssMiB(d.pid(), "VmRSS:"));
      std::printf("soak: %6d requests  %7.1f s  RSS %7.1f MiB\n", i + 1,
                  std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), samples.back().second);
      std::fflush(stdout);
    }
  }
  double lo = 1e30, hi = 0;
  for (const auto& [n, rss] : samples)
    if (n > warmup) { lo = std::min(lo, rss); hi = std::max(hi, rss); }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("soak: %d requests in %.1f s; 5xx %d, other unexpected %d, frames fetched %d, missing %d\n", requests,
              seconds, fiveHundreds, otherFailures, framesFetched, framesMissing);
  std::printf("soak: RSS after %d requests: min %.1f MiB, max %.1f MiB (spread %.1f%%); peak (VmHWM) %.1f MiB\n", warmup,
              lo, hi, hi > 0 ? 100.0 * (hi - lo) / lo : 0.0, rssMiB(d.pid(), "VmHWM:"));
  for (const auto& [what, n] : counts) std::printf("soak:   %-24s %d\n", what.c_str(), n);
  const bool flat = hi <= lo * 1.05;
  const bool ok = fiveHundreds == 0 && framesMissing == 0 && otherFailures == 0 && flat;
  if (ok) std::filesystem::remove_all(dir);
  else std::printf("soak: FAILED; the daemon's log is %s\n", (dir / "stderr.log").c_str());
  return ok ? 0 : 1;
}
