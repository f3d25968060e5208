#pragma once
#include <set>
#include <string>
#include <vector>

#include "renderer/frame/FrameResources.h"
#include "renderer/frame/GpuTypes.h"
#include "renderer/frame/Technique.h"
#include "renderer/raytracing/Cancel.h"
#include "renderer/shading/CubeFaces.h"

namespace radiant {

// Shadow maps for every punctual light: a cube map (6 x 90 degree faces) per point light, a
// perspective 2D map per spot light (cone plus margin) and an orthographic 2D map per directional
// light fitted to the scene bounds. Maps store the light's distance measure in R32F; the direct
// pass filters them with PCF (see shaders/direct/direct.frag for the bias model). MASK texels below
// the cutoff cast nothing, BLEND surfaces a dithered coverage alpha (shaders/shadow_maps/shadow.frag).
// The maps depend only on the scene geometry, its lights and the map size, so they are cached under
// that digest: a request that changes the camera or another pass's knobs reuses them.
//
// Their cost is the fragments they rasterise: the map's area times its overdraw, which layered
// geometry makes unbounded (16,667 stacked triangles: 2.7 billion fragments in a default frame's 17
// maps, 4.7 s on llvmpipe). prepare() estimates the overdraw from the triangles (mapCoverage, once per
// change of geometry, lights and exclusions) and, when the request leaves shadow_map_size to the
// default, draws maps small enough to stay within kFragmentBudget (with a warning); a size the request
// gives runs as asked up to kFragmentLimit, and is refused above it: before the job is queued when the
// scene's own lights exceed it (validate), else when the frame adds the environment's (prepare).
// Opaque materials are drawn by a shader variant that cannot discard, so that the depth test runs
// before it (shadow.frag).
class ShadowMapsPass final : public Technique {
public:
  const TechniqueInfo& info() const override;
  Requirements requirements(const Scene&, const api::RenderRequest&) const override;
  void validate(const Scene&, const FrameView&, const Params&) const override;
  void prepare(const Scene&, const Params&, FrameResources&) override;
  void execute(PassContext&) override;

  // World -> light clip transforms for one face / map; exposed for tests.
  static glm::mat4 cubeFaceViewProj(const glm::vec3& lightPos, int face, float znear) {
    return radiant::cubeFaceViewProj(lightPos, face, znear);  // renderer/shading/CubeFaces.h
  }

  static constexpr double kMaxBytes = 1024.0 * 1024.0 * 1024.0;  // every map of a frame together (1 GiB)
  // Estimated fragments of every map of a frame together: the default size is lowered to stay within
  // kFragmentBudget (about 0.5 s on llvmpipe here, milliseconds on a GPU; the shared samples and
  // built-in scenes need 2-20 million), a given size above kFragmentLimit (about 7 s here) is refused.
  static constexpr double kFragmentBudget = 256.0 * 1024.0 * 1024.0;
  static constexpr double kFragmentLimit = 16.0 * kFragmentBudget;
  static constexpr int kMinAutoSize = 64;  // the smallest map the budget chooses (the schema's minimum is a user's)

  // Each light's maps' rasterised area in units of one map's area (a map of size s rasterises about
  // coverage * s^2 fragments; a point light's six faces together), from every triangle of the meshes
  // not excluded: a directional light's orthographic map (fitted to the scene's bounding sphere)
  // covers the triangles' projected area, a spot or point light's maps their solid angle (each
  // triangle's at most 2 pi) in texels per steradian at the map's centre (spot) or on average (cube).
  static std::vector<double> mapCoverage(const Scene& scene, const std::vector<Light>& lights,
                                         const std::set<int>& excluded, const rt::Cancel& cancel = {});
  // The size the default draws at: `size` halved until coverage * size^2 is within the budget, no
  // smaller than kMinAutoSize.
  static int sizeWithinBudget(int size, double coverage);
  // The 422s (limit-exceeded at shadow_map_size): maps of size^2 with this coverage (summed over
  // `lights` lights) above kFragmentLimit; `cubes` point-light cubes and `maps2d` 2D maps above kMaxBytes.
  static void checkFragments(int size, double coverage, std::size_t lights);
  static void checkBytes(int size, int cubes, int maps2d);

private:
  FrameResources::Refill maps_;  // hit: the maps hold this frame's; else execute() renders them
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
  std::string coverageKey_;  // what coverage_ was estimated for: geometry, lights and exclusions
  double coverage_ = 0.0;    // every map's coverage summed (mapCoverage)
  double estimateMs_ = 0.0;  // what this frame's prepare() spent on mapCoverage
  std::string warning_;      // for stats.warnings when the budget lowered the default size
};

}  // namespace radiant
