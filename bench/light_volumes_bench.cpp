// light_volumes (issue 15): GPU time of the gathering against the beam count for the linear traversal
// (the paper's loop over every beam) and the culled one (BVH over the beams' cones), the error against
// the reference light tracer, and the comparison with caustic triangles and photon splatting.
//   build/bench/light_volumes_bench timing <width> <height> [max_linear_beams=5120] [max_bvh_beams=81920] [frames=3]
//     [min_beams=0] (rows with fewer beams are skipped: extend a run without repeating it)
//   build/bench/light_volumes_bench compare [size=128] [lt_paths_per_pixel=256] [scene name prefix] [methods=all|light_volumes] [max_subdivision_beams]
// Scenes (a Lambertian floor, albedo 0.5, seen from straight above by an orthographic camera that sits
// below every scatterer, so that the light tracer's camera connections see the floor directly):
//   ring    the paper's cardioid (Fig. 2): a half ring of mirror (radius 0.5 m, 0.2 m tall, roughness
//           0, R = 0.9) lit by a point light over its open side; facets x rows x 2 triangles from 40 x 1
//           (80 beams) to 1280 x 32 (81920 beams).
//   water   the paper's Fig. 3: a wavy water surface (ior 1.33, roughness 0, 20 x 20 x 2 triangles,
//           1 m square, waves of 2 cm) 0.5 m over the floor under a point light.
//   window  a frosted window (thin glass pane, ior 1.5, 0.4 m, 32 x 32 x 2) 0.8 m over the floor under
//           a point light, roughness 0.1 / 0.2 / 0.3 / 0.4 (sigma ~ 0.016 / 0.06 / 0.14 / 0.25 rad).
//   plate   a glossy metal plate (0.6 m, roughness 0.3, R = 0.9, 24 x 24 x 2) 1.2 m above the floor,
//           lit from below by a spot (the scene of tests/unit/light_volumes CalibrationTest).
// timing: one line per run: beams, traversal, the pass's GPU ms (beams cached, median of `frames`),
//   setup and BVH ms, and the relative L1 of bvh against linear at the same beam count.
// compare: per scene, the light_volumes AOV, the caustics AOV (caustic triangles and their splat
//   mode; mirror and smooth glass only) and photon_gi's indirect AOV (max_bounces 2) against the light
//   tracer's image of the paths with exactly two scattering events (L S D E, L G D E: the only ones in
//   these scenes that end on the floor with two events): relative L1, energy ratio, GPU ms of the pass
//   (caches warm, median of 3), and the light tracer's own noise floor.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "bench/BenchSupport.h"
#include "renderer/Renderer.h"
#include "renderer/raytracing/RayScene.h"
#include "renderer/reference/LightTracer.h"
#include "tests/support/SceneBuilder.h"

namespace {

using namespace radiant;
using bench::aovOf;
using bench::relativeRmse;

Renderer& renderer() {
  static std::unique_ptr<Renderer> r = std::make_unique<Renderer>();
  return *r;
}

Material metal(float roughness, float base) {
  Material m = testing::lambertian(glm::vec3(base));
  m.metallicFactor = 1.f;
  m.roughnessFactor = roughness;
  return m;
}

// Half ring around -x (angles 90..270 degrees), normals pointing to the axis (the mirror's inside).
Scene ringScene(int facets, int rows) {
  testing::SceneBuilder b;
  const int floor = b.material(testing::lambertian(glm::vec3(0.5f)));
  b.quad(glm::vec3(0.f), {1.f, 0, 0}, {0, 0, -1.f}, floor, "floor");
  MeshInstance m;
  m.name = "ring";
  m.material = b.material(metal(0.f, 0.9f));
  const float R = 0.5f, H = 0.2f, pi = 3.14159265f;
  for (int i = 0; i <= facets; ++i)
    for (int j = 0; j <= rows; ++j) {
      const float a = 0.5f * pi + pi * i / facets;
      m.positions.push_back({R * std::cos(a), H * j / rows, R * std::sin(a)});
      m.normals.push_back({-std::cos(a), 0.f, -std::sin(a)});
    }
  for (int i = 0; i < facets; ++i)
    for (int j = 0; j < rows; ++j) {
      const std::uint32_t p = i * (rows + 1) + j, q = p + rows + 1;
      m.indices.insert(m.indices.end(), {p, p + 1, q, q, p + 1, q + 1});
    }
  // Wind every triangle to face the axis.
  for (std::size_t t = 0; t < m.indices.size(); t += 3) {
    const glm::vec3 a = m.positions[m.indices[t]], bb = m.positions[m.indices[t + 1]], c = m.positions[m.indices[t + 2]];
    if (glm::dot(glm::cross(bb - a, c - a), m.normals[m.indices[t]]) < 0.f) std::swap(m.indices[t + 1], m.indices[t + 2]);
  }
  for (auto& p : m.positions) m.bounds.extend(p);
  b.scene().meshes.push_back(std::move(m));
  b.pointLight({1.6f, 0.9f, 0.f}, 4.f);
  b.topDownOrtho(1.5f, 0.7f);
  return b.build("bench:light_volumes:ring:" + std::to_string(facets) + "x" + std::to_string(rows));
}

Scene plateScene() {
  testing::SceneBuilder b;
  const int floor = b.material(testing::lambertian(glm::vec3(0.5f)));
  b.quad(glm::vec3(0.f), {3.f, 0, 0}, {0, 0, -3.f}, floor, "floor");
  const glm::vec3 light(-0.3f, 0.4f, 0.f), centre(0.f, 1.2f, 0.f);
  b.gridY(centre, 0.3f, 24, false, b.material(metal(0.3f, 0.9f)), "plate");
  // A spot light pointing up at the plate: the floor gets no direct light, only what the plate sends.
  b.spotLight(light, centre - light, 3.f, 0.7f, 0.8f);
  b.topDownOrtho(1.f, 2.f);
  return b.build("bench:light_volumes:plate");
}

Material glass(float roughness, float ior) {
  Material m = testing::lambertian(glm::vec3(1.f));
  m.transmissionFactor = 1.f;
  m.roughnessFactor = roughness;
  m.ior = ior;
  m.doubleSided = true;
  return m;
}

// A height field y = y0 + h(x, z) over [-half, half]^2 with n x n x 2 triangles, normals from the
// analytic gradient (facing +y).
template <class H, class G>
MeshInstance heightField(float y0, float half, int n, H h, G grad, int material, const std::string& name) {
  MeshInstance m;
  m.name = name;
  m.material = material;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      const float x = -half + 2.f * half * i / n, z = -half + 2.f * half * j / n;
      m.positions.push_back({x, y0 + h(x, z), z});
      const glm::vec2 g = grad(x, z);
      m.normals.push_back(glm::normalize(glm::vec3(-g.x, 1.f, -g.y)));
    }
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const std::uint32_t p = i * (n + 1) + j, q = p + n + 1;
      // counter-clockwise seen from +y
      m.indices.insert(m.indices.end(), {p, p + 1, q, q, p + 1, q + 1});
    }
  for (auto& p : m.positions) m.bounds.extend(p);
  return m;
}

Scene waterScene() {
  testing::SceneBuilder b;
  const int floor = b.material(testing::lambertian(glm::vec3(0.5f)));
  b.quad(glm::vec3(0.f), {1.5f, 0, 0}, {0, 0, -1.5f}, floor, "floor");
  const float a = 0.02f, k = 2.f * 3.14159265f / 0.5f;  // 2 cm waves of 0.5 m wavelength
  b.scene().meshes.push_back(heightField(
      0.5f, 0.5f, 20, [&](float x, float z) { return a * std::sin(k * x) * std::cos(0.8f * k * z); },
      [&](float x, float z) {
        return glm::vec2(a * k * std::cos(k * x) * std::cos(0.8f * k * z), -a * 0.8f * k * std::sin(k * x) * std::sin(0.8f * k * z));
      },
      b.material(glass(0.f, 1.33f)), "water"));
  b.pointLight({0.2f, 1.5f, 0.1f}, 4.f);
  b.topDownOrtho(0.4f, 0.8f);
  return b.build("bench:light_volumes:water");
}

Scene windowScene(float roughness) {
  testing::SceneBuilder b;
  const int floor = b.material(testing::lambertian(glm::vec3(0.5f)));
  b.quad(glm::vec3(0.f), {2.f, 0, 0}, {0, 0, -2.f}, floor, "floor");
  b.gridY({0.f, 0.8f, 0.f}, 0.2f, 32, true, b.material(glass(roughness, 1.5f)), "window");
  b.pointLight({-0.3f, 1.6f, 0.f}, 4.f);
  b.topDownOrtho(0.6f, 0.8f);
  return b.build("bench:light_volumes:window:" + std::to_string(roughness));
}

long gSubdivisionBeams = -1;  // compare's light_volumes max_subdivision_beams; < 0: the schema's default

api::RenderRequest request(int width, int height, const std::string& traversal) {
  api::RenderRequest r;
  r.width = width;
  r.height = height;
  r.passes["light_volumes"] = {{"traversal", traversal}};
  if (gSubdivisionBeams >= 0) r.passes["light_volumes"]["max_subdivision_beams"] = gSubdivisionBeams;
  r.disabledPasses.insert("photon_gi");
  r.disabledPasses.insert("caustics");
  r.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"beauty", "light_volumes"}, false}};
  return r;
}

const api::PassStats& passOf(const RenderOutput& out, const std::string& name) {
  for (const auto& p : out.stats.passes)
    if (p.name == name) return p;
  throw std::runtime_error("missing pass " + name);
}

struct Timed {
  double gpuMs = 0.0, firstCpuMs = 0.0;
  Image image;
  double beams = 0.0, segments = 0.0, setupMs = 0.0, bvhMs = 0.0, fallbacks = 0.0, added = 0.0, exhausted = 0.0;
};

// The pass `pass` of `r` on `scene`: a first frame (which builds and caches the pass's derived data),
// then `frames` frames; the median of their GPU ms and the first of their images (AOV `aov`).
Timed timedPass(const Scene& scene, const api::RenderRequest& r, const std::string& pass, const std::string& aov,
                int frames) {
  Timed t;
  const RenderOutput first = renderer().render(scene, r);
  const auto& p0 = passOf(first, pass);
  t.firstCpuMs = p0.cpuMs;
  if (pass == "light_volumes") {
    t.setupMs = p0.counters.at("setup_ms");
    t.bvhMs = p0.counters.at("bvh_ms");
  }
  std::vector<double> ms;
  for (int k = 0; k < frames; ++k) {
    const RenderOutput out = renderer().render(scene, r);
    ms.push_back(passOf(out, pass).gpuMs);
    if (k == 0) {
      t.image = aovOf(out, aov);
      if (pass == "light_volumes") {
        t.beams = passOf(out, pass).counters.at("beams");
        t.segments = passOf(out, pass).counters.at("bvh_segments");
        t.fallbacks = passOf(out, pass).counters.at("tessellation_specular_fallbacks");
        t.added = passOf(out, pass).counters.at("subdivision_beams_added");
        t.exhausted = passOf(out, pass).counters.at("subdivision_budget_exhausted");
      }
    }
  }
  std::sort(ms.begin(), ms.end());
  t.gpuMs = ms[ms.size() / 2];
  return t;
}

Timed timed(const Scene& scene, int width, int height, const std::string& traversal, int frames) {
  return timedPass(scene, request(width, height, traversal), "light_volumes", "light_volumes", frames);
}

double relativeL1(const Image& a, const Image& b) {
  double d = 0.0, s = 0.0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i) {
    d += std::abs(double(a.pixels[i]) - b.pixels[i]);
    s += std::abs(double(b.pixels[i]));
  }
  return s > 0.0 ? d / s : 0.0;
}
double total(const Image& a) {
  double s = 0.0;
  for (float v : a.pixels) s += v;
  return s;
}

// The light tracer's image of the paths with exactly two scattering events, at the frame's camera.
Image lightTraced(const Scene& scene, int size, int pathsPerPixel, double& ms, std::uint64_t seed = 1) {
  const auto t0 = std::chrono::steady_clock::now();
  rt::RayScene rays(scene);
  reference::LightTracer lt(rays);
  reference::LightTracerOptions o;
  o.paths = reference::LightTracerOptions::Paths::All;
  o.minPathBounce = o.maxPathBounce = 2;
  o.pathsPerPixel = pathsPerPixel;
  o.seed = seed;
  Image img = lt.render(scene.camera, size, size, o);
  ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return img;
}

void timing(int width, int height, int maxLinear, int maxBvh, int frames, int minBeams) {
  const int grid[][2] = {{40, 1}, {80, 2}, {160, 4}, {320, 8}, {640, 16}, {1280, 32}};
  for (const auto& g : grid) {
    if (2 * g[0] * g[1] > maxBvh) break;
    if (2 * g[0] * g[1] < minBeams) continue;
    const Scene scene = ringScene(g[0], g[1]);
    const Timed bvh = timed(scene, width, height, "bvh", frames);
    std::printf("ring %dx%d beams=%.0f traversal=bvh gpu_ms=%.2f segments=%.0f setup_ms=%.1f bvh_ms=%.1f\n", width,
                height, bvh.beams, bvh.gpuMs, bvh.segments, bvh.setupMs, bvh.bvhMs);
    std::fflush(stdout);
    if (bvh.beams <= maxLinear) {
      const Timed lin = timed(scene, width, height, "linear", frames);
      std::printf("ring %dx%d beams=%.0f traversal=linear gpu_ms=%.2f relL1(bvh vs linear)=%.2e\n", width, height,
                  lin.beams, lin.gpuMs, relativeL1(bvh.image, lin.image));
      std::fflush(stdout);
    }
  }
}

// One scene of the comparison: every technique that applies against the light tracer.
void compare(const char* name, const Scene& scene, int size, int ltPaths, bool specular, bool othersToo) {
  double ltMs = 0.0, ms2 = 0.0;
  const Image ref = lightTraced(scene, size, ltPaths, ltMs);
  // The light tracer's own noise: the relative L1 between two seeds (their difference has sqrt(2) times
  // the noise of one, so one image's noise floor is this / sqrt(2)).
  const Image ref2 = lightTraced(scene, size, ltPaths, ms2, 2);
  std::printf("| %s | light tracer, %d paths/pixel | %.0f (CPU) | 0 | %.3f (noise floor) | 1 |\n", name, ltPaths, ltMs,
              relativeL1(ref2, ref) / std::sqrt(2.0));
  auto row = [&](const std::string& method, const Timed& t, const std::string& detail) {
    std::printf("| %s | %s | %.1f | %.0f | %.3f | %.3f |\n", name, (method + detail).c_str(), t.gpuMs, t.firstCpuMs,
                relativeL1(t.image, ref), total(t.image) / total(ref));
    std::fflush(stdout);
  };
  {
    const Timed lv = timed(scene, size, size, "bvh", 3);
    char d[160];
    std::snprintf(d, sizeof d, " (%.0f beams%s%s%s)", lv.beams,
                  lv.added > 0 ? (", " + std::to_string(long(lv.added)) + " by subdivision").c_str() : "",
                  lv.exhausted > 0 ? ", subdivision budget exhausted" : "", lv.fallbacks > 0 ? ", specular fallback" : "");
    row("light_volumes", lv, d);
  }
  if (!othersToo) return;
  if (specular) {
    for (int P : {64, 128, 256}) {
      api::RenderRequest r;
      r.width = r.height = size;
      r.disabledPasses = {"photon_gi", "light_volumes"};
      r.passes["caustics"] = {{"photon_resolution", P}};
      r.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"beauty", "caustics"}, false}};
      row("caustics", timedPass(scene, r, "caustics", "caustics", 3), " (triangles, P " + std::to_string(P) + ")");
      r.passes["caustics"] = {{"photon_resolution", P}, {"method", "splat"}};
      row("caustics", timedPass(scene, r, "caustics", "caustics", 3), " (splat, P " + std::to_string(P) + ")");
    }
  }
  if (specular) {
    // The photon tracer ends paths at Dirac-delta lobes: photon_gi has no L S D E light to splat.
    std::printf("| %s | photon_gi | - | - | - | 0 (ends photon paths at Dirac lobes) |\n", name);
    return;
  }
  auto photons = [&](int count, const std::string& method) {
    api::RenderRequest r;
    r.width = r.height = size;
    r.disabledPasses = {"caustics", "light_volumes"};
    r.passes["photon_gi"] = {{"photons", count}, {"max_bounces", 2}, {"method", method}};
    r.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"beauty", "indirect"}, false}};
    row("photon_gi", timedPass(scene, r, "photon_gi", "indirect", 3),
        " (" + method + ", " + std::to_string(count / 1000) + "k photons)");
  };
  for (int count : {50000, 250000, 1000000}) photons(count, "gather");
  photons(250000, "splat");
}

}  // namespace

int main(int argc, char** argv) {
  const std::string mode = argc > 1 ? argv[1] : "compare";
  auto arg = [&](int i, int fallback) { return argc > i ? std::atoi(argv[i]) : fallback; };
  std::printf("GL_RENDERER %s\n", renderer().device().renderer.c_str());
  if (mode == "timing") {
    timing(arg(2, 256), arg(3, 256), arg(4, 5120), arg(5, 81920), arg(6, 3), arg(7, 0));
    return 0;
  }
  if (mode != "compare") {
    std::fprintf(stderr, "usage: %s timing <w> <h> [max_linear] [max_bvh] [frames] [min_beams] | compare [size] [paths]\n", argv[0]);
    return 2;
  }
  const int size = arg(2, 128), paths = arg(3, 256);
  const std::string only = argc > 4 ? argv[4] : "";  // run only the scenes whose name starts with this
  auto wanted = [&](const char* name) { return std::string(name).rfind(only, 0) == 0; };
  const bool others = !(argc > 5 && std::string(argv[5]) == "light_volumes");  // the other techniques' rows too
  if (argc > 6) gSubdivisionBeams = std::atol(argv[6]);
  std::printf("%dx%d; ms = the pass's GPU ms, caches warm (median of 3); first-frame CPU ms includes building "
              "beams, photon images or photon maps\n\n",
              size, size);
  std::printf("| scene | method | ms | first-frame CPU ms | relL1 | energy |\n|---|---|---|---|---|---|\n");
  if (wanted("ring (80)")) compare("ring (80)", ringScene(40, 1), size, paths, true, others);
  if (wanted("ring (5120)")) compare("ring (5120)", ringScene(320, 8), size, paths, true, others);
  if (wanted("water")) compare("water", waterScene(), size, paths, true, others);
  for (float r : {0.1f, 0.2f, 0.3f, 0.4f}) {
    char name[48];
    std::snprintf(name, sizeof name, "window r %.1f", r);
    if (wanted(name)) compare(name, windowScene(r), size, paths, false, others);
  }
  if (wanted("plate")) compare("plate", plateScene(), size, paths, false, others);
  return 0;
}
