#pragma once
// Photon GI: photon tracing on the CPU (renderer/raytracing/PhotonTracer.h) and view-dependent
// splatting on the GPU (Stürzlinger & Bastos 1997, optimised mode §2.2.1): the indirect light of every
// visible diffuse and glossy surface, written to the `indirect` AOV and added to beauty. Direct light
// from punctual lights stays with the raster `direct` pass (shadow maps); photons that reached their
// surface straight from a punctual light or the sky are not splatted. Direct light from emissive
// triangles, which no raster pass computes, is splatted (its photons have bounce 0).
//
// Derived data, each cached by exactly its inputs (stats.cache):
//   photon_gi_photons  records, by scene, lights, environment, seed and max_bounces (not the camera,
//                      not the photon count: more photons extend the set, fewer use a prefix);
//   photon_gi_splats   the GPU array of splats (photons with their kernel radius, plus the coverage
//                      points of the edge renormalisation), by the photon set, count, C, schedule.
#include <cstdint>
#include <string>
#include <vector>

#include "renderer/frame/Technique.h"
#include "renderer/shading/Denoiser.h"
#include "renderer/techniques/photon_gi/Splatting.h"

namespace radiant {

class PhotonGiPass final : public Technique {
public:
  const TechniqueInfo& info() const override;
  Requirements requirements(const Scene&, const api::RenderRequest&) const override;
  void prepare(const Scene&, const Params&, FrameResources&) override;
  void execute(PassContext&) override;

  // The kernel radius of eq. 3, h = C sqrt(A / n), for a surface of area A holding n splatted photons,
  // and its progressive variant (h^2 scaled by (N / N0)^alpha for N photons in total, Knaus & Zwicker
  // 2011: the radius shrinks more slowly than the paper's, so the photons per kernel grow as N^alpha).
  static float kernelRadius(float C, double area, double n, bool ppm, double photons, double ppmBasePhotons,
                            double ppmAlpha);

private:
  struct Settings {
    std::uint64_t photons = 0;
    float C = 10.f;
    bool ppm = false;
    double ppmAlpha = 2.0 / 3.0, ppmBase = 250000;
    int maxBounces = 8;
    float environmentLightPhotons = 0.5f;
  } settings_;
  photon_gi::SplatSettings splat_;
  photon_gi::SplatGrid* grid_ = nullptr;  // in the cache, valid for this frame
  bool upload_ = false;                          // the grid changed: upload it in execute()
  // The splat set (its cache key) this frame uses. The splat buffers hold one set at a time
  // (FrameResources::refill), so a cached set of another scene or setting is uploaded again (and rebuilt:
  // the CPU copy is released after upload).
  std::string splatDigest_;
  bool rebuilt_ = false;            // this frame rebuilt a cached set that was not resident
  bool recordsReleased_ = false;    // this frame released the records after building the grid (memory)
  float lightPhotonWeight_ = 1.f;  // the environment lights' weight in the sky photons' emission
  std::size_t records_ = 0, photonSplats_ = 0, coveragePoints_ = 0;
  std::size_t splatBufferBytes_ = 0;  // the splat buffer's size (at most 12.5% over the grid's)
  std::uint64_t traced_ = 0;  // photons traced by this frame (0 when the set was cached)
  std::uint64_t capped_ = 0;  // photons of the cached set ended by max_bounces (PhotonSet::capped)
  bool denoise_ = true;
  denoise::Settings denoiseSettings_;
  double traceMs_ = 0.0, buildMs_ = 0.0;
  float hMin_ = 0.f, hMax_ = 0.f;
};

}  // namespace radiant
