// env_diffuse (issue 6): GPU time and error on the built-in Cornell box, 128x128, receivers sphere and
// tall box (extras flags), for M (downsample) in {2, 4, 8} x cube resolution {64, 128, 256}, polygon
// form factor; plus the three methods at M = 4, R = 128 (the thesis' tables 3.1 / 3.2).
//   build/bench/env_diffuse_bench --benchmark_counters_tabular=true
// Reported time = GL_TIME_ELAPSED of the env_diffuse pass in steady state (cube maps cached: the
// final gathering only). Counters: build_ms = the pass's GPU time on the frame that renders the cube
// maps (both receivers, all faces, downsampling, area lights, irradiance map); rel_rmse_* = relative
// RMS error on the receivers' pixels (3x3 box filtered, silhouettes excluded) against the reference
// path tracer's one-bounce indirect light (bounce range [2, 2], 512 spp).
#include <algorithm>
#include <climits>
#include <cmath>
#include <memory>

#include <benchmark/benchmark.h>

#include "renderer/Renderer.h"
#include "renderer/reference/PathTracer.h"
#include "renderer/scene/BuiltinScenes.h"
#include "tests/gl/env_diffuse/EnvDiffuseTestSupport.h"

namespace {
using namespace radiant;

constexpr int kSize = 128;

struct Fixture {
  Renderer renderer;
  Scene scene = loadBuiltinScene("cornell_box");
  Image reference;
  testing::Masks masks;

  Fixture() {
    reference::PathTracer pt(scene);
    reference::ReferenceOptions o;
    o.spp = 512;
    o.minPathBounce = 2;
    o.maxPathBounce = 2;
    Camera cam = scene.camera;
    cam.aspectRatio = 1.f;
    reference = pt.render(cam, kSize, kSize, o);
    masks = testing::receiverMasks(renderer, scene, kSize);
  }
  double relRmse(const Image& t, int which) const { return testing::relRmse3(t, reference, masks, which); }
};

Fixture& fixture() {
  static std::unique_ptr<Fixture> f = std::make_unique<Fixture>();
  return *f;
}

double envGpuMs(const RenderOutput& out) {
  for (const auto& p : out.stats.passes)
    if (p.name == "env_diffuse") return p.gpuMs;
  return 0;
}

void run(benchmark::State& state, const char* method, int M, int R) {
  Fixture& f = fixture();
  api::RenderRequest req;
  req.width = req.height = kSize;
  req.passes["env_diffuse"] = {{"form_factor", method}, {"downsample", M}, {"cube_resolution", R}};
  req.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"indirect_diffuse"}, false}};
  // A fresh renderer has no cached cube maps: its first frame measures building them.
  double buildMs = 0;
  {
    Renderer fresh;
    buildMs = envGpuMs(fresh.render(f.scene, req));
  }
  f.renderer.render(f.scene, req);  // warm the steady-state renderer's cache
  const Image* indirect = nullptr;
  RenderOutput out;
  for (auto _ : state) {
    out = f.renderer.render(f.scene, req);
    state.SetIterationTime(envGpuMs(out) / 1000.0);
  }
  for (const auto& a : out.aovs)
    if (a.aov == "indirect_diffuse") indirect = &a;
  state.counters["build_ms"] = buildMs;
  state.counters["rel_rmse_sphere"] = f.relRmse(*indirect, 1);
  state.counters["rel_rmse_box"] = f.relRmse(*indirect, 2);
  state.SetLabel(std::string(method) + " M=" + std::to_string(M) + " R=" + std::to_string(R));
}

void BM_EnvDiffusePolygon(benchmark::State& state) {
  run(state, "polygon", static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
}
BENCHMARK(BM_EnvDiffusePolygon)
    ->ArgsProduct({{2, 4, 8}, {64, 128, 256}})
    ->Iterations(3)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);

void BM_EnvDiffuseMethods(benchmark::State& state) {
  static const char* methods[] = {"classic", "point", "polygon"};
  run(state, methods[state.range(0)], static_cast<int>(state.range(1)), 128);
}
BENCHMARK(BM_EnvDiffuseMethods)
    ->ArgsProduct({{0, 1, 2}, {2, 4}})
    ->Iterations(3)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
