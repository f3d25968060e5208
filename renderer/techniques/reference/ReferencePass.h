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

// Reference image of `aov` ("beauty", "direct", "indirect", "caustics", "ao", "reference", "media",
// "media_transmittance") for the frame's view. For "ao", aoDefinition is "volumetric" (thesis eq. 4.6)
// or "cosine" (cosine-weighted step). The media AOVs come from the volumetric reference
// (renderer/reference/VolumeTracer.h) over the frame's particle systems (FrameView::media).
// Caustics: when the scene has a material with a Dirac-delta lobe, "beauty" and "indirect" are the path
// tracer without the caustic paths L S+ D E plus the light tracer's caustics (renderer/reference/
// LightTracer.h), so that a point light's caustic through glass is in the ground truth, counted once;
// "caustics" is the light tracer's caustics alone. `caustics = false` keeps the path tracer alone.
struct ReferenceRequest {
  std::string aov = "beauty";
  int spp = 64;
  int lightPathsPerPixel = 0;  // light tracer paths per pixel; 0 = spp
  bool caustics = true;
  int maxBounces = rt::kDefaultMaxBounces;
  bool russianRoulette = true;
  float aoRadius = 0.5f;
  std::string aoDefinition = "cosine";
  // aov "media" / "media_transmittance": the volumetric reference's light transport.
  std::string mediaMode = "single_scatter_unshadowed";
};
// The reference pass's parameters (its schema, defaults filled in) as a ReferenceRequest.
ReferenceRequest referenceRequestFrom(const Params& params);
// What rendering (or finding) a reference image did.
struct ReferenceRun {
  bool cacheHit = false;
  std::uint64_t rays = 0;         // traced by this call (0 when cached)
  std::uint64_t pathsCapped = 0;  // paths max_bounces ended while alive (0 when cached)
  bool lightTraced = false;       // the light tracer added the caustic paths L S+ D E
};
const Image& referenceImage(FrameResources& resources, const Scene& scene, const FrameView& view,
                            const ReferenceRequest& request, ReferenceRun* run = nullptr,
                            const std::function<void(double)>& progress = {});

class ReferencePass final : public Technique {
public:
  const TechniqueInfo& info() const override;
  // The reference AOV's ground truth is the reference itself in the same mode (aov, bounce range,
  // caustics, AO definition, media mode) at the compare block's spp and with its own seed
  // (renderer/Renderer.cpp, compare()): `compare: {"aov": "reference", "spp": 1024}` scores a 64-spp
  // reference pass against an independent 1024-spp one.
  GroundTruth groundTruth(const Params& params, const std::string& aov) const override;
  Requirements requirements(const Scene&, const api::RenderRequest&) const override;
  void prepare(const Scene&, const Params&, FrameResources&) override;
  void execute(PassContext&) override;
private:
  ReferenceRequest request_;
};

}  // namespace radiant
