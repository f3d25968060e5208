// ambient_occlusion quality/speed curve (issue 5): GPU milliseconds of the AO pass and its error against
// the reference renderer's AO modes, for every method x samples {4, 8, 16, 32} x interleave on/off, on
// the built-in ao_creases scene at 256 x 256 with R = 0.5 m.
//   build/bench/ambient_occlusion_bench --benchmark_counters_tabular=true
// "interleave on" is thesis 4.1.3 as a whole: 4x4 rotated kernels plus the depth-aware 4x4 filter;
// "off" is one kernel for every pixel and no filter. Errors (mean absolute / RMS over the image):
// volumetric against the volumetric definition (thesis eq. 4.6, PathTracer AoVolumetric), the others
// against the cosine-weighted step definition (eq. 4.2, AoCosineStep); every method also against the
// cosine-weighted step (mae_cos), so methods compare across definitions. crytek has no AO definition of
// its own (whole-sphere depth comparison, 1/2 on open planes): it is scored against the step definition.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>

#include <benchmark/benchmark.h>

#include "renderer/Renderer.h"
#include "renderer/reference/PathTracer.h"
#include "renderer/scene/BuiltinScenes.h"

namespace {

using namespace radiant;

constexpr int kSize = 256;
constexpr float kRadius = 0.5f;
constexpr int kReferenceSpp = 256;
const char* const kMethods[] = {"volumetric", "containment", "crytek", "gtao"};

struct Fixture {
  Scene scene = loadBuiltinScene("ao_creases");
  std::unique_ptr<Renderer> renderer = std::make_unique<Renderer>();
  Image refVolumetric, refCosine;
  Fixture() {
    reference::PathTracer tracer(scene);
    Camera cam = scene.camera;
    cam.aspectRatio = 1.f;
    reference::ReferenceOptions o;
    o.aoRadius = kRadius;
    o.spp = kReferenceSpp;
    o.mode = reference::ReferenceOptions::Mode::AoVolumetric;
    refVolumetric = tracer.render(cam, kSize, kSize, o);
    o.mode = reference::ReferenceOptions::Mode::AoCosineStep;
    refCosine = tracer.render(cam, kSize, kSize, o);
    std::printf("GL renderer: %s | %s\n", renderer->device().renderer.c_str(), renderer->device().version.c_str());
  }
};

Fixture& fixture() {
  static Fixture f;
  return f;
}

struct Errors {
  double mae, rmse;
};
Errors errors(const Image& a, const Image& ref) {
  double s = 0.0, s2 = 0.0;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      const double d = a.at(x, y)[0] - ref.at(x, y)[0];
      s += std::abs(d);
      s2 += d * d;
    }
  const double n = static_cast<double>(kSize) * kSize;
  return {s / n, std::sqrt(s2 / n)};
}

void BM_AmbientOcclusion(benchmark::State& state) {
  Fixture& fx = fixture();
  const std::string method = kMethods[state.range(0)];
  const int samples = static_cast<int>(state.range(1));
  const bool interleave = state.range(2) != 0;
  api::RenderRequest req;
  req.width = req.height = kSize;
  req.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"ao"}, false}};
  req.passes["ambient_occlusion"] = {{"method", method},         {"samples", samples},
                                     {"radius", kRadius},        {"interleave", interleave},
                                     {"blur", interleave},       {"resolution_scale", "full"}};
  fx.renderer->render(fx.scene, req);  // warm-up: shader compilation, resource allocation
  double gpuMs = 0.0;
  RenderOutput out;
  for (auto _ : state) {
    out = fx.renderer->render(fx.scene, req);
    double ms = 0.0;
    for (const auto& p : out.stats.passes)
      if (p.name == "ambient_occlusion") ms = p.gpuMs;
    gpuMs += ms;
    state.SetIterationTime(ms * 1e-3);
  }
  const Image* ao = nullptr;
  for (const auto& a : out.aovs)
    if (a.aov == "ao") ao = &a;
  if (!ao) {
    state.SkipWithError("no ao AOV");
    return;
  }
  const Errors own = errors(*ao, method == "volumetric" ? fx.refVolumetric : fx.refCosine);
  const Errors cosine = errors(*ao, fx.refCosine);
  state.SetLabel(method + (interleave ? " interleave+blur" : " plain"));
  state.counters["gpu_ms"] = gpuMs / static_cast<double>(state.iterations());
  state.counters["mae_own"] = own.mae;
  state.counters["rmse_own"] = own.rmse;
  state.counters["mae_cos"] = cosine.mae;
}

void configurations(benchmark::internal::Benchmark* b) {
  for (int m = 0; m < 4; ++m)
    for (int samples : {4, 8, 16, 32})
      for (int interleave : {0, 1}) b->Args({m, samples, interleave});
}

BENCHMARK(BM_AmbientOcclusion)
    ->Apply(configurations)
    ->ArgNames({"method", "samples", "interleave"})
    ->Iterations(5)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
