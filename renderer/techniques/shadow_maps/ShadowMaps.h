#pragma once
#include <set>
#include <string>
#include <vector>

#include "renderer/frame/GpuTypes.h"
#include "renderer/frame/Technique.h"
#include "renderer/shading/CubeFaces.h"

namespace radiant {

// Shadow maps for every punctual light: a cube map (6 x 90 degree faces) per point light, a
// perspective 2D map per spot light (cone plus margin) and an orthographic 2D map per directional
// light fitted to the scene bounds. Maps store the light's distance measure in R32F; the direct
// pass filters them with PCF (see shaders/direct/direct.frag for the bias model). MASK texels below
// the cutoff cast nothing, BLEND surfaces a dithered coverage alpha (shaders/shadow_maps/shadow.frag).
// The maps depend only on the scene geometry, its lights and the map size, so they are cached under
// that digest: a request that changes the camera or another pass's knobs reuses them.
class ShadowMapsPass final : public Technique {
public:
  const TechniqueInfo& info() const override;
  Requirements requirements(const Scene&, const api::RenderRequest&) const override;
  void prepare(const Scene&, const Params&, FrameResources&) override;
  void execute(PassContext&) override;

  // World -> light clip transforms for one face / map; exposed for tests.
  static glm::mat4 cubeFaceViewProj(const glm::vec3& lightPos, int face, float znear) {
    return radiant::cubeFaceViewProj(lightPos, face, znear);  // renderer/shading/CubeFaces.h
  }

  static constexpr double kMaxBytes = 1024.0 * 1024.0 * 1024.0;  // every map of a frame together (1 GiB)

private:
  bool mapsValid_ = false;
  std::string digest_;  // what the maps hold once execute() rendered them (FrameResources::holds)
  int size_ = 1024;
  std::vector<gpu::ShadowInfo> infos_;
  struct Draw {
    int light;
    int layer;  // layer-face in the cube array or layer in the 2D array
    bool cube;
    glm::mat4 viewProj;
  };
  std::vector<Draw> draws_;
  std::set<int> excluded_;  // meshes left out of the maps this frame
};

}  // namespace radiant
