#include "renderer/reference/LightTracer.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "renderer/raytracing/CameraRays.h"
#include "renderer/raytracing/Lights.h"
#include "renderer/raytracing/Particles.h"
#include "renderer/raytracing/RayScene.h"
#include "renderer/raytracing/Threads.h"

namespace radiant::reference {
namespace {

using namespace radiant::rt;

constexpr std::uint64_t kMinPathsPerBlock = 4096;
constexpr std::uint64_t kBlocksPerWave = 8;  // images in flight; summed in block order
constexpr std::uint64_t kCancelPollPaths = 256;  // light paths between two polls of the cancel flag: well under a ms
constexpr int kRussianRouletteStart = 3;

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

struct Tracer {
  const RayScene& rays;
  const SceneLights& lights;
  const CameraRays& camera;
  const LightTracerOptions& o;
  int width;

  bool inRange(int k) const { return k >= o.minPathBounce && k <= o.maxPathBounce; }

  // Adds beta f |wp.ns| |wc.ng| / |wp.ng| x importance to the pixel that sees the hit (header comment).
  void connect(const SurfaceHit& hit, const Shading& sh, const glm::vec3& wp, const glm::vec3& beta,
               const VolumeInterior& interior, std::vector<float>& image, Sampler& sampler, RayCounter& counter) const {
    CameraRays::Connection c;
    if (!camera.connect(hit.p, c)) return;
    const float gp = glm::dot(wp, sh.ngFacing), gc = glm::dot(c.toCamera, sh.ngFacing);
    const glm::vec3 wpL = sh.frame.toLocal(wp), wcL = sh.frame.toLocal(c.toCamera);
    // The camera direction must lie on the side of the geometric surface its lobe expects.
    if (wcL.z > 0.f ? gc <= 0.f : gc >= 0.f) return;
    if (!(std::abs(gp) > 0.f)) return;
    const glm::vec3 f = sh.bsdf.eval(wpL, wcL);
    if (!(maxComponent(f) > 0.f)) return;
    const glm::vec3 value = beta * f * interior.towards(rays, hit, c.toCamera).transmittance(c.distance) *
                            (std::abs(wpL.z) * std::abs(gc) / std::abs(gp) * c.importance);
    if (!finite(value)) return;
    Ray shadow{RayScene::offsetOrigin(hit.p, hit.ng, hit.offsetScale, c.toCamera), c.toCamera, 0.f, c.distance};
    if (shadow.tfar > 0.f && rays.occluded(shadow, sampler, counter)) return;
    float* px = &image[(static_cast<std::size_t>(c.y) * width + c.x) * 3];
    px[0] += value.x, px[1] += value.y, px[2] += value.z;
  }

  void trace(std::uint64_t index, std::vector<float>& image, RayCounter& counter) const {
    Sampler sampler(index, 0, o.seed ^ 0x6C6967687470617Bull);  // not the camera's or the photons' sequences
    Emission e;
    if (!lights.sampleLe(sampler, e)) return;
    glm::vec3 beta = e.flux;
    Ray ray = e.ray;
    const bool caustics = o.paths == LightTracerOptions::Paths::Caustics;
    int deltas = 0;  // delta scattering events so far (all of them, in the caustics class)
    VolumeInterior interior;  // KHR_materials_volume: the absorbing medium the particle travels in
    for (int k = 1; k <= o.maxBounces; ++k) {  // k = the bounce count if this hit is connected
      SurfaceHit hit;
      if (!rays.intersect(ray, hit, sampler, counter)) return;
      beta *= interior.transmittance(hit.distance);  // Beer-Lambert over the segment (VolumeInterior.h)
      if (k == 1 && e.windowRange > 0.f) beta *= rangeWindow(hit.distance, e.windowRange);
      if (!(maxComponent(beta) > 0.f) || !finite(beta)) return;
      if (rays.materialOf(hit.mesh).unlit) return;  // unlit surfaces do not scatter (as in the path tracer)
      const glm::vec3 wp = -ray.dir;
      const Shading sh = rays.shade(hit, wp, TransportMode::Importance);
      const glm::vec3 wpL = sh.frame.toLocal(wp);
      const bool classOk = caustics ? (deltas == k - 1 && k >= 2) : true;
      if (classOk && inRange(k) && sh.bsdf.hasNonDeltaLobe(wpL)) connect(hit, sh, wp, beta, interior, image, sampler, counter);
      if (k == o.maxBounces) {
        ++counter.capped;
        return;
      }
      const float uLobe = sampler.next(), uFresnel = sampler.next();
      const glm::vec2 uDir = sampler.next2();
      GltfBsdf::Sample s;
      if (!sh.bsdf.sample(wpL, uLobe, uFresnel, uDir, s)) return;
      if (caustics && !s.delta) return;  // no longer L S+ D: nothing later can be a caustic
      if (s.delta) ++deltas;
      // Adjoint BSDF with shading normals and roulette from the fourth event on, as the photon tracer.
      if (!continueParticle(rays, hit, sh, wp, wpL, s, o.russianRoulette && k >= kRussianRouletteStart, sampler, beta,
                            ray, interior))
        return;
    }
  }
};

}  // namespace

LightTracer::LightTracer(const rt::RayScene& rays) : rays_(rays) {}
LightTracer::~LightTracer() = default;

std::uint64_t LightTracer::raysTraced() const { return lastRays_; }
std::uint64_t LightTracer::pathsCapped() const { return lastCapped_; }

Image LightTracer::render(const Camera& camera, int width, int height, const LightTracerOptions& options) const {
  if (width <= 0 || height <= 0)
    throw std::invalid_argument("LightTracer::render(): image size " + std::to_string(width) + "x" +
                                std::to_string(height) + " is not positive");
  if (options.pathsPerPixel < 1) throw std::invalid_argument("LightTracer::render(): pathsPerPixel must be >= 1");
  if (options.maxBounces < 0) throw std::invalid_argument("LightTracer::render(): maxBounces must be >= 0");

  const SceneLights lights(rays_, options.environment, options.skyRadiance);
  const CameraRays cameraRays(camera, width, height);
  const Tracer tracer{rays_, lights, cameraRays, options, width};
  const std::size_t pixels = static_cast<std::size_t>(width) * height;
  const std::uint64_t paths = static_cast<std::uint64_t>(options.pathsPerPixel) * pixels;
  // A block's image is summed once per block, so a block traces at least half a path per pixel: the
  // sums then cost less than the paths. Depends on the image size only (determinism).
  const std::uint64_t pathsPerBlock = std::max<std::uint64_t>(kMinPathsPerBlock, pixels / 2);
  const std::uint64_t blocks = (paths + pathsPerBlock - 1) / pathsPerBlock;
  std::vector<double> sum(pixels * 3, 0.0);
  std::vector<std::vector<float>> wave(std::min(blocks, kBlocksPerWave));
  std::atomic<std::uint64_t> rayCount{0}, capped{0};

  auto run = [&] {
    for (std::uint64_t first = 0; first < blocks; first += kBlocksPerWave) {
      const std::uint64_t count = std::min(kBlocksPerWave, blocks - first);
      tbb::parallel_for(tbb::blocked_range<std::uint64_t>(0, count, 1), [&](const tbb::blocked_range<std::uint64_t>& r) {
        RayCounter counter;
        for (std::uint64_t b = r.begin(); b != r.end(); ++b) {
          std::vector<float>& image = wave[b];
          image.assign(pixels * 3, 0.f);
          const std::uint64_t lo = (first + b) * pathsPerBlock, hi = std::min(paths, lo + pathsPerBlock);
          for (std::uint64_t i = lo; i < hi; ++i) {
            if ((i - lo) % kCancelPollPaths == 0) options.cancel.check("the reference light tracer's paths");
            tracer.trace(i, image, counter);
          }
        }
        rayCount += counter.rays;
        capped += counter.capped;
      });
      for (std::uint64_t b = 0; b < count; ++b)  // block order: independent of the thread count
        for (std::size_t i = 0; i < sum.size(); ++i) sum[i] += wave[b][i];
      if (options.progress) options.progress(static_cast<double>(first + count) / static_cast<double>(blocks));
    }
  };
  rt::withThreads(options.threads, run);
  Image image = Image::make("beauty", width, height, 3);
  const double scale = 1.0 / static_cast<double>(paths);
  for (std::size_t i = 0; i < sum.size(); ++i) image.pixels[i] = static_cast<float>(sum[i] * scale);
  lastRays_ = rayCount.load();
  lastCapped_ = capped.load();
  return image;
}

bool sceneHasDeltaLobes(const Scene& scene) {
  for (const MeshInstance& m : scene.meshes) {
    const Material& mat = scene.material(m.material);
    if (!mat.unlit && mat.roughnessFactor <= 0.f) return true;
  }
  return false;
}

}  // namespace radiant::reference
