#pragma once
#include <vector>

#include "renderer/frame/Technique.h"

namespace radiant {

// glTF alphaMode BLEND (spec 3.9.4, "the rendered output is combined with the background using the
// normal painting operation, i.e. the Porter and Duff over operator"): the G-buffer leaves BLEND
// surfaces out, so every other pass lights what lies behind them; this pass then forward-shades them
// (emission, punctual lights with shadow maps, the environment's split-sum specular and SH diffuse)
// and composites them over `beauty`, sorted back to front by the view depth of each primitive's
// bounding-box centre, tested against the opaque depth buffer. docs/TECHNIQUES.md, "transparency".
class TransparencyPass final : public Technique {
public:
  const TechniqueInfo& info() const override;
  Requirements requirements(const Scene&, const api::RenderRequest&) const override;
  void prepare(const Scene&, const Params&, FrameResources&) override;
  void execute(PassContext&) override;

private:
  int pcfRadius_ = 1;
};

}  // namespace radiant
