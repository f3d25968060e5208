#pragma once
// The CPU reference path tracer (renderer/reference/) as a pass, and the cached ground truth that the
// `compare` block scores frames against. The BVH is built once per scene; each reference image is
// cached under the digest of exactly what shapes it (scene, camera, size, samples, bounce range, sky,
// AO definition and radius), so a sweep over a GPU technique's knobs renders the ground truth once.
#include <string>

#include "renderer/Image.h"
#include "renderer/frame/FrameView.h"
#include "renderer/frame/Technique.h"
#include "renderer/reference/PathTracer.h"

namespace radiant {

// Reference image of `aov` ("beauty", "direct", "indirect", "ao", "reference", "media",
// "media_transmittance") for the frame's view. The media AOVs come from the volumetric reference
// (renderer/reference/VolumeTracer.h) over the frame's particle systems (FrameView::media).
// For "ao", aoDefinition is "volumetric" (thesis eq. 4.6) or "cosine" (cosine-weighted step).
struct ReferenceRequest {
  std::string aov = "beauty";
  int spp = 64;
  int maxBounces = 8;
  bool russianRoulette = true;
  float aoRadius = 0.5f;
  std::string aoDefinition = "cosine";
  // aov "media" / "media_transmittance": the volumetric reference's light transport.
  std::string mediaMode = "single_scatter_unshadowed";
};
const Image& referenceImage(FrameResources& resources, const Scene& scene, const FrameView& view,
                            const ReferenceRequest& request, bool* cacheHit = nullptr,
                            std::uint64_t* rays = nullptr);

class ReferencePass final : public Technique {
public:
  const TechniqueInfo& info() const override;
  Requirements requirements(const Scene&, const api::RenderRequest&) const override;
  void prepare(const Scene&, const Params&, FrameResources&) override;
  void execute(PassContext&) override;
private:
  ReferenceRequest request_;
};

}  // namespace radiant
