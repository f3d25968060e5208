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

namespace {
using namespace radiant;

constexpr int kSize = 128;

struct Fixture {
  Renderer renderer;
  Scene scene = loadBuiltinScene("cornell_box");
  Image reference;
  std::vector<int> mask;  // 1 sphere, 2 tall box, 0 other or silhouette

  Fixture() {
    reference::PathTracer pt(scene);
    reference::ReferenceOptions o;
    o.spp = 512;
    o.minPathBounce = 2;
    o.maxPathBounce = 2;
    Camera cam = scene.camera;
    cam.aspectRatio = 1.f;
    reference = pt.render(cam, kSize, kSize, o);
    // Receiver mask from the rasteriser: the receivers made emissive, read back from the G-buffer.
    Scene s = scene;
    s.digest += "|mask";
    for (MeshInstance& m : s.meshes) {
      if (m.name != "sphere" && m.name != "tall_box") continue;
      Material mat = s.material(m.material);
      mat.emissiveFactor = m.name == "sphere" ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
      s.materials.push_back(mat);
      m.material = static_cast<int>(s.materials.size()) - 1;
    }
    api::RenderRequest r;
    r.width = r.height = kSize;
    r.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"emission"}, false}};
    RenderOutput out = renderer.render(s, r);
    const Image& e = out.aovs.back();
    std::vector<int> id(kSize * kSize);
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x) id[y * kSize + x] = e.at(x, y)[0] > 0.5f ? 1 : e.at(x, y)[1] > 0.5f ? 2 : 0;
    mask = id;
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int X = std::clamp(x + dx, 0, kSize - 1), Y = std::clamp(y + dy, 0, kSize - 1);
            if (id[Y * kSize + X] != id[y * kSize + x]) mask[y * kSize + x] = 0;
          }
  }

  double relRmse(const Image& t, int which) const {
    double num = 0, den = 0;
    for (int y = 1; y + 1 < kSize; ++y)
      for (int x = 1; x + 1 < kSize; ++x) {
        bool inside = true;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) inside = inside && mask[(y + dy) * kSize + x + dx] == which;
        if (!inside) continue;
        for (int c = 0; c < 3; ++c) {
          double a = 0, b = 0;
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) a += t.at(x + dx, y + dy)[c], b += reference.at(x + dx, y + dy)[c];
          num += (a - b) * (a - b);
          den += b * b;
        }
      }
    return std::sqrt(num / den);
  }
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
