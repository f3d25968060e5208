#pragma once
// Illumination networks (thesis ch. 9, Algorithm 7): multiple scattering in a static particle medium
// under directional lights, a uniform sky and emission. N nodes sampled from the frame's media in
// proportion to their extinction carry the incoming radiance of D shared directions; the visibility
// network V (N x D: upstream node and link opacity) is built on the GPU by per-direction binning in
// an M x M window and cached with the nodes by medium digest and the parameters that shape it; each
// request iterates eq. 9.1 `iterations` times from 0, resuming from the cached radiance when that is
// an earlier request's state under the same sources and at most as many iterations (warm_start), so a
// frame never depends on earlier requests (the thesis' §9.2 start from the previous lights' solution
// would make it so; not done). The final image (final_render) marches
// each pixel's ray through the medium's own particles with the lights (and, when affordable, the sky)
// scattered once exactly and the rest interpolated from the nodes (march.frag), or splats every node
// as a spherical billboard carrying its share of the optical mass (the thesis; the spherical_billboards
// shaders).
//
// Writes the `media` AOV (premultiplied radiance, transmittance in media_transmittance) and, when it
// owns the "media" light path, composes beauty = beauty * T + media. Ground truth: the volumetric
// reference's `full` mode. CPU side and oracles: Network.h; GPU: NetworkGpu.h.
#include <memory>
#include <string>
#include <vector>

#include "renderer/frame/GpuTypes.h"
#include "renderer/frame/Technique.h"
#include "renderer/gl/Gl.h"
#include "renderer/techniques/illumination_network/Network.h"
#include "renderer/techniques/illumination_network/NetworkGpu.h"

namespace radiant {

class IlluminationNetworkPass final : public Technique {
public:
  const TechniqueInfo& info() const override;
  GroundTruth groundTruth(const Params&, const std::string& aov) const override;
  Requirements requirements(const Scene&, const api::RenderRequest&) const override;
  void validate(const Scene& scene, const FrameView& view, const Params& params) const override;
  void prepare(const Scene&, const Params&, FrameResources&) override;
  void execute(PassContext&) override;

  // The window M for "window": 0 (auto). A column through the centre of the bounding sphere holds
  // about 4N / (pi M^2) nodes, so its links are 2R pi M^2 / (4N) long while a bin is 2R / M wide;
  // M = round((4N / pi)^(1/3)) makes the two equal (cubic cells: M = 11 for N = 1024, and 11 nodes per
  // central column), far below the thesis' upper bound, where most links see the sky (notes §4
  // "Occupancy"). At least 1.
  static int autoWindow(int nodes);

  struct Network;  // the cached derived data (nodes, directions, GPU network)

private:
  void reportStats(PassContext& ctx, bool build, const std::vector<double>& residuals) const;
  Network* net_ = nullptr;
  bool march_ = true, skyExact_ = true, linearSource_ = true, exactLinks_ = false;
  int marchSteps_ = 64, marchStretch_ = 64, marchDraws_ = 0;
  long long loopBudget_ = 0;   // network::shaderLoopBudget of this context's GL_RENDERER (0: not read yet)
  long long piecesLoops_ = 0;  // loop iterations of one piece of the march (network::marchPieceLoops)
  bool marchFallback_ = false;
  float kernel_ = 0.f;  // the march's Gaussian width (world units)
  std::vector<gpu::MediaParticle> particles_;  // the medium's own particles, for the march
  bool fresh_ = false, warm_ = false;
  int iterations_ = 0, resumedFrom_ = 0, iterationsRun_ = 0;
  std::string stateKey_;  // the sources of this request's iteration (sourcesKey)
  std::vector<network::DirectionalLight> lights_;
  std::vector<double> transmittance_;
  int ignoredLights_ = 0;
  std::vector<gpu::MediaParticle> splats_;
  std::vector<int> order_;
  gl::VertexArray vao_;
};

}  // namespace radiant
