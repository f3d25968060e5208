// Cancellation that reaches every loop (issue 30; docs/API.md, "Jobs, queue, timeouts"): a render
// cancelled mid-pass throws 409 "canceled" within a second of its flag, whatever pass it is in, and
// leaves the Renderer and its caches usable: a small render after it equals the same render of an
// identical scene under another digest (fresh caches, never touched by the cancelled frame).
//
// Each case's big frame would take several seconds or more on llvmpipe; the flag is raised 200 ms into
// the pass under test, or, where the pass finished sooner (a GPU), a third of its measured time into it
// on a retry. What is asserted is the condition (the frame was cancelled, not finished, and the next
// frame is right); time only bounds the wait (2.5 s under CI load; the API promises one second, idle).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "api/Validate.h"
#include "renderer/Renderer.h"
#include "renderer/scene/BuiltinScenes.h"
#include "tests/support/ImageDifference.h"
#include "tests/support/RenderTestSupport.h"

namespace radiant {
namespace {

using nlohmann::json;
using Clock = std::chrono::steady_clock;
using testing::aov;
using testing::renderer;

double msBetween(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

// photon_gi (on by default) traces its photons in prepare(): off unless it is the pass under test, so
// that the flag lands in the pass under test.
json body(json passes, json aovs, int size, json media = json::array()) {
  if (!passes.contains("photon_gi")) passes["photon_gi"] = false;
  json b = {{"scene", {{"builtin", "unused"}}},
            {"width", size},
            {"height", size},
            {"supersampling", 1},
            {"outputs", json::array({{{"format", "exr"}, {"aovs", aovs}}})},
            {"passes", passes}};
  if (!media.empty()) b["media"] = media, b["ambient"] = {0.3, 0.35, 0.45};
  return b;
}

// A cloud of n particles on a jittered lattice in the unit cube around the origin.
json cloud(int n) {
  json particles = json::array();
  const int side = static_cast<int>(std::ceil(std::cbrt(double(n))));
  for (int i = 0; i < n; ++i) {
    const int x = i % side, y = (i / side) % side, z = i / (side * side);
    particles.push_back({{"p", {-1.0 + 2.0 * (x + 0.5) / side, -1.0 + 2.0 * (y + 0.5) / side,
                                -1.0 + 2.0 * (z + 0.5) / side}},
                         {"r", 2.5 / side}});
  }
  return json::array({{{"kind", "cloud"}, {"tau", 2.0}, {"albedo", {0.9, 0.9, 0.9}}, {"particles", particles}}});
}

struct Case {
  const char* name;
  const char* scene;  // builtin
  json big, small;    // request bodies
  const char* aov;    // compared after the cancel
  const char* where;  // in the 409's detail: the loop that saw the flag
  // The pass whose execute() the flag should land in: it is raised 200 ms after that pass starts (the
  // frame's progress reaches its share), or 200 ms after the frame starts when "" (work in prepare()).
  const char* pass = "";
};

Scene sceneUnder(const char* builtin, const std::string& digest) {
  Scene s = loadBuiltinScene(builtin);
  s.digest = digest;
  return s;
}

// Renders `c.big` with the flag raised 200 ms into the pass under test; then `c.small` on the same
// renderer and on the same scene under another digest. On a fast device (a GPU) the big frame's pass
// can finish inside 200 ms, or pass its last check before the flag: then the pass's wall time, measured
// from the progress callbacks, sets the next try's delay (a third of it), on a scene under a new digest
// so that no cache from the finished try shortens it. No device is assumed: the flag must land in the pass.
void cancelMidPass(const Case& c) {
  Renderer& r = renderer();
  const Scene fresh = sceneUnder(c.scene, std::string("sha256:cancel-fresh-") + c.name);
  const RenderOutput expected = r.render(fresh, api::parseRenderRequest(c.small));

  // Pass i of n starts at progress 0.95 i / n (Renderer::render); the small frame plans the same passes.
  double passStart = 0.0, passEnd = 0.95;
  if (*c.pass) {
    std::size_t i = 0;
    while (i < expected.stats.passes.size() && expected.stats.passes[i].name != c.pass) ++i;
    ASSERT_LT(i, expected.stats.passes.size()) << c.pass << " is not planned";
    const double n = double(expected.stats.passes.size());
    passStart = 0.95 * double(i) / n;
    passEnd = 0.95 * double(i + 1) / n;
  }
  double delayMs = 200.0;
  for (int attempt = 0;; ++attempt) {
    const Scene used = sceneUnder(c.scene, std::string("sha256:cancel-used-") + c.name + "-" + std::to_string(attempt));
    std::atomic<bool> cancel{false}, started{!*c.pass};
    Clock::time_point passBegan = Clock::now(), passFinished{};
    FrameInputs inputs;
    inputs.progress = [&](double v) {  // called in order, from the render's threads
      if (v >= passStart - 1e-9 && !started.exchange(true)) passBegan = Clock::now();
      if (v >= passEnd - 1e-9 && passFinished == Clock::time_point{}) passFinished = Clock::now();
    };
    Clock::time_point raised{};
    std::atomic<bool> done{false};
    std::thread canceller([&] {
      while (!started.load() && !done.load()) std::this_thread::sleep_for(std::chrono::microseconds(100));
      const auto until = Clock::now() + std::chrono::microseconds(static_cast<long>(delayMs * 1000.0));
      while (Clock::now() < until && !done.load()) std::this_thread::sleep_for(std::chrono::microseconds(200));
      if (done.load()) return;
      raised = Clock::now();
      cancel.store(true);
    });
    const auto start = Clock::now();
    std::string detail;
    int status = 0;
    try {
      r.render(used, api::parseRenderRequest(c.big), &cancel, inputs);
    } catch (const api::ApiError& e) {
      status = e.status;
      detail = e.detail();
      EXPECT_EQ(e.type, "canceled");
    }
    const auto end = Clock::now();
    done = true;
    canceller.join();
    if (status == 0) {
      // Finished before the flag, or with the flag raised after the pass's last check (on a GPU a pass's
      // loop can end long before its draws do): again, with a delay inside the pass's measured time.
      const double passMs = msBetween(passBegan, passFinished == Clock::time_point{} ? end : passFinished);
      std::printf("%s: the big frame finished in %.1f ms (the pass %.1f ms), the flag %s at %.1f ms\n", c.name,
                  msBetween(start, end), passMs, cancel.load() ? "raised" : "not raised", delayMs);
      if (attempt == 3 || passMs < 0.5) {
        // A pass whose whole run is shorter than a tenth of the API's one second cannot keep a cancelled
        // frame waiting: on such a device (a GPU; its loop may pass every check before the draws run)
        // the loop's checks cannot be reached and are proven where the pass is slow (llvmpipe, CI).
        if (passMs < 100.0)
          GTEST_SKIP() << c.name << ": the pass runs in " << passMs << " ms on this device, too fast to land the "
                       << "flag inside its loop";
        FAIL() << c.name << ": the big frame kept finishing before the flag reached a check: make it bigger";
      }
      delayMs = std::min(delayMs, passMs) / 3.0;
      continue;
    }
    EXPECT_EQ(status, 409) << c.name;
    const double latency = msBetween(raised, end);
    std::printf("%s: stopped %.0f ms after the flag (%.0f ms in): %s\n", c.name, latency, msBetween(start, end),
                detail.c_str());
    // The API's one second is measured on a quiet machine (docs/API.md: 0-600 ms per pass on llvmpipe);
    // CI runs two test processes on two cores, which can double a stretch's time, so the bound here is
    // 2.5 s: still far inside every big frame, which would run for several seconds more uncancelled.
    EXPECT_LT(latency, 2500.0) << c.name << ": " << detail;
    EXPECT_NE(detail.find(c.where), std::string::npos) << c.name << ": cancelled elsewhere: " << detail;

    const RenderOutput after = r.render(used, api::parseRenderRequest(c.small));
    EXPECT_TRUE(testing::allFinite(after));
    EXPECT_LT(testing::maxAbsDifference(aov(expected, c.aov), aov(after, c.aov)), 1e-5)
        << c.name << ": the frame after the cancelled one differs from the same frame on fresh caches";
    return;
  }
}

TEST(Cancel, ReferencePathTracer) {
  cancelMidPass({"reference", "cornell_box", body({{"reference", {{"spp", 65536}}}}, {"reference"}, 64),
                 body({{"reference", {{"spp", 4}}}}, {"reference"}, 16), "reference", "reference path tracer",
                 // Raised once the pass runs: under CI's load the frame's set-up took over 200 ms once,
                 // and the flag landed before the pass ("cancelled before pass reference").
                 "reference"});
}

TEST(Cancel, ReferenceLightTracer) {
  // cornell_glass has delta lobes: the reference adds the light tracer's caustics after the path tracer.
  cancelMidPass({"reference_light_tracer", "cornell_glass",
                 body({{"reference", {{"spp", 1}, {"light_paths_per_pixel", 65536}}}}, {"reference"}, 64),
                 body({{"reference", {{"spp", 2}, {"light_paths_per_pixel", 2}}}}, {"reference"}, 16), "reference", "light tracer", "reference"});
}

TEST(Cancel, PhotonGiTracing) {
  cancelMidPass({"photon_gi", "cornell_box", body({{"photon_gi", {{"photons", 4000000}}}}, {"beauty"}, 32),
                 body({{"photon_gi", {{"photons", 20000}}}}, {"beauty"}, 32), "beauty", "photon tracing"});
}

TEST(Cancel, Caustics) {
  cancelMidPass({"caustics", "cornell_glass",
                 body({{"caustics", {{"photon_resolution", 256}, {"cube_resolution", 1024}}}}, {"beauty", "caustics"}, 256),
                 body({{"caustics", {{"photon_resolution", 32}, {"cube_resolution", 64}}}}, {"beauty", "caustics"}, 32),
                 "caustics", "caustics", "caustics"});
}

TEST(Cancel, LightVolumes) {
  cancelMidPass({"light_volumes", "cornell_glossy",
                 body({{"light_volumes", {{"max_subdivision_beams", 1048576}, {"max_triangle_sigma", 0.01},
                                          {"traversal", "linear"}}}},
                      {"beauty"}, 256),
                 body({{"light_volumes", {{"max_subdivision_beams", 0}}}}, {"beauty"}, 32), "beauty", "light_volumes"});
}

TEST(Cancel, EnvDiffuse) {
  cancelMidPass({"env_diffuse", "cornell_box",
                 body({{"env_diffuse", {{"cube_resolution", 512}, {"downsample", 16}, {"bounces", 4}}}},
                      {"beauty", "indirect_diffuse"}, 256),
                 body({{"env_diffuse", {{"cube_resolution", 32}, {"downsample", 4}}}}, {"beauty", "indirect_diffuse"}, 32),
                 "indirect_diffuse", "env_diffuse", "env_diffuse"});
}

TEST(Cancel, SphericalBillboards) {
  cancelMidPass({"spherical_billboards", "cornell_box",
                 body({{"spherical_billboards", json::object()}}, {"beauty", "media"}, 512, cloud(60000)),
                 body({{"spherical_billboards", json::object()}}, {"beauty", "media"}, 32, cloud(64)), "media", "spherical_billboards", "spherical_billboards"});
}

TEST(Cancel, DepthImpostors) {
  cancelMidPass({"depth_impostors", "cornell_box",
                 body({{"spherical_billboards", false}, {"depth_impostors", {{"particles_per_block", 1}}}},
                      {"beauty", "media"}, 512, cloud(20000)),
                 body({{"spherical_billboards", false}, {"depth_impostors", json::object()}}, {"beauty", "media"}, 32,
                      cloud(64)),
                 "media", "depth_impostors", "depth_impostors"});
}

TEST(Cancel, SpecularDistanceMaps) {
  // The maps are drawn one object-layer-face at a time with a check between faces: at 512 texels per
  // side and 6 layers (288 MiB, within SpecularPass::kMaxBytes) the maps of cornell_glass's sphere take
  // seconds.
  cancelMidPass({"specular", "cornell_glass",
                 body({{"caustics", false}, {"specular", {{"cube_resolution", 512}, {"layers", 6}}}}, {"beauty"}, 32),
                 body({{"caustics", false}, {"specular", {{"cube_resolution", 32}, {"layers", 3}}}}, {"beauty"}, 16),
                 "beauty", "specular's", "specular"});
}

// At 8192 nodes x 128 directions the network's visibility build (NetworkGpu::buildVisibility) runs about
// 1.5 s on llvmpipe; it is split into stretches of directions with a check between them, so the flag
// lands in the build or in the iterations, both the pass's own loops.
TEST(Cancel, IlluminationNetworkVisibilityAndIterations) {
  cancelMidPass({"illumination_network", "cornell_box",
                 body({{"spherical_billboards", false},
                       {"illumination_network", {{"nodes", 8192}, {"directions", 128}, {"iterations", 1024}, {"warm_start", false}}}},
                      {"beauty", "media"}, 64, cloud(512)),
                 body({{"spherical_billboards", false},
                       {"illumination_network", {{"nodes", 64}, {"directions", 8}, {"iterations", 2}, {"warm_start", false}}}},
                      {"beauty", "media"}, 32, cloud(64)),
                 "media", "illumination_network", "illumination_network"});
}

}  // namespace
}  // namespace radiant
