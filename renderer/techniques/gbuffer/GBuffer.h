#pragma once
#include "renderer/frame/Technique.h"

namespace radiant {

// Rasterises the scene once: reversed-Z float depth plus world position, shading normal, albedo,
// material (metallic, roughness, occlusion, transmission), emission and geometric normal.
class GBufferPass final : public Technique {
public:
  const TechniqueInfo& info() const override;
  Requirements requirements(const Scene&, const api::RenderRequest&) const override;
  void prepare(const Scene&, const Params&, FrameResources&) override;
  void execute(PassContext&) override;
};

}  // namespace radiant
