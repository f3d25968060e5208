#pragma once
// Hierarchical depth impostors (thesis ch. 8, Algorithm 6): self-shadowed single scattering for large
// particle clouds. Particles are grouped into blocks (spatial clusters, Blocks.h); every block gets a
// depth impostor for the view and for the shadowed light (front depth MIN, back depth MAX,
// transmittance multiplied, one pass); the blocks' light impostors are accumulated into K light
// slices, 4 per RGBA texture, by commutative multiplicative blending (no sorting); and the blocks are
// gathered back to front, their opacity scaled where the scene depth lies inside the block, the
// light's transmittance interpolated between the enclosing slices (Impostors.h, shaders/depth_impostors).
// `light_transmittance: fourier` replaces the slices by Fourier opacity maps (Jansen and Bavoil 2010,
// Blocks.h): the same light impostors and block pass, 2M + 1 coefficients in the slice textures.
//
// Owns the media AOV when the request names it (TechniqueInfo::exclusive, claimsWhenNamed), otherwise
// spherical_billboards does. The first punctual light of the scene is shadowed by the slices, the
// others and the sky are not (the sky adds albedo * ambient per block). Ground truth: the volumetric
// reference's single_scatter mode. Blocks and impostors are cached by the medium and parameters, the
// impostors also by the camera and the light.
#include <cstddef>
#include <vector>

#include "api/Media.h"
#include "renderer/frame/Technique.h"
#include "renderer/gl/Gl.h"
#include "renderer/techniques/depth_impostors/Impostors.h"

namespace radiant {

class DepthImpostorsPass final : public Technique {
public:
  const TechniqueInfo& info() const override;
  Requirements requirements(const Scene&, const api::RenderRequest&) const override;
  GroundTruth groundTruth(const Params& params, const std::string& aov) const override;
  // The impostor atlas's limit (impostors::atlasLayout: 2048 texels a side, tiles of at least 4) for
  // the frame's particles at particles_per_block, counted without building the blocks (blockCount): a
  // 422 before the queue (Renderer::check); prepare() checks the blocks it built with the same rule.
  void validate(const Scene& scene, const FrameView& view, const Params& params) const override;
  void prepare(const Scene&, const Params&, FrameResources&) override;
  void execute(PassContext&) override;

  // How many blocks impostors::buildBlocks makes of the frame's particles: ceil(n / b) for each
  // system's n particles with optical depth (mediaParticles' rule).
  static std::size_t blockCount(const std::vector<api::ParticleSystem>& media, int particlesPerBlock);
  // The atlas of `blocks` tiles at `requestedRes`, or the 422 when they do not fit even at the smallest tile.
  static impostors::AtlasLayout fittedAtlas(std::size_t blocks, int requestedRes);

private:
  impostors::ImpostorSet* set_ = nullptr;  // cached in FrameResources
  impostors::ImpostorAxis viewAxis_, lightAxis_;
  impostors::SliceFrame frame_;
  bool hasLight_ = false;
  std::vector<int> order_;  // blocks back to front
  gl::VertexArray vao_;
  int clipScaling_ = 1, forwardScatter_ = 0, particlesPerBlock_ = 0, requestedRes_ = 0;
  int fourierTerms_ = 0;  // 0: slices
};

}  // namespace radiant
