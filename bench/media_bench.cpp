// Participating media (issue 16): milliseconds of the spherical_billboards pass against the particle
// layer's resolution ratio (thesis Table 7.1) and against particle count and overdraw, for the
// spherical, planar and soft methods, each with its error against the volumetric reference
// (single_scatter_unshadowed, the model the technique solves; pixel centres).
//   build/bench/media_bench [size=512] [repeats=5]
// Timing: the pass's GPU time (GL_TIME_ELAPSED) as the median of `repeats` frames after one warm-up;
// the CPU part (sorting, source radiance per particle) is reported separately. Error: RMSE of the
// media AOV over the reference's mean (relative RMSE).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "api/Validate.h"
#include "bench/BenchSupport.h"
#include "renderer/Renderer.h"
#include "renderer/scene/BuiltinScenes.h"

namespace {

using namespace radiant;
using bench::aovOf;
using bench::relativeRmse;
using nlohmann::json;

struct Timing {
  double gpuMs, cpuMs, overdraw;
};

Timing timePass(Renderer& r, const Scene& scene, const json& body, int repeats) {
  std::vector<double> gpu, cpu;
  double overdraw = 0;
  for (int i = 0; i <= repeats; ++i) {
    const RenderOutput out = r.render(scene, api::parseRenderRequest(body));
    for (const auto& p : out.stats.passes)
      if (p.name == "spherical_billboards" && i > 0) {
        gpu.push_back(p.gpuMs), cpu.push_back(p.cpuMs);
        overdraw = p.counters.at("overdraw_estimate");
      }
  }
  std::sort(gpu.begin(), gpu.end());
  std::sort(cpu.begin(), cpu.end());
  return {gpu[gpu.size() / 2], cpu[cpu.size() / 2], overdraw};
}

}  // namespace

int main(int argc, char** argv) {
  const int size = argc > 1 ? std::atoi(argv[1]) : 512;
  const int repeats = argc > 2 ? std::atoi(argv[2]) : 5;
  Renderer renderer;
  std::printf("GL renderer: %s | %s\n", renderer.device().renderer.c_str(), renderer.device().version.c_str());
  const Scene scene = loadBuiltinScene("explosion");
  // Only the G-buffer (the scene depth the particles read) besides the media pass: the opaque
  // shading passes cost seconds on llvmpipe and do not change the media pass's work.
  // One raster sample per pixel, as this bench's figures in docs/PERFORMANCE.md were measured (the
  // HTTP default is "supersampling": 2 since 2026-12-02; the C++ RenderRequest's stays 1).
  json base = {{"scene", {{"builtin", "explosion"}}}, {"width", size}, {"height", size}, {"supersampling", 1},
               {"passes", {{"direct", false}, {"photon_gi", false}}},
               {"outputs", json::array({{{"format", "exr"}, {"aovs", {"media"}}}})}};

  // The reference once (pixel centres, deterministic).
  json refBody = base;
  refBody["passes"]["spherical_billboards"] = false;
  refBody["passes"]["reference"] = {{"aov", "media"}, {"media_mode", "single_scatter_unshadowed"}, {"spp", 1}};
  refBody["outputs"] = json::array({{{"format", "exr"}, {"aovs", {"reference"}}}});
  const RenderOutput refOut = renderer.render(scene, api::parseRenderRequest(refBody));
  const Image reference = aovOf(refOut, "reference");

  std::printf("\nexplosion (%zu particles), %dx%d: ms of the spherical_billboards pass by layer ratio\n",
              scene.features.particles, size, size);
  std::printf("%-10s %-6s %9s %9s %9s %12s\n", "method", "ratio", "gpu_ms", "cpu_ms", "overdraw", "rel_rmse");
  for (const char* method : {"spherical", "planar", "soft"})
    for (double ratio : {1.0, 0.5, 0.25, 0.125}) {
      json body = base;
      body["passes"]["spherical_billboards"] = {{"method", method}, {"resolution_ratio", ratio}};
      const Timing t = timePass(renderer, scene, body, repeats);
      const Image media = aovOf(renderer.render(scene, api::parseRenderRequest(body)), "media");
      std::printf("%-10s %-6.3f %9.2f %9.2f %9.1f %12.4f\n", method, ratio, t.gpuMs, t.cpuMs, t.overdraw,
                  relativeRmse(media, reference));
    }

  std::printf("\nparticle count (smoke cloud of radius-0.3 m particles in the explosion room), ratio 1\n");
  std::printf("%-10s %8s %9s %9s %9s\n", "method", "count", "gpu_ms", "cpu_ms", "overdraw");
  for (const char* method : {"spherical", "planar", "soft"})
    for (int count : {64, 256, 1024, 4096}) {
      json body = base;
      body["passes"]["spherical_billboards"] = {{"method", method}};
      body["media"] = json::array({{{"kind", "smoke"},
                                    {"tau", 1.0},
                                    {"generator", {{"center", {0, 1.2, 0}}, {"extent", {1.5, 0.8, 1.5}},
                                                   {"count", count}, {"radius", 0.3}}}}});
      Scene empty = scene;
      empty.media.clear();  // only the request's cloud
      empty.features = computeFeatures(empty);
      const Timing t = timePass(renderer, empty, body, repeats);
      std::printf("%-10s %8d %9.2f %9.2f %9.1f\n", method, count, t.gpuMs, t.cpuMs, t.overdraw);
    }
  return 0;
}
