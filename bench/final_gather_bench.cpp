// A final gather over photon_gi's photons, measured against the reference (issue 32: "compare the
// denoiser with the best simple alternatives (more photons, final gather)"). A CPU experiment on the
// ray-tracing core, not a pass: it answers whether a final gather would lower the built-in Cornell
// box's indirect error at the default frame's cost before anyone builds one on the GPU.
//
// The estimator (Jensen 1996, "Global illumination using photon maps", with Christensen's 1999
// precomputed irradiance estimates): the indirect radiance at the surface x a pixel sees is
//   L_ind(x, wo) = 1/N sum_i f(wo, wi) cos / pdf * L_r(y_i, -wi),
// wi drawn from x's BSDF, y_i the surface the ray meets, and L_r(y) = f_y(-wi, n_y) E(y) the light y
// reflects (exact for a Lambertian y), E(y) the photons' irradiance: photon_gi's biweight density
// estimate over *all* the records (those straight from the emitters too, which are direct light at y),
// with photon_gi's kernel radius per surface h = C_fg sqrt(A / n) (eq. 3 of Stürzlinger & Bastos), taken
// at every `stride`-th record once and looked up at the nearest one on y's plane. Emitters hit by a
// gather ray add nothing (that is direct light at x, the `direct` pass's).
//
//   build/bench/final_gather_bench [--size 128] [--photons 250000] [--rays 64] [--C 20] [--stride 4]
//                                  [--seed 1] [--truth-spp 1024] [--frame indirect.exr]
//
// Prints the gather's time per stage and the indirect image's RMSE (RGB, over pixels and channels)
// against the mean of two reference renders of bounces [2, inf) (seeds 99 and 98, cached in /tmp), and
// the truth's own noise; --frame scores a daemon frame's `indirect` AOV against the same truth.
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <unordered_map>
#include <vector>

#include "renderer/io/ImageIO.h"
#include "renderer/raytracing/CameraRays.h"
#include "renderer/raytracing/Lights.h"
#include "renderer/raytracing/PhotonTracer.h"
#include "renderer/raytracing/RayScene.h"
#include "renderer/reference/PathTracer.h"
#include "renderer/scene/BuiltinScenes.h"
#include "renderer/techniques/photon_gi/Splatting.h"

namespace {

using namespace radiant;
using io::readImage;
using io::writeFile;
using io::encodeExr;
using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

// A uniform hash grid of points: cells of `cell` world units.
struct PointGrid {
  float cell = 1.f;
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> cells;
  static std::uint64_t key(int x, int y, int z) {
    return (std::uint64_t(std::uint32_t(x) & 0x1FFFFF) << 42) | (std::uint64_t(std::uint32_t(y) & 0x1FFFFF) << 21) |
           std::uint64_t(std::uint32_t(z) & 0x1FFFFF);
  }
  glm::ivec3 cellOf(const glm::vec3& p) const { return glm::ivec3(glm::floor(p / cell)); }
  void insert(const glm::vec3& p, std::uint32_t i) {
    const glm::ivec3 c = cellOf(p);
    cells[key(c.x, c.y, c.z)].push_back(i);
  }
  template <class F>
  void around(const glm::vec3& p, F&& f) const {
    const glm::ivec3 c = cellOf(p);
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          auto it = cells.find(key(c.x + dx, c.y + dy, c.z + dz));
          if (it == cells.end()) continue;
          for (std::uint32_t i : it->second) f(i);
        }
  }
};

double rmse(const Image& a, const Image& b) {
  double s = 0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i) s += double(a.pixels[i] - b.pixels[i]) * (a.pixels[i] - b.pixels[i]);
  return std::sqrt(s / a.pixels.size());
}

Image truthImage(const Scene& scene, const Camera& cam, int size, int spp, std::uint64_t seed) {
  const std::string path = "/tmp/fg_truth_" + std::to_string(size) + "_" + std::to_string(spp) + "_" +
                           std::to_string(seed) + ".exr";
  if (std::filesystem::exists(path)) return readImage(path);
  reference::PathTracer pt(scene);
  reference::ReferenceOptions o;
  o.spp = spp;
  o.seed = seed;
  o.minPathBounce = 2;
  Image img = pt.render(cam, size, size, o);
  img.aov = "beauty";
  writeFile(path, encodeExr({img}, false));
  return img;
}

}  // namespace

int main(int argc, char** argv) {
  int size = 128, rays = 64, stride = 4, truthSpp = 1024;
  std::uint64_t photons = 250000, seed = 1;
  float C = 20.f;
  std::string framePath;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i], v = argv[i + 1];
    if (a == "--size") size = std::stoi(v);
    else if (a == "--photons") photons = std::stoull(v);
    else if (a == "--rays") rays = std::stoi(v);
    else if (a == "--C") C = std::stof(v);
    else if (a == "--stride") stride = std::stoi(v);
    else if (a == "--seed") seed = std::stoull(v);
    else if (a == "--truth-spp") truthSpp = std::stoi(v);
    else if (a == "--frame") framePath = v;
    else { std::fprintf(stderr, "unknown option %s\n", a.c_str()); return 2; }
  }
  const Scene scene = loadBuiltinScene("cornell_box");
  Camera cam = scene.camera;
  cam.aspectRatio = 1.f;
  const Image t1 = truthImage(scene, cam, size, truthSpp, 99), t2 = truthImage(scene, cam, size, truthSpp, 98);
  Image truth = t1;
  for (std::size_t i = 0; i < truth.pixels.size(); ++i) truth.pixels[i] = 0.5f * (t1.pixels[i] + t2.pixels[i]);
  const double truthNoise = 0.5 * rmse(t1, t2);  // of the mean of two: sigma / sqrt(2), sigma = rmse / sqrt(2)
  std::printf("truth: %d spp x 2, own noise %.4f\n", truthSpp, truthNoise);
  if (!framePath.empty()) {
    const Image f = readImage(framePath, "indirect");
    const double e = rmse(f, truth);
    std::printf("frame %s: indirect RMSE %.4f (own %.4f)\n", framePath.c_str(), e,
                std::sqrt(std::max(0.0, e * e - truthNoise * truthNoise)));
  }

  const auto t0 = Clock::now();
  rt::RayScene rs(scene);
  const rt::SceneLights lights(rs, nullptr, glm::vec3(0.f));
  rt::PhotonSet set;
  rt::PhotonOptions po;
  po.seed = seed;
  rt::tracePhotons(rs, lights, po, photons, set);
  const double traceMs = msSince(t0);

  // Kernel radius per surface (eq. 3) over every record.
  const auto t1s = Clock::now();
  std::vector<double> count(scene.meshes.size(), 0.0);
  for (const auto& r : set.records) count[r.mesh] += 1.0;
  std::vector<float> h(scene.meshes.size(), 0.f);
  float hMax = 0.f;
  for (std::size_t m = 0; m < scene.meshes.size(); ++m) {
    if (count[m] <= 0) continue;
    h[m] = static_cast<float>(C * std::sqrt(photon_gi::meshArea(scene.meshes[m]) / count[m]));
    hMax = std::max(hMax, h[m]);
  }
  PointGrid records;
  records.cell = hMax;
  std::vector<glm::vec3> normals(set.records.size());
  for (std::uint32_t i = 0; i < set.records.size(); ++i) {
    records.insert(set.records[i].position, i);
    normals[i] = set.records[i].normal();
  }
  // Irradiance at every stride-th record (biweight kernel on the record's plane).
  struct Estimate {
    glm::vec3 p, n, E;
    int mesh;
  };
  std::vector<Estimate> est;
  for (std::size_t i = 0; i < set.records.size(); i += stride)
    est.push_back({set.records[i].position, normals[i], glm::vec3(0.f), set.records[i].mesh});
  const float invM = 1.f / float(photons);
  tbb::parallel_for(std::size_t(0), est.size(), [&](std::size_t e) {
    Estimate& q = est[e];
    const float hh = h[q.mesh];
    glm::vec3 E(0.f);
    records.around(q.p, [&](std::uint32_t j) {
      const auto& r = set.records[j];
      const glm::vec3 d = r.position - q.p;
      const float r2 = glm::dot(d, d) / (hh * hh);
      if (r2 >= 1.f || std::abs(glm::dot(d, q.n)) > 0.25f * hh || glm::dot(normals[j], q.n) < 0.9f) return;
      const float k = 3.f / rt::kPi * (1.f - r2) * (1.f - r2);
      E += r.flux * (invM * k / (hh * hh));
    });
    q.E = E;
  });
  PointGrid estimates;
  estimates.cell = hMax;
  for (std::uint32_t i = 0; i < est.size(); ++i) estimates.insert(est[i].p, i);
  const double precomputeMs = msSince(t1s);

  // The gather.
  const auto t2s = Clock::now();
  rt::CameraRays camRays(cam, size, size);
  Image out = Image::make("indirect", size, size, 3);
  std::vector<std::uint64_t> misses(size, 0), rayCount(size, 0);
  const int sub = 4;  // primary samples a pixel (2 x 2 strata), rays / sub gather rays each
  const int perSub = std::max(1, rays / sub);
  tbb::parallel_for(0, size, [&](int y) {
    rt::RayCounter counter;
    for (int x = 0; x < size; ++x) {
      glm::vec3 sum(0.f);
      for (int s = 0; s < sub; ++s) {
        rt::Sampler sampler(std::uint64_t(y) * size + x, s, seed ^ 0x9E3779B97F4A7C15ull);
        const float jx = (float(s % 2) + sampler.next()) * 0.5f, jy = (float(s / 2) + sampler.next()) * 0.5f;
        rt::Ray ray = camRays.ray(x + jx, y + jy);
        rt::SurfaceHit hit;
        if (!rs.intersect(ray, hit, sampler, counter)) continue;
        const glm::vec3 wo = -glm::normalize(ray.dir);
        const rt::Shading sh = rs.shade(hit, wo);
        const glm::vec3 woL = sh.frame.toLocal(wo);
        for (int g = 0; g < perSub; ++g) {
          rt::GltfBsdf::Sample smp;
          const float u0 = sampler.next(), u1 = sampler.next(), u2 = sampler.next(), u3 = sampler.next();
          if (!sh.bsdf.sample(woL, u0, u1, glm::vec2(u2, u3), smp) || smp.delta) continue;
          const glm::vec3 wi = sh.frame.toWorld(smp.wi);
          rt::Ray gr;
          gr.org = rt::RayScene::offsetOrigin(hit.p, sh.ngFacing, hit.offsetScale, wi);
          gr.dir = wi;
          rt::SurfaceHit yh;
          ++rayCount[y];
          if (!rs.intersect(gr, yh, sampler, counter)) continue;
          // The nearest estimate on y's plane.
          const glm::vec3 ny = glm::dot(yh.ng, wi) < 0.f ? yh.ng : -yh.ng;
          float best = 1e30f;
          int bi = -1;
          const float hy = h[yh.mesh] > 0.f ? h[yh.mesh] : hMax;
          estimates.around(yh.p, [&](std::uint32_t j) {
            const Estimate& q = est[j];
            if (q.mesh != yh.mesh || glm::dot(q.n, ny) < 0.9f) return;
            const glm::vec3 d = q.p - yh.p;
            const float d2 = glm::dot(d, d);
            if (d2 < best && d2 < hy * hy) best = d2, bi = int(j);
          });
          if (bi < 0) { ++misses[y]; continue; }
          const rt::Shading shy = rs.shade(yh, -wi);
          const glm::vec3 fy = shy.bsdf.eval(shy.frame.toLocal(-wi), glm::vec3(0.f, 0.f, 1.f));
          sum += smp.weight * fy * est[bi].E;
        }
      }
      const glm::vec3 v = sum / float(sub * perSub);
      float* o = out.at(x, y);
      o[0] = v.x, o[1] = v.y, o[2] = v.z;
    }
  });
  const double gatherMs = msSince(t2s);
  std::uint64_t m = 0, rc = 0;
  for (int y = 0; y < size; ++y) m += misses[y], rc += rayCount[y];
  const double e = rmse(out, truth);
  std::printf("photons %llu (%zu records, %zu estimates), C %.0f, rays %d: trace %.0f ms, estimates %.0f ms, "
              "gather %.0f ms (%llu rays, %.2f%% without an estimate)\n",
              (unsigned long long)photons, set.records.size(), est.size(), C, sub * perSub, traceMs, precomputeMs,
              gatherMs, (unsigned long long)rc, 100.0 * double(m) / double(std::max<std::uint64_t>(rc, 1)));
  std::printf("final gather: indirect RMSE %.4f (own %.4f)\n", e,
              std::sqrt(std::max(0.0, e * e - truthNoise * truthNoise)));
  double mo = 0, mt = 0;
  for (std::size_t i = 0; i < out.pixels.size(); ++i) mo += out.pixels[i], mt += truth.pixels[i];
  std::printf("mean: gather %.5f truth %.5f (ratio %.4f)\n", mo / out.pixels.size(), mt / out.pixels.size(), mo / mt);
  writeFile("/tmp/fg_out.exr", encodeExr({out}, false));
  return 0;
}
