// light_volumes (issue 15): GPU time of the gathering against the beam count for the linear traversal
// (the paper's loop over every beam) and the culled one (BVH over the beams' cones), and the error
// against the reference light tracer.
//   build/bench/light_volumes_bench [size=256] [max_linear_beams=5120] [lt_paths_per_pixel=64] [error]
// ("error": only the error runs).
// Scenes (a Lambertian floor, albedo 0.5, seen from above by an orthographic camera):
//   ring   the paper's cardioid (Fig. 2): a half ring of mirror (radius 0.5 m, 0.2 m tall, roughness
//          0, R = 0.9) lit by a point light over its open side; facets x rows x 2 triangles from 40 x 1
//          (80 beams) to 1280 x 32 (81920 beams).
//   plate  a glossy plate (0.6 m, roughness 0.3, 24 x 24 x 2) 1.2 m above the floor, lit from below.
// Output, one line per run:
//   ring beams=<B> traversal=<linear|bvh> gpu_ms=<ms, the pass's GPU time, beams cached, median of 3>
//   equal-image check: relative L1 of bvh against linear at the same beam count
//   error: relative L1 and energy ratio of the light_volumes AOV against the light tracer's image of
//   the paths with exactly two scattering events (L S D E, L G D E: the only ones in these scenes that
//   end on the floor with two events), and the light tracer's time.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "renderer/Renderer.h"
#include "renderer/raytracing/RayScene.h"
#include "renderer/reference/LightTracer.h"
#include "tests/support/SceneBuilder.h"

namespace {

using namespace radiant;

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
  b.quad(glm::vec3(0.f), {1.5f, 0, 0}, {0, 0, -1.5f}, floor, "floor");
  b.gridY({0.f, 1.2f, 0.f}, 0.3f, 24, false, b.material(metal(0.3f, 0.9f)), "plate");
  // A spot light pointing up at the plate: the floor gets no direct light, only what the plate sends.
  b.spotLight({-0.5f, 0.6f, 0.f}, {0.45f, 1.f, 0.f}, 2.f, 0.5f, 0.7f);
  b.topDownOrtho(1.f, 1.f);
  return b.build("bench:light_volumes:plate");
}

api::RenderRequest request(int size, const std::string& traversal) {
  api::RenderRequest r;
  r.width = r.height = size;
  r.passes["light_volumes"] = {{"traversal", traversal}};
  r.disabledPasses.insert("photon_gi");
  r.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"beauty", "light_volumes"}, false}};
  return r;
}

const Image& aovOf(const RenderOutput& out, const std::string& name) {
  for (const auto& a : out.aovs)
    if (a.aov == name) return a;
  throw std::runtime_error("missing aov " + name);
}
const api::PassStats& passOf(const RenderOutput& out, const std::string& name) {
  for (const auto& p : out.stats.passes)
    if (p.name == name) return p;
  throw std::runtime_error("missing pass " + name);
}

struct Timed {
  double gpuMs = 0.0;
  Image image;
  double beams = 0.0, segments = 0.0, setupMs = 0.0, bvhMs = 0.0;
};

Timed timed(const Scene& scene, int size, const std::string& traversal) {
  Timed t;
  const RenderOutput first = renderer().render(scene, request(size, traversal));  // builds and caches the beams
  const auto& p0 = passOf(first, "light_volumes");
  t.setupMs = p0.counters.at("setup_ms");
  t.bvhMs = p0.counters.at("bvh_ms");
  std::vector<double> ms;
  for (int k = 0; k < 3; ++k) {
    const RenderOutput out = renderer().render(scene, request(size, traversal));
    ms.push_back(passOf(out, "light_volumes").gpuMs);
    if (k == 0) {
      t.image = aovOf(out, "light_volumes");
      t.beams = passOf(out, "light_volumes").counters.at("beams");
      t.segments = passOf(out, "light_volumes").counters.at("bvh_segments");
    }
  }
  std::sort(ms.begin(), ms.end());
  t.gpuMs = ms[1];
  return t;
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

void error(const char* name, const Scene& scene, int size, int ltPaths) {
  const Timed lv = timed(scene, size, "bvh");
  double ltMs = 0.0;
  const Image ref = lightTraced(scene, size, ltPaths, ltMs);
  // The light tracer's own noise: the relative L1 between two seeds (their difference has sqrt(2) times
  // the noise of one, so one image's noise floor is this / sqrt(2)).
  double ms2 = 0.0;
  const Image ref2 = lightTraced(scene, size, ltPaths, ms2, 2);
  std::printf("%s error: beams=%.0f gpu_ms=%.2f relL1=%.4f energy=%.4f (light tracer %d paths/pixel, %.0f ms; "
              "its noise floor relL1=%.4f)\n",
              name, lv.beams, lv.gpuMs, relativeL1(lv.image, ref), total(lv.image) / total(ref), ltPaths, ltMs,
              relativeL1(ref2, ref) / std::sqrt(2.0));
}

}  // namespace

int main(int argc, char** argv) {
  const int size = argc > 1 ? std::atoi(argv[1]) : 256;
  const int maxLinear = argc > 2 ? std::atoi(argv[2]) : 5120;
  const int ltPaths = argc > 3 ? std::atoi(argv[3]) : 64;
  std::printf("GL_RENDERER %s, %dx%d\n", renderer().device().renderer.c_str(), size, size);
  const bool timing = !(argc > 4 && std::string(argv[4]) == "error");
  const int grid[][2] = {{40, 1}, {80, 2}, {160, 4}, {320, 8}, {640, 16}, {1280, 32}};
  for (const auto& g : grid) {
    if (!timing) break;
    const Scene scene = ringScene(g[0], g[1]);
    const Timed bvh = timed(scene, size, "bvh");
    std::printf("ring beams=%.0f traversal=bvh gpu_ms=%.2f segments=%.0f setup_ms=%.1f bvh_ms=%.1f\n", bvh.beams,
                bvh.gpuMs, bvh.segments, bvh.setupMs, bvh.bvhMs);
    if (bvh.beams <= maxLinear) {
      const Timed lin = timed(scene, size, "linear");
      std::printf("ring beams=%.0f traversal=linear gpu_ms=%.2f relL1(bvh vs linear)=%.2e\n", lin.beams, lin.gpuMs,
                  relativeL1(bvh.image, lin.image));
    }
    std::fflush(stdout);
  }
  error("ring", ringScene(40, 1), size, ltPaths);
  error("ring", ringScene(320, 8), size, ltPaths);
  error("plate", plateScene(), size, ltPaths);
  return 0;
}
