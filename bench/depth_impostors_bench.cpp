// Hierarchical depth impostors (issue 17): milliseconds of the depth_impostors pass against the
// particles per block b at N = 8000 (thesis Fig. 8.6: the optimum near 40 blocks), with the
// spherical_billboards pass on the same cloud as the per-particle baseline.
//   build/bench/depth_impostors_bench [size=256] [repeats=5] [N=8000] [error_size=64] [fourier_b=200]
// Two timings per b, each the median of `repeats` frames after one warm-up:
//   static:   the same cloud, camera and light every frame: blocks and impostors come from the cache,
//             the pass only gathers (one quad per block);
//   animated: a new cloud every frame (the generator's seed alternates), as in the thesis' animated
//             cloud: blocks (CPU clustering), both impostor atlases and the slices are rebuilt.
// gpu_ms is GL_TIME_ELAPSED around the pass, cpu_ms the CPU time of prepare+execute (on llvmpipe the
// GPU is the CPU, so the sum is the cost). rel_rmse: the media AOV at error_size^2 against the
// volumetric reference in single_scatter mode (rendered once), RMSE over the reference's mean: a time
// optimum means nothing without it (one block of 8000 particles is cheap and wrong).
// Then the opacity-shadow-map comparison at b = fourier_b: the light's transmittance from K slices
// against Fourier opacity maps (light_transmittance: fourier) of equal texture memory, K = 4, 8, 12, 16
// against M = 1, 3, 5, 7 (K/4 RGBA textures each), the same two timings and rel_rmse.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <utility>
#include <vector>

#include "api/Validate.h"
#include "bench/BenchSupport.h"
#include "renderer/Renderer.h"
#include "renderer/scene/Scene.h"

namespace {

using namespace radiant;
using bench::aovOf;
using bench::relativeRmse;
using nlohmann::json;

json cloud(int n, int seed) {
  const double r = 0.25 * std::cbrt(256.0 / n);
  const double tau = 10.0 * std::pow(1.0 + r, 3) / (n * r * r * r);  // optical diameter 20
  return {{"kind", "cloud"}, {"tau", tau}, {"albedo", {0.9, 0.9, 0.9}}, {"seed", seed},
          {"generator", {{"count", n}, {"extent", {1, 1, 1}}, {"radius", r}}}};
}

struct Timing {
  double gpuMs, cpuMs, blocks, res;
};

Timing timePass(Renderer& r, const Scene& scene, json body, const char* pass, int repeats, bool animate, int n) {
  std::vector<double> gpu, cpu;
  Timing t{0, 0, 0, 0};
  for (int i = 0; i <= repeats; ++i) {
    body["media"] = json::array({cloud(n, animate ? 1 + (i % 2) : 1)});
    std::fflush(stdout);
    const RenderOutput out = r.render(scene, api::parseRenderRequest(body));
    for (const auto& p : out.stats.passes)
      if (p.name == pass && i > 0) {
        gpu.push_back(p.gpuMs), cpu.push_back(p.cpuMs);
        if (p.counters.count("blocks")) t.blocks = p.counters.at("blocks"), t.res = p.counters.at("impostor_resolution");
      }
  }
  std::sort(gpu.begin(), gpu.end());
  std::sort(cpu.begin(), cpu.end());
  t.gpuMs = gpu[gpu.size() / 2], t.cpuMs = cpu[cpu.size() / 2];
  return t;
}

}  // namespace

int main(int argc, char** argv) {
  const int size = argc > 1 ? std::atoi(argv[1]) : 256;
  const int repeats = argc > 2 ? std::atoi(argv[2]) : 5;
  const int n = argc > 3 ? std::atoi(argv[3]) : 8000;
  Renderer renderer;
  std::printf("GL renderer: %s | %s\n", renderer.device().renderer.c_str(), renderer.device().version.c_str());
  Scene scene;
  scene.name = "impostors-bench";
  Light sun;
  sun.type = LightType::Directional;
  sun.direction = glm::normalize(glm::vec3(-1.f, -0.5f, -0.6f));
  sun.intensity = 3.f;
  scene.lights.push_back(sun);
  Camera cam;
  cam.yfov = glm::radians(40.f);
  cam.znear = 0.05f;
  cam.world = glm::mat4(1.f);
  cam.world[3] = glm::vec4(0.f, 0.f, 4.f, 1.f);
  cam.fromFile = true;
  scene.camera = cam;
  scene.features = computeFeatures(scene);
  // One raster sample per pixel, as this bench's figures in docs/PERFORMANCE.md were measured (the
  // HTTP default is "supersampling": 2 since 2026-12-02; the C++ RenderRequest's stays 1).
  const json base = {{"scene", {{"builtin", "unused"}}}, {"width", size}, {"height", size}, {"supersampling", 1},
                     {"passes", {{"direct", false}, {"photon_gi", false}}},
                     {"outputs", json::array({{{"format", "exr"}, {"aovs", {"media"}}}})}};

  const int errorSize = argc > 4 ? std::atoi(argv[4]) : 64;
  json small = base;
  small["width"] = small["height"] = errorSize;
  small["media"] = json::array({cloud(n, 1)});
  json refBody = small;
  refBody["passes"]["reference"] = {{"aov", "media"}, {"media_mode", "single_scatter"}, {"spp", 1}};
  refBody["outputs"] = json::array({{{"format", "exr"}, {"aovs", {"reference"}}}});
  const Image reference = aovOf(renderer.render(scene, api::parseRenderRequest(refBody)), "reference");
  auto errorOf = [&](const json& passes) {
    json body = small;
    for (auto& [k, v] : passes.items()) body["passes"][k] = v;
    return relativeRmse(aovOf(renderer.render(scene, api::parseRenderRequest(body)), "media"), reference);
  };

  std::printf("\ncloud of N = %d particles (optical diameter 20, albedo 0.9), %dx%d, one directional light\n", n, size, size);
  for (bool animate : {false, true}) {
    json body = base;
    const Timing sb = timePass(renderer, scene, body, "spherical_billboards", repeats, animate, n);
    std::printf("\n%s: spherical_billboards (per particle, unshadowed): gpu %.1f ms, cpu %.1f ms, total %.1f ms, "
                "rel_rmse %.3f\n",
                animate ? "animated" : "static", sb.gpuMs, sb.cpuMs, sb.gpuMs + sb.cpuMs, errorOf(json::object()));
    std::printf("%8s %8s %6s %9s %9s %9s %9s\n", "b", "blocks", "res", "gpu_ms", "cpu_ms", "total_ms", "rel_rmse");
    double best = 1e30, bestB = 0, bestBlocks = 0;
    for (int b : {2, 5, 10, 20, 50, 100, 200, 400, 800, 2000, 8000}) {
      if (b > n) continue;
      body["passes"]["depth_impostors"] = {{"particles_per_block", b}};
      const Timing t = timePass(renderer, scene, body, "depth_impostors", repeats, animate, n);
      std::printf("%8d %8.0f %6.0f %9.1f %9.1f %9.1f", b, t.blocks, t.res, t.gpuMs, t.cpuMs, t.gpuMs + t.cpuMs);
      if (animate) std::printf("         -\n");  // the same cloud as the static rows: measured there
      else std::printf(" %9.3f\n", errorOf(body["passes"]));
      if (t.gpuMs + t.cpuMs < best) best = t.gpuMs + t.cpuMs, bestB = b, bestBlocks = t.blocks;
    }
    std::printf("%s optimum: b = %.0f (%.0f blocks), %.1f ms\n", animate ? "animated" : "static", bestB, bestBlocks, best);
  }

  const int fourierB = argc > 5 ? std::atoi(argv[5]) : 200;
  std::printf("\nlight transmittance at equal texture memory, b = %d: slices against Fourier opacity maps\n", fourierB);
  std::printf("%9s %6s %6s %10s %10s %12s %12s %9s\n", "source", "knob", "RGBA", "static_gpu", "static_cpu", "static_total",
              "animated_ms", "rel_rmse");
  for (auto [K, M] : {std::pair{4, 1}, std::pair{8, 3}, std::pair{12, 5}, std::pair{16, 7}}) {
    for (bool fourier : {false, true}) {
      json body = base;
      json p = {{"particles_per_block", fourierB}, {"slices", K}};
      if (fourier) p["light_transmittance"] = "fourier", p["fourier_terms"] = M;
      body["passes"]["depth_impostors"] = p;
      const Timing st = timePass(renderer, scene, body, "depth_impostors", repeats, false, n);
      const Timing an = timePass(renderer, scene, body, "depth_impostors", repeats, true, n);
      std::printf("%9s %4s%2d %6d %10.1f %10.1f %12.1f %12.1f %9.3f\n", fourier ? "fourier" : "slices", fourier ? "M=" : "K=",
                  fourier ? M : K, (K + 3) / 4, st.gpuMs, st.cpuMs, st.gpuMs + st.cpuMs, an.gpuMs + an.cpuMs,
                  errorOf(body["passes"]));
    }
  }
  return 0;
}
