#pragma once
#include "renderer/Image.h"
#include "renderer/frame/Technique.h"

namespace radiant {

// Direct lighting: every punctual light through the glTF BRDF (shaders/common/brdf.glsl) with
// PCF-filtered shadow maps, plus emission, plus the uniform sky where no surface is. Writes `direct`
// and initialises `beauty`.
class DirectPass final : public Technique {
public:
  const TechniqueInfo& info() const override;
  Requirements requirements(const Scene&, const api::RenderRequest&) const override;
  void prepare(const Scene&, const Params&, FrameResources&) override;
  void execute(PassContext&) override;
private:
  int pcfRadius_ = 1;
  bool imageBasedLighting_ = true;
};

}  // namespace radiant
