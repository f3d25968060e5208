// The caustics technique (issue 14): thesis Table 6.1 as measured numbers (photon image P x caustic
// cube C, ms) with the error of the caustics AOV against the reference light tracer's caustics (the
// L S+ D E class), and the splat baseline over its radius at equal P. Plain main (no Google Benchmark):
//   build/bench/caustics_bench [size=96] [light_paths_per_pixel=512] [frames=3]
// CAUSTICS_BENCH_KNOBS={json} adds caustics parameters to every frame; CAUSTICS_BENCH_QUICK=1 measures
// only P 128 / C 256. The secondary lookup (specular_lookup, beauty only) is off: the AOV is scored.
// Scene: the built-in cornell_glass (glass sphere, point light), its own camera. Reference: the light
// tracer (renderer/reference/LightTracer.h, Paths::Caustics, maxBounces 8) at the given paths per pixel,
// seed 1; its own noise is measured against a second run with seed 2 (RMSE of the difference / sqrt 2).
// The frames are rendered at 3x the size and box-filtered 3x3 (the light tracer averages over pixels).
// `caustics ms` = the pass's GPU time (GL_TIME_ELAPSED), minimum over `frames` frames; the specular
// pass's distance maps are cached after the first frame, photon_gi is off. Prints Markdown tables.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "renderer/Renderer.h"
#include "renderer/frame/FrameView.h"
#include "renderer/io/ImageIO.h"
#include "renderer/metrics/Metrics.h"
#include "renderer/raytracing/RayScene.h"
#include "renderer/reference/LightTracer.h"
#include "renderer/scene/BuiltinScenes.h"
#include "tests/gl/specular/SpecularTestSupport.h"

namespace {

using namespace radiant;

const Image& aov(const RenderOutput& out, const std::string& name) {
  for (const auto& a : out.aovs)
    if (a.aov == name) return a;
  std::fprintf(stderr, "missing aov %s\n", name.c_str());
  std::exit(1);
}

struct Run {
  double ms = 1e30, cpuMs = 1e30;
  double rmse = 0, relMse = 0;
  double flux = 0;  // sum of the caustics image (luminance-free: green channel)
};

double sumGreen(const Image& img) {
  double s = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) s += img.at(x, y)[1];
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  const int size = argc > 1 ? std::atoi(argv[1]) : 96;
  const int paths = argc > 2 ? std::atoi(argv[2]) : 512;
  const int frames = argc > 3 ? std::atoi(argv[3]) : 3;
  Scene scene = loadBuiltinScene("cornell_glass");
  Renderer renderer;
  std::printf("GL renderer: %s\n", renderer.device().renderer.c_str());

  // The raster frame samples pixel centres, the light tracer averages over each pixel: the frames are
  // rendered at 3x the size and box-filtered (a focus smaller than a pixel is otherwise hit or missed).
  constexpr int kSuper = 3;
  api::RenderRequest base;
  base.width = base.height = size * kSuper;
  base.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"beauty", "caustics"}, false}};
  base.disabledPasses.insert("photon_gi");

  // Reference caustics: the light tracer, two seeds.
  api::RenderRequest refRequest = base;
  refRequest.width = refRequest.height = size;
  const FrameView view = makeFrameView(scene, refRequest);
  rt::RayScene rays(scene);
  reference::LightTracer tracer(rays);
  reference::LightTracerOptions o;
  o.pathsPerPixel = paths;
  o.paths = reference::LightTracerOptions::Paths::Caustics;
  auto t0 = std::chrono::steady_clock::now();
  o.seed = 1;
  const Image ref = tracer.render(view.camera, size, size, o);
  const double refMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  o.seed = 2;
  const Image ref2 = tracer.render(view.camera, size, size, o);
  const metrics::ImageMetrics noise = metrics::compareImages(ref2, ref);
  if (const char* dir = std::getenv("CAUSTICS_BENCH_IMAGES")) {
    io::writeFile(std::string(dir) + "/reference_caustics.png", io::encodePng(ref, 0.f));
  }
  std::printf("reference: light tracer %d paths/pixel at %dx%d, %.0f ms; its own noise RMSE %.5f (relMSE %.5f), "
              "caustic sum %.3f\n\n",
              paths, size, size, refMs, noise.rmse / std::sqrt(2.0), noise.relMse / 2.0, sumGreen(ref));

  auto measure = [&](nlohmann::json knobs) {
    api::RenderRequest r = base;
    if (std::getenv("CAUSTICS_BENCH_ENERGY")) knobs["energy_check"] = true;
    // The caustics AOV is scored; the secondary lookup (LS+DS+E, beauty only) is not part of it.
    knobs["specular_lookup"] = false;
    if (const char* extra = std::getenv("CAUSTICS_BENCH_KNOBS")) knobs.update(nlohmann::json::parse(extra));
    r.passes["caustics"] = knobs;
    Run run;
    for (int f = 0; f < frames; ++f) {
      RenderOutput out = renderer.render(scene, r);
      for (const auto& p : out.stats.passes)
        if (p.name == "caustics") {
          run.ms = std::min(run.ms, p.gpuMs);
          run.cpuMs = std::min(run.cpuMs, p.cpuMs);
        }
      if (f == frames - 1) {
        const Image c = testing::boxDownsample(aov(out, "caustics"), kSuper);
        const metrics::ImageMetrics m = metrics::compareImages(c, ref);
        run.rmse = m.rmse;
        run.relMse = m.relMse;
        run.flux = sumGreen(c);
        if (std::getenv("CAUSTICS_BENCH_ENERGY"))
          for (const auto& p : out.stats.passes)
            if (p.name == "caustics")
              std::fprintf(stderr, "%s: photon %.4f lost %.4f deposited %.4f valid %.0f\n", knobs.dump().c_str(),
                           p.counters.at("photon_power"), p.counters.at("lost_power"), p.counters.at("deposited_power"),
                           p.counters.at("valid_photons"));
        if (const char* dir = std::getenv("CAUSTICS_BENCH_IMAGES"))
          io::writeFile(std::string(dir) + "/caustics_" + knobs.dump() + ".png", io::encodePng(c, 0.f));
      }
    }
    return run;
  };

  if (std::getenv("CAUSTICS_BENCH_QUICK")) {  // one cell (P 128, C 256), e.g. to sweep CAUSTICS_BENCH_KNOBS
    const Run t = measure({{"photon_resolution", 128}, {"cube_resolution", 256}});
    std::printf("P 128, C 256: %.1f ms / %.4f (%.4f) / %.2f\n", t.ms, t.rmse, t.relMse, t.flux / sumGreen(ref));
    return 0;
  }
  std::printf("Table 6.1 measured: caustics pass GPU ms / RMSE against the light tracer (relMSE) / image sum "
              "over the reference's\n\n");
  std::printf("| C \\ P | 32 | 64 | 128 | 256 |\n|---|---|---|---|---|\n");
  for (int C : {64, 128, 256, 512}) {
    std::printf("| %d |", C);
    for (int P : {32, 64, 128, 256}) {
      const Run r = measure({{"photon_resolution", P}, {"cube_resolution", C}});
      std::printf(" %.1f ms / %.4f (%.4f) / %.2f |", r.ms, r.rmse, r.relMse, r.flux / sumGreen(ref));
      std::fflush(stdout);
    }
    std::printf("\n");
  }
  std::printf("\nSplat baseline at P = 128, C = 256, against the triangles at the same P and C\n\n");
  std::printf("| method | splat radius | ms | RMSE | relMSE | image sum (ref %.3f) |\n|---|---|---|---|---|---|\n",
              sumGreen(ref));
  {
    const Run t = measure({{"photon_resolution", 128}, {"cube_resolution", 256}});
    std::printf("| triangles | - | %.1f | %.4f | %.4f | %.3f |\n", t.ms, t.rmse, t.relMse, t.flux);
  }
  for (double radius : {0.0025, 0.005, 0.01, 0.02, 0.04, 0.08}) {
    const Run s = measure({{"photon_resolution", 128}, {"cube_resolution", 256}, {"method", "splat"}, {"splat_radius", radius}});
    std::printf("| splat | %.4f | %.1f | %.4f | %.4f | %.3f |\n", radius, s.ms, s.rmse, s.relMse, s.flux);
    std::fflush(stdout);
  }
  return 0;
}
