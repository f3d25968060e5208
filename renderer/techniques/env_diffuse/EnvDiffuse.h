#pragma once
// Robust diffuse environment mapping (thesis ch. 3; docs/TECHNIQUES.md "env_diffuse").
// Per receiver: a cube map of radiance and distance from its reference point with the receiver left
// out, box-filtered to M x M faces; every low-resolution texel becomes a quadrilateral area light and
// each visible receiver fragment gathers them with the polygon-to-point form factor (eq. 3.3,
// Algorithm 1), or with the point-to-point (VPL) or classic pre-convolved baselines.
// The cube maps are derived data, cached per receiver under the digest of the scene, its lights, the
// sky, the receiver, its reference point and the cube parameters.
#include <string>
#include <vector>

#include "renderer/frame/FrameResources.h"
#include "renderer/frame/Technique.h"
#include "renderer/techniques/env_diffuse/Receivers.h"

namespace radiant {

class EnvDiffusePass final : public Technique {
public:
  enum Method : int { kPolygon = 0, kPoint = 1, kClassic = 2 };  // matches ENV_METHOD_* in gather.glsl

  const TechniqueInfo& info() const override;
  Requirements requirements(const Scene&, const api::RenderRequest&) const override;
  void validate(const Scene& scene, const FrameView& view, const Params& params) const override;
  void prepare(const Scene&, const Params&, FrameResources&) override;
  void execute(PassContext&) override;
  // indirect_diffuse: the reference's indirect (two or more scattering events) up to 1 + bounces, the
  // paths the cube maps hold.
  GroundTruth groundTruth(const Params& params, const std::string& aov) const override;

  // Size of the cube map the classic method convolves, and of its irradiance map.
  static constexpr int kConvolutionSourceSize = 32;
  static constexpr int kIrradianceSize = 16;

private:
  struct ReceiverState {
    env_diffuse::Receiver receiver;
    std::string prefix;  // resource name prefix
    FrameResources::Refill maps;  // hit: its maps hold this frame's; else execute() renders them
  };
  void buildCubeMaps(PassContext& ctx, const ReceiverState& r);

  std::vector<ReceiverState> receivers_;
  int cubeResolution_ = 128;
  int downsample_ = 4;
  int bounces_ = 1;
  Method method_ = kPolygon;
  glm::vec3 skyRadiance_{0.f};  // what sky texels hold: the ambient radiance with include_sky, else 0
  bool horizonClip_ = true;
};

}  // namespace radiant
