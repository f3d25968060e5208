// Reference path tracer throughput on the built-in Cornell box at 256x256 with up to 16 bounces
// (issue 4's benchmark). Reports rays per second and the time 256 spp would take.
//   build/bench/reference_bench --benchmark_min_time=1
#include <chrono>

#include <benchmark/benchmark.h>

#include "renderer/reference/PathTracer.h"
#include "renderer/scene/BuiltinScenes.h"

namespace {

void BM_ReferenceCornell(benchmark::State& state) {
  using namespace radiant;
  const Scene scene = loadBuiltinScene("cornell_box");
  reference::PathTracer pt(scene);
  reference::ReferenceOptions o;
  o.spp = static_cast<int>(state.range(0));
  o.maxBounces = 16;
  o.russianRoulette = state.range(1) != 0;
  Camera cam = scene.camera;
  cam.aspectRatio = 1.f;
  std::uint64_t rays = 0;
  double seconds = 0;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    Image img = pt.render(cam, 256, 256, o);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    rays += pt.raysTraced();
    benchmark::DoNotOptimize(img.pixels.data());
  }
  state.counters["rays_per_s"] = benchmark::Counter(static_cast<double>(rays), benchmark::Counter::kIsRate);
  state.counters["s_per_256spp"] = seconds / state.iterations() * 256.0 / o.spp;
}
BENCHMARK(BM_ReferenceCornell)->Args({16, 1})->Args({16, 0})->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
