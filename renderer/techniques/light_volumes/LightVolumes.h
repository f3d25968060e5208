#pragma once
// Glossy light volumes (Duvenhage, Bouatouch, Kourie): backward polygon beam tracing of LS+DE and
// LG+DE light, first order (one S or G vertex) from punctual lights. Beam set-up on the CPU
// (Beams.h), a BVH over the beams' bounding cones (BeamBvh.h) for the culled traversal, and the
// per-fragment gathering in a compute shader (shaders/light_volumes/gather.comp), written to the
// `light_volumes` AOV and added to beauty.
//
// Derived data, cached by exactly its inputs (stats.cache):
//   light_volumes_beams  beams, cones and BVH, by scene, lights and the parameters that shape them
//                        (sigma_scale, shadows, max_concentration, max_triangle_sigma,
//                        tessellation_fallback, cull_sigmas, max_subdivision_beams); never by the
//                        camera, split or traversal.
#include <string>

#include "renderer/frame/FrameResources.h"
#include "renderer/frame/Technique.h"
#include "renderer/techniques/light_volumes/BeamBvh.h"
#include "renderer/techniques/light_volumes/Beams.h"

namespace radiant {

class LightVolumesPass final : public Technique {
public:
  const TechniqueInfo& info() const override;
  Requirements requirements(const Scene&, const api::RenderRequest&) const override;
  void prepare(const Scene&, const Params&, FrameResources&) override;
  void execute(PassContext&) override;
  std::vector<int> shadowMapExclusions(const Scene&, const Params&) const override;
  void addCostCounts(const Scene& scene, api::SceneCounts& counts) const override;

  struct Cache {
    light_volumes::BeamSet beams;
    light_volumes::BeamBvh bvh;
    double setupMs = 0.0, bvhMs = 0.0;
  };

private:
  const Cache* cache_ = nullptr;  // in FrameResources' cache, valid for this frame
  bool built_ = false, bvh_ = true;
  int beautyClasses_ = 3;  // which of its beams join beauty (execute; gather.comp u_beautyClasses)
  FrameResources::Refill uploaded_;  // hit: the beam buffers hold this frame's beams; else execute() uploads them
  light_volumes::Split split_ = light_volumes::Split::TwoD;
};

}  // namespace radiant
