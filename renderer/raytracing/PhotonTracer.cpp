#include "renderer/raytracing/PhotonTracer.h"

#include "renderer/raytracing/Particles.h"
#include "renderer/raytracing/Threads.h"

#include <algorithm>
#include <atomic>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace radiant::rt {
namespace {

constexpr std::uint64_t kBlock = 1024;  // photons per work item; records are concatenated in block order
constexpr std::uint64_t kCancelPollPhotons = 64;  // a millisecond or less of tracing
constexpr std::uint64_t kWaveBlocks = 256;        // 262,144 photons traced between two appends to the set

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

void tracePhoton(const RayScene& rays, const SceneLights& lights, const PhotonOptions& o, std::uint64_t index,
                 std::vector<PhotonRecord>& out, RayCounter& counter) {
  // "photons": not the camera's sequences. Low-discrepancy over the emission and the first bounce
  // (Sampler.h, kLowDiscrepancyDims): the photons' first indirect hits cover the scene evenly instead of
  // clumping as independent samples do.
  Sampler sampler = Sampler::lowDiscrepancy(index, o.seed ^ 0x70686F746F6E73ull);
  Emission e;
  if (!lights.sampleLe(sampler, e)) return;
  glm::vec3 flux = e.flux;
  const bool deltaStartsCaustic = lights.emitters()[e.light].kind == SceneLights::Kind::Punctual;
  Ray ray = e.ray;
  const int lastBounce = o.maxBounces - 1;
  bool narrowLobePath = true;  // every scattering so far off a metal or glass by a non-diffuse lobe
  bool specularChain = true;  // every scattering vertex so far on a Material::isSpecular() surface
  bool scatteredNonDelta = false;  // some earlier vertex scattered through a non-delta lobe
  VolumeInterior interior;  // KHR_materials_volume: the absorbing medium the photon travels in
  for (int bounce = 0; bounce <= lastBounce; ++bounce) {
    SurfaceHit hit;
    if (!rays.intersect(ray, hit, sampler, counter)) return;
    flux *= interior.transmittance(hit.distance);  // Beer-Lambert over the segment (VolumeInterior.h)
    if (bounce == 0 && e.windowRange > 0.f) flux *= rangeWindow(hit.distance, e.windowRange);
    if (!(maxComponent(flux) > 0.f) || !finite(flux)) return;
    if (rays.materialOf(hit.mesh).unlit) return;  // KHR_materials_unlit absorbs (the reference ends paths there)
    const glm::vec3 wo = -ray.dir;  // towards where the photon came from
    const Shading sh = rays.shade(hit, wo, TransportMode::Importance);
    const glm::vec3 woL = sh.frame.toLocal(wo);
    if (sh.bsdf.hasNonDeltaLobe(woL)) {
      PhotonRecord r;
      r.position = hit.p;
      r.mesh = hit.mesh;
      r.normalOct = octEncode(sh.ngFacing);
      r.photon = static_cast<std::uint32_t>(index);
      r.wiOct = octEncode(wo);
      r.bounce = static_cast<std::uint16_t>(bounce);
      r.flags = static_cast<std::uint16_t>((bounce >= 1 && specularChain ? kPhotonSpecularChain : 0) |
                                           (bounce >= 1 && narrowLobePath ? kPhotonNarrowLobePath : 0));
      r.flux = flux;
      r.light = static_cast<std::uint32_t>(e.light);
      out.push_back(r);
    }
    if (bounce == lastBounce) {
      ++counter.capped;
      return;
    }
    specularChain = specularChain && rays.materialOf(hit.mesh).isSpecular();
    const float uLobe = sampler.next(), uFresnel = sampler.next();
    const glm::vec2 uDir = sampler.next2();
    GltfBsdf::Sample s;
    if (!sh.bsdf.sample(woL, uLobe, uFresnel, uDir, s)) return;
    // A delta scattering ends only a path that has had no other and that left a punctual light: L S+ D
    // from point, spot and directional lights is the caustics pass's class. After a diffuse or glossy
    // vertex the photon crosses glass and mirrors (L D S+ D: a lit ceiling seen through a glass sphere by
    // the floor), as the reference path tracer's paths do; so does light from the sky and from emissive
    // triangles, which the caustics pass has no photons for (the sky through a thin glass wall onto
    // what it encloses: TransmissionTest's striped spheres, issue 29 item 5).
    if (s.delta && !scatteredNonDelta && deltaStartsCaustic) return;
    scatteredNonDelta = scatteredNonDelta || !s.delta;
    narrowLobePath = narrowLobePath && (s.flags & (kLobeGlossy | kLobeSpecular)) != 0 &&
                     rays.materialOf(hit.mesh).scattersNarrowLobe();
    if (!continueParticle(rays, hit, sh, wo, woL, s, o.russianRoulette, sampler, flux, ray, interior)) return;
  }
}

}  // namespace

std::uint32_t octEncode(const glm::vec3& v, int bits) {
  const float l1 = std::abs(v.x) + std::abs(v.y) + std::abs(v.z);
  if (!(l1 > 0.f) || !std::isfinite(l1)) return octEncode(glm::vec3(0.f, 0.f, 1.f), bits);
  glm::vec2 p = glm::vec2(v.x, v.y) / l1;
  if (v.z < 0.f) {  // the lower hemisphere folds over the diagonals
    const glm::vec2 folded = (1.f - glm::abs(glm::vec2(p.y, p.x)));
    p = glm::vec2(p.x >= 0.f ? folded.x : -folded.x, p.y >= 0.f ? folded.y : -folded.y);
  }
  const float scale = static_cast<float>((1 << (bits - 1)) - 1);
  const std::uint32_t mask = (1u << bits) - 1u;
  auto snorm = [&](float x) {
    return static_cast<std::uint32_t>(static_cast<std::int32_t>(std::lround(std::clamp(x, -1.f, 1.f) * scale))) & mask;
  };
  return snorm(p.x) | (snorm(p.y) << bits);
}

glm::vec3 octDecode(std::uint32_t packed, int bits) {
  const float scale = static_cast<float>((1 << (bits - 1)) - 1);
  auto coordinate = [&](std::uint32_t field) {  // sign-extended from `bits` bits (two's complement, C++20)
    const int v = static_cast<std::int32_t>(field << (32 - bits)) >> (32 - bits);
    return std::clamp(static_cast<float>(v) / scale, -1.f, 1.f);
  };
  const std::uint32_t mask = (1u << bits) - 1u;
  const glm::vec2 p(coordinate(packed & mask), coordinate((packed >> bits) & mask));
  glm::vec3 v(p.x, p.y, 1.f - std::abs(p.x) - std::abs(p.y));
  if (v.z < 0.f) {
    const glm::vec2 unfolded = 1.f - glm::abs(glm::vec2(v.y, v.x));
    v.x = p.x >= 0.f ? unfolded.x : -unfolded.x;
    v.y = p.y >= 0.f ? unfolded.y : -unfolded.y;
  }
  return glm::normalize(v);
}

std::size_t PhotonSet::recordsOfFirst(std::uint64_t n) const {
  if (n >= emitted) return records.size();
  return static_cast<std::size_t>(
      std::lower_bound(records.begin(), records.end(), n,
                       [](const PhotonRecord& r, std::uint64_t v) { return r.photon < v; }) -
      records.begin());
}

void tracePhotons(const RayScene& rays, const SceneLights& lights, const PhotonOptions& options,
                  std::uint64_t count, PhotonSet& set) {
  if (count <= set.emitted) return;
  const std::uint64_t begin = set.emitted;
  const std::uint64_t blocks = (count - begin + kBlock - 1) / kBlock;
  const std::size_t original = set.records.size();
  std::atomic<std::uint64_t> rayCount{0}, capped{0};
  try {
    // In waves of kWaveBlocks blocks, each appended in block order once traced and then freed: the
    // records are held once, not twice (every block's, then the joined set: 4M photons' 351 MiB of
    // records were 700 MiB at that moment, issue 30). The set is reserved for the whole trace at the
    // first wave's records per photon (+10%), so the records are moved at most once more.
    for (std::uint64_t w0 = 0; w0 < blocks; w0 += kWaveBlocks) {
      const std::uint64_t w1 = std::min(blocks, w0 + kWaveBlocks);
      std::vector<std::vector<PhotonRecord>> perBlock(w1 - w0);
      auto run = [&] {
        tbb::parallel_for(tbb::blocked_range<std::uint64_t>(w0, w1, 1), [&](const tbb::blocked_range<std::uint64_t>& r) {
          RayCounter counter;
          for (std::uint64_t b = r.begin(); b != r.end(); ++b) {
            const std::uint64_t lo = begin + b * kBlock, hi = std::min(count, lo + kBlock);
            auto& out = perBlock[b - w0];
            out.reserve((hi - lo) * 2);
            for (std::uint64_t i = lo; i < hi; ++i) {
              if ((i - lo) % kCancelPollPhotons == 0) options.cancel.check("photon tracing");
              tracePhoton(rays, lights, options, i, out, counter);
            }
          }
          rayCount += counter.rays;
          capped += counter.capped;
        });
      };
      rt::withThreads(options.threads, run);
      std::size_t added = 0;
      for (const auto& v : perBlock) added += v.size();
      if (set.records.size() + added > set.records.capacity()) {
        const std::uint64_t traced = std::min(count, begin + w1 * kBlock) - begin;
        const double perPhoton = double(set.records.size() - original + added) / double(traced);
        const std::size_t rest = static_cast<std::size_t>(1.1 * perPhoton * double(count - begin - traced));
        set.records.reserve(set.records.size() + added + rest);
      }
      for (auto& v : perBlock) {
        set.records.insert(set.records.end(), v.begin(), v.end());
        std::vector<PhotonRecord>().swap(v);
      }
    }
  } catch (...) {
    set.records.resize(original);  // a cancelled trace leaves the set as it was
    throw;
  }
  set.emitted = count;
  set.rays += rayCount.load();
  set.capped += capped.load();
}

}  // namespace radiant::rt
