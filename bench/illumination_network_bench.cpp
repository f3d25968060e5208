// Illumination networks (issue 17): milliseconds per iteration and per frame of the
// illumination_network pass against N in {512, 1024, 2048, 4096} and D in {32, 64, 128}, each with its
// error against the volumetric reference's full mode, on the thesis' default cloud (a homogeneous
// sphere, R = 1, tau = 10, so 2 R tau = 20; albedo 0.9; isotropic phase) lit by a directional light and
// a uniform sky; then the goal: the network at N = 1024, D = 128 against the single-scatter methods
// on the same cloud (spherical_billboards; depth_impostors when the registry has it).
//   build/bench/illumination_network_bench [size=64] [iterations=32] [spp=256] [repeats=1] [table|goal|both|directions]
// The goal runs on two clouds of the same optical size: the homogeneous sphere (one particle: what the
// network samples its nodes from) and 8000 constant particles in the unit ball (the depth_impostors
// bench's cloud), so the single-scatter methods see particles they can shadow between.
// Timing: the pass's GPU time (GL_TIME_ELAPSED) and CPU time, medians of `repeats` frames, cold starts
// (warm_start false) so every frame iterates from 0. Per (N, D) of the table: one warm-up frame of 0
// iterations (builds the visibility network, compiles the shaders), then the timed frames of 0 and of
// `iterations` iterations (the network cached). Per iteration (iter_ms): the difference between the
// two, over `iterations`; the rest of the frame (the light transmittance, the camera sources and the
// final render, march by default) is frame0_ms. Error (the table's and the goal's): RMSE of the media
// AOV's RGB over 4x4-pixel blocks, relative to the mean of the reference (`full`, 64 scattering events).
// The table prints the UTC date and the load average before and after (docs/PERFORMANCE.md).
#include <algorithm>
#include <cmath>
#include <tuple>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <string>
#include <vector>

#include "api/Validate.h"
#include "bench/BenchSupport.h"
#include "renderer/Renderer.h"
#include "renderer/techniques/Registry.h"

namespace {

using namespace radiant;
using bench::aovOf;
using bench::relativeRmse;
using nlohmann::json;

const api::PassStats& passOf(const RenderOutput& out, const std::string& name) {
  for (const auto& p : out.stats.passes)
    if (p.name == name) return p;
  std::fprintf(stderr, "missing pass %s\n", name.c_str());
  std::exit(1);
}

double blockError(const Image& a, const Image& ref) {
  const int B = 4, nx = a.width / B, ny = a.height / B;
  double e2 = 0, mean = 0;
  for (int by = 0; by < ny; ++by)
    for (int bx = 0; bx < nx; ++bx)
      for (int c = 0; c < 3; ++c) {
        double sa = 0, sr = 0;
        for (int y = 0; y < B; ++y)
          for (int x = 0; x < B; ++x) sa += a.at(bx * B + x, by * B + y)[c], sr += ref.at(bx * B + x, by * B + y)[c];
        e2 += std::pow((sa - sr) / (B * B), 2), mean += sr / (B * B);
      }
  return std::sqrt(e2 / (nx * ny * 3)) / (mean / (nx * ny * 3));
}

struct Timing {
  double gpuMs, cpuMs;
};

// "2026-12-02 07:46 UTC, load average 2.33 3.37 5.36" (the machine is shared: docs/PERFORMANCE.md).
std::string whenAndLoad() {
  char when[64];
  const std::time_t now = std::time(nullptr);
  std::strftime(when, sizeof when, "%Y-%m-%d %H:%M:%S UTC", std::gmtime(&now));
  std::ifstream f("/proc/loadavg");
  std::string l1, l5, l15;
  f >> l1 >> l5 >> l15;
  return std::string(when) + ", load average (1, 5, 15 min) " + l1 + " " + l5 + " " + l15;
}

Timing median(Renderer& r, const Scene& scene, const json& body, const std::string& pass, int repeats, Image* media,
              api::PassStats* stats = nullptr, bool warmUp = true) {
  std::vector<double> gpu, cpu;
  for (int i = warmUp ? 0 : 1; i <= repeats; ++i) {
    const RenderOutput out = r.render(scene, api::parseRenderRequest(body));
    if (i == 0) continue;
    const api::PassStats& p = passOf(out, pass);
    gpu.push_back(p.gpuMs), cpu.push_back(p.cpuMs);
    if (media) *media = aovOf(out, "media");
    if (stats) *stats = p;
  }
  std::sort(gpu.begin(), gpu.end());
  std::sort(cpu.begin(), cpu.end());
  return {gpu[gpu.size() / 2], cpu[cpu.size() / 2]};
}

}  // namespace

int main(int argc, char** argv) {
  const int size = argc > 1 ? std::atoi(argv[1]) : 64;
  const int iterations = argc > 2 ? std::atoi(argv[2]) : 32;
  const int spp = argc > 3 ? std::atoi(argv[3]) : 256;
  const int repeats = argc > 4 ? std::atoi(argv[4]) : 1;
  const std::string mode = argc > 5 ? argv[5] : "both";
  if (mode != "table" && mode != "goal" && mode != "both" && mode != "directions") {
    std::fprintf(stderr, "mode must be table, goal, both or directions, not %s\n", mode.c_str());
    return 2;
  }
  Renderer renderer;
  std::printf("GL renderer: %s | %s\n", renderer.device().renderer.c_str(), renderer.device().version.c_str());

  Scene scene;
  scene.name = "network-cloud";
  Light sun;
  sun.type = LightType::Directional;
  sun.direction = glm::normalize(glm::vec3(1.f, -0.6f, -0.5f));
  sun.intensity = 3.f;
  scene.lights.push_back(sun);
  scene.camera.projection = ProjectionType::Orthographic;
  scene.camera.xmag = scene.camera.ymag = 1.2f;
  scene.camera.znear = 0.01f, scene.camera.zfar = 100.f;
  scene.camera.world = glm::mat4(1.f);
  scene.camera.world[3] = glm::vec4(0, 0, 10, 1);
  scene.camera.fromFile = true;
  const json cloud = {{"kind", "cloud"}, {"tau", 10.0}, {"albedo", {0.9, 0.9, 0.9}},
                      {"particles", json::array({{{"p", {0, 0, 0}}, {"r", 1.0}}})}};
  // One raster sample per pixel, as this bench's figures in docs/PERFORMANCE.md were measured (the
  // HTTP default is "supersampling": 2 since 2026-12-02; the C++ RenderRequest's stays 1).
  const json base = {{"scene", {{"builtin", "unused"}}}, {"width", size}, {"height", size}, {"supersampling", 1},
                     {"ambient", {0.3, 0.35, 0.45}}, {"media", json::array({cloud})},
                     {"outputs", json::array({{{"format", "exr"}, {"aovs", {"media"}}}})}};

  json refBody = base;
  refBody["passes"] = {{"spherical_billboards", false},
                       {"reference", {{"aov", "media"}, {"media_mode", "full"}, {"spp", spp}, {"max_bounces", 64}}}};
  refBody["outputs"] = json::array({{{"format", "exr"}, {"aovs", {"reference"}}}});
  const RenderOutput refOut = renderer.render(scene, api::parseRenderRequest(refBody));
  const Image reference = aovOf(refOut, "reference");
  std::printf("reference: full, %d spp, %dx%d, %.0f ms\n", spp, size, size, passOf(refOut, "reference").cpuMs);

  auto networkBody = [&](int N, int D, int iters) {
    json b = base;
    b["passes"] = {{"spherical_billboards", false},
                   {"illumination_network", {{"nodes", N}, {"directions", D}, {"iterations", iters}, {"warm_start", false}}}};
    return b;
  };
  if (mode == "table" || mode == "both") {
  std::printf("\nillumination_network, %d iterations per frame (cold start), %dx%d, median of %d frames\n", iterations,
              size, size, repeats);
  std::printf("start: %s\n", whenAndLoad().c_str());
  std::printf("%6s %4s %4s %9s %12s %12s %10s %10s %11s %11s %10s %9s\n", "N", "D", "M", "sky_links", "frame_gpu_ms",
              "frame_cpu_ms", "frame0_ms", "iter_ms", "us/node/it", "ms/node/fr", "residual", "error");
  for (int N : {512, 1024, 2048, 4096})
    for (int D : {32, 64, 128}) {
      Image media;
      api::PassStats p;
      const Timing zero = median(renderer, scene, networkBody(N, D, 0), "illumination_network", repeats, nullptr);
      const Timing frame = median(renderer, scene, networkBody(N, D, iterations), "illumination_network", repeats,
                                  &media, &p, /*warmUp=*/false);
      const double zeroMs = std::max(zero.gpuMs, zero.cpuMs), frameMs = std::max(frame.gpuMs, frame.cpuMs);
      const double perIter = (frameMs - zeroMs) / std::max(1, iterations);
      const double err = blockError(media, reference);
      std::printf("%6d %4d %4.0f %9.3f %12.2f %12.2f %10.2f %10.3f %11.4f %11.4f %10.2e %9.4f\n", N, D,
                  p.counters.at("window"), p.counters.at("link_occupancy"), frame.gpuMs, frame.cpuMs, zeroMs, perIter,
                  1e3 * perIter / N, frameMs / N, iterations > 0 ? p.counters.at("residual_last") : 0.0, err);
      std::fflush(stdout);
    }

  std::printf("end: %s\n", whenAndLoad().c_str());
  }
  if (mode == "table") return 0;

  // Error against D at N 1024 (issue 17's "falls with N and D", a numeric Fig. 9.6), for the isotropic
  // phase (the thesis') and Henyey-Greenstein g 0.5 and 0.8, each against its own `full` reference. The
  // frame splits into the light scattered once (the frame of 0 iterations: the sun exactly, the sky over
  // the D directions' normalised phase column) and the rest (the network's multiply scattered part: the
  // frame of `iterations` minus that of 0). The once part is scored against the same frame at D 512 (the
  // sky's quadrature converged; the reference's own single_scatter mode integrates 8 midpoint pieces per
  // chord, too coarse for the lit skin of a cloud 20 optical depths across), the multiply scattered part
  // against full minus that D 512 once part.
  if (mode == "directions") {
    std::printf("\nerror against D at N 1024, %d cold iterations, %dx%d, references %d spp\n", iterations, size, size, spp);
    std::printf("start: %s\n", whenAndLoad().c_str());
    std::printf("%-10s %4s %9s %9s %9s %9s %9s\n", "phase", "D", "error", "once_err", "ms_err", "ms_share", "frame_ms");
    for (const double g : {0.0, 0.5, 0.8}) {
      json medium = cloud;
      if (g > 0) medium["phase"] = {{"model", "hg"}, {"g", g}};
      json b0 = base;
      b0["media"] = json::array({medium});
      json rb = b0;
      rb["passes"] = refBody["passes"];
      rb["outputs"] = refBody["outputs"];
      const Image full = aovOf(renderer.render(scene, api::parseRenderRequest(rb)), "reference");
      auto frame = [&](int D, int iters, Timing* t) {
        json b = b0;
        b["passes"] = {{"spherical_billboards", false},
                       {"illumination_network", {{"nodes", 1024}, {"directions", D}, {"iterations", iters}, {"warm_start", false}}}};
        Image img;
        const Timing timing = median(renderer, scene, b, "illumination_network", t ? repeats : 1, &img, nullptr, /*warmUp=*/false);
        if (t) *t = timing;
        return img;
      };
      const Image once = frame(512, 0, nullptr);
      Image ms = full;
      double meanFull = 0, meanMs = 0;
      for (std::size_t k = 0; k < ms.pixels.size(); ++k) {
        ms.pixels[k] = full.pixels[k] - once.pixels[k];
        meanFull += full.pixels[k], meanMs += ms.pixels[k];
      }
      for (int D : {4, 8, 16, 32, 64, 128}) {
        Timing t;
        const Image img = frame(D, iterations, &t), img0 = frame(D, 0, nullptr);
        Image msNet = img;
        for (std::size_t k = 0; k < msNet.pixels.size(); ++k) msNet.pixels[k] = img.pixels[k] - img0.pixels[k];
        std::printf("%-10s %4d %9.4f %9.4f %9.4f %9.3f %9.0f\n", g > 0 ? ("hg " + std::to_string(g).substr(0, 3)).c_str() : "isotropic",
                    D, blockError(img, full), blockError(img0, once), blockError(msNet, ms), meanMs / meanFull,
                    std::max(t.gpuMs, t.cpuMs));
        std::fflush(stdout);
      }
    }
    std::printf("end: %s\n", whenAndLoad().c_str());
    return 0;
  }

  // The goal: N 1024, D 128 against single scattering, per cloud, against that cloud's own reference.
  bool impostors = false;
  for (const auto& t : createTechniques()) impostors |= t->info().name == "depth_impostors";
  const double rp = 0.25 * std::cbrt(256.0 / 8000.0);
  const json particles = {{"kind", "cloud"}, {"tau", 10.0 * std::pow(1.0 + rp, 3) / (8000 * rp * rp * rp)},
                          {"albedo", {0.9, 0.9, 0.9}}, {"seed", 1},
                          {"generator", {{"count", 8000}, {"extent", {1, 1, 1}}, {"radius", rp}}}};
  for (const auto& [name, medium, count] : {std::tuple<const char*, json, int>{"homogeneous sphere", cloud, 1},
                                            std::tuple<const char*, json, int>{"8000 particles", particles, 8000}}) {
    json b0 = base;
    b0["media"] = json::array({medium});
    json rb = b0;
    rb["passes"] = refBody["passes"];
    rb["outputs"] = refBody["outputs"];
    const RenderOutput ro = renderer.render(scene, api::parseRenderRequest(rb));
    const Image ref = aovOf(ro, "reference");
    std::printf("\nthe goal on the %s (%d particles): reference full %d spp, %.0f ms\n", name, count, spp,
                passOf(ro, "reference").cpuMs);
    auto run = [&](const char* pass, json passes, int perParticles, double* errOut) {
      json b = b0;
      b["passes"] = passes;
      Image media;
      const Timing t = median(renderer, scene, b, pass, repeats, &media);
      const double err = blockError(media, ref);
      std::printf("  %-22s error %.4f  %9.2f ms gpu %9.2f ms cpu per frame  %8.4f ms per %s\n", pass, err, t.gpuMs,
                  t.cpuMs, std::max(t.gpuMs, t.cpuMs) / perParticles, perParticles == 1024 ? "node" : "particle");
      if (errOut) *errOut = err;
    };
    double net = 0, sbe = 0, die = 0;
    run("illumination_network",
        {{"illumination_network", {{"nodes", 1024}, {"directions", 128}, {"iterations", iterations}, {"warm_start", false}}}},
        1024, &net);
    run("spherical_billboards", {{"spherical_billboards", json::object()}}, count, &sbe);
    if (impostors) run("depth_impostors", {{"depth_impostors", json::object()}}, count, &die);
    std::printf("  ratio of errors to the network's: spherical_billboards %.2f", sbe / net);
    if (impostors) std::printf(", depth_impostors %.2f", die / net);
    std::printf("\n");
    std::fflush(stdout);
  }
  return 0;
}
