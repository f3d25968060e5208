// Soak benchmark (issues 13 and 30; not a test, not in CI): starts radiantd and sends N mixed requests
// on one keep-alive client, per 25: synchronous renders with each pass, scene uploads (a new digest each
// time), inline scenes, async renders cancelled at once, bad requests of every hardening class, and
// (issue 30) an uploaded environment map (a new digest each time) lighting the default passes, a
// participating-medium frame, a refining job of 2 batches, and one hostile upload from
// tests/data/crashers/{images,gltf} in turn (any status below 500).
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

#include "renderer/io/ImageIO.h"
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

// A 16x8 environment map, a new digest every time: a sky with a sun-like texel (the environment's
// light split and photon_gi's sky photons run for it).
std::string uniqueEnvironment(int i) {
  radiant::Image sky = radiant::Image::make("beauty", 16, 8, 3);
  for (std::size_t p = 0; p < sky.pixels.size(); ++p) sky.pixels[p] = 0.5f + 1e-4f * float(i % 1000) + 0.01f * float(p % 3);
  for (int c = 0; c < 3; ++c) sky.pixels[(2 * 16 + 5) * 3 + std::size_t(c)] = 400.f;
  return radiant::io::encodeExr({sky}, false);
}

std::vector<std::string> hostileFiles(const std::string& folder) {
  std::vector<std::string> files;
  for (const auto& e : std::filesystem::directory_iterator(std::string(RADIANT_SOURCE_DIR) + "/tests/data/crashers/" + folder)) {
    if (!e.is_regular_file() || e.path().extension() == ".py") continue;
    std::ifstream in(e.path(), std::ios::binary);
    files.emplace_back((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  }
  return files;
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

  const std::vector<std::string> hostileImages = hostileFiles("images"), hostileScenes = hostileFiles("gltf");

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
  // expect: 1 = 2xx, 0 = 4xx, -1 = anything below 500 (hostile uploads: a few are valid files).
  auto note = [&](const httplib::Result& r, const std::string& what, int expect) {
    ++counts[what];
    if (!r) { ++otherFailures; return json(); }
    if (r->status >= 500) {
      ++fiveHundreds;
      std::fprintf(stderr, "soak: %s -> %d %s\n", what.c_str(), r->status, r->body.substr(0, 300).c_str());
    } else if (expect >= 0 && (expect == 1) != (r->status < 300)) {
      ++otherFailures;
      std::fprintf(stderr, "soak: %s -> %d %s\n", what.c_str(), r->status, r->body.substr(0, 300).c_str());
    }
    return json::parse(r->body, nullptr, false);
  };

  std::map<int, double> kindSeconds;  // per kind of the cycle, for the summary
  for (int i = 0; i < requests; ++i) {
    const int kind = i % 25;
    const auto started = std::chrono::steady_clock::now();
    if (kind == 20) {  // a new environment map, then the default passes under it
      const json up = note(c.Put("/v1/images", uniqueEnvironment(i), "image/x-exr"), "upload environment", 1);
      if (up.is_object()) {
        const json body = {{"scene", {{"inline_glb", radiant::test::base64(uniqueScene(i))}}}, {"environment", up["digest"]},
                           {"width", 16}, {"height", 16}, {"seed", i}};
        const json job = note(c.Post("/v1/renders", body.dump(), "application/json"), "render environment", 1);
        if (job.is_object()) fetchFrames(job);
      }
    } else if (kind == 21) {  // a participating medium (the planner's media passes)
      const json body = {{"scene", {{"builtin", "explosion"}}}, {"width", 16}, {"height", 16}, {"seed", i}};
      const json job = note(c.Post("/v1/renders", body.dump(), "application/json"), "render media", 1);
      if (job.is_object()) fetchFrames(job);
    } else if (kind == 22) {  // a refining job of 2 batches, waited for
      const json accepted = note(c.Post("/v1/renders", json{{"scene", {{"builtin", "cornell_box"}}}, {"width", 16}, {"height", 16},
                                                          {"async", true}, {"refine", {{"max_batches", 2}}}}.dump(),
                                        "application/json"),
                                 "refine", 1);
      if (!accepted.is_object()) continue;
      const std::string url = "/v1/renders/" + accepted["id"].get<std::string>();
      for (int k = 0; k < 2000; ++k) {
        auto r = c.Get(url.c_str());
        const json job = r ? json::parse(r->body, nullptr, false) : json();
        const std::string state = job.is_object() ? job.value("state", "") : "";
        if (state == "done") { fetchFrames(job); break; }
        if (state != "queued" && state != "running") {
          ++otherFailures;
          std::fprintf(stderr, "soak: refine -> %s\n", r ? r->body.substr(0, 300).c_str() : "no answer");
          break;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      }
    } else if (kind == 23) {  // a hostile image upload
      note(c.Put("/v1/images", hostileImages[std::size_t(i / 25) % hostileImages.size()], "application/octet-stream"),
           "hostile image", -1);
    } else if (kind == 24) {  // a hostile glTF upload
      note(c.Put("/v1/scenes", hostileScenes[std::size_t(i / 25) % hostileScenes.size()], "application/octet-stream"),
           "hostile scene", -1);
    } else if (kind < 12) {  // renders: each pass in turn, on each built-in scene
      const auto& [pass, params] = passes[std::size_t(i / 25 + kind) % passes.size()];
      json body = {{"scene", {{"builtin", scenes[std::size_t(i) % scenes.size()]}}}, {"width", 16}, {"height", 16},
                   {"seed", i}, {"passes", {{pass, params}}}};
      if (pass == "gbuffer") body["outputs"] = {{{"format", "exr"}, {"aovs", {"beauty", "normal", "depth"}}}};
      const json job = note(c.Post("/v1/renders", body.dump(), "application/json"), "render " + pass, 1);
      if (job.is_object()) fetchFrames(job);
    } else if (kind < 14) {  // uploads, then a render of the upload by digest
      const json up = note(c.Put("/v1/scenes", uniqueScene(i), "model/gltf-binary"), "upload", 1);
      if (up.is_object()) {
        const json job = note(c.Post("/v1/renders", json{{"scene", {{"digest", up["digest"]}}}, {"width", 16}, {"height", 16}}.dump(),
                                     "application/json"),
                              "render uploaded", 1);
        if (job.is_object()) fetchFrames(job);
      }
    } else if (kind == 14) {  // inline GLB
      const json body = {{"scene", {{"inline_glb", radiant::test::base64(uniqueScene(-i))}}}, {"width", 16}, {"height", 16}};
      const json job = note(c.Post("/v1/renders", body.dump(), "application/json"), "render inline", 1);
      if (job.is_object()) fetchFrames(job);
    } else if (kind < 17) {  // async, cancelled at once; if it finished first, its frames must be there
      const json accepted = note(c.Post("/v1/renders", json{{"scene", {{"builtin", "cornell_box"}}}, {"width", 32}, {"height", 32},
                                                          {"async", true}, {"passes", {{"reference", {{"spp", 4}}}}}}.dump(),
                                        "application/json"),
                                 "async", 1);
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
      note(c.Post("/v1/renders", text, "application/json"), "bad " + what, 0);
    }
    kindSeconds[kind] += std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
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
  std::printf("soak: seconds per kind of the cycle (0-11 renders, 12-13 uploads, 14 inline, 15-16 async, 17-19 bad,\n"
              "soak: 20 environment, 21 media, 22 refine, 23-24 hostile):");
  for (const auto& [kind, t] : kindSeconds) std::printf(" %d:%.0f", kind, t);
  std::printf("\n");
  const bool flat = hi <= lo * 1.05;
  const bool ok = fiveHundreds == 0 && framesMissing == 0 && otherFailures == 0 && flat;
  if (ok) std::filesystem::remove_all(dir);
  else std::printf("soak: FAILED; the daemon's log is %s\n", (dir / "stderr.log").c_str());
  return ok ? 0 : 1;
}
