#pragma once
// The photon splat grid that photon_gi publishes for other passes (its internal output "photon_grid"):
// the GPU splat array and its uniform grid (photon_gi's resources "photon_gi_splats" and
// "photon_gi_cells", layouts in shaders/photon_gi/photon.glsl and gather.comp), uploaded in photon_gi's
// prepare() so that passes that execute before photon_gi (specular's distance maps) can gather from the
// same photons with the same kernel and surface test (shaders/photon_gi/photon.glsl).
//
// Publishing (photon_gi, prepare): upload, then publishPhotonGrid(). Reading (a pass that declares
// "photon_grid" as an optional input, in execute): publishedPhotonGrid() returns the grid, or nullptr
// when photon_gi is not planned this frame (the frame's blackboard, FrameResources::product). The grid's `digest` names the photon set and splat
// settings it holds (photon_gi's splat cache key plus the kernel): derived data shaded from the photons
// keys on it.
#include <cstdint>
#include <memory>
#include <string>

#include <glm/glm.hpp>

#include "renderer/frame/FrameResources.h"
#include "renderer/gl/Gl.h"

namespace radiant {

// Shared by photon_gi's gather/splat and every reader of the grid (the surface test of photon.glsl).
constexpr GLuint kPhotonSplatBinding = 5, kPhotonCellBinding = 6;
// A surface point must lie within this fraction of h of the photon's plane (a curved surface deviates
// from its tangent plane by r^2 / 2R) and its geometric normal within acos(0.7) = 45.6 degrees of the
// photon's (creases between walls are 90).
constexpr float kPhotonPlaneTolerance = 0.25f;
constexpr float kPhotonNormalCosine = 0.7f;
// Renormalised estimates divide by the kernel mass on their surface, at least this much (a right-angled
// corner has 1/4; thin features much less, where dividing would only amplify noise).
constexpr float kPhotonMinKernelMass = 0.2f;
// Candidates per cell and dispatch of a gather: 27 cells x 2000 = 54000 loop iterations per invocation,
// under llvmpipe's loop limit of 65535 per invocation (docs/DEVELOPMENT.md).
constexpr std::uint32_t kPhotonGatherSlice = 2000;

struct PhotonGrid {
  std::string digest;  // the photon set and splat settings (photon_gi's splat cache key) and the kernel
  std::size_t count = 0;  // splats (photons and coverage points) in the buffers
  glm::vec3 origin{0.f};
  float cellSize = 1.f;
  float walkReach = 1e30f;  // neighbour cells farther than this from the point are skipped (grid.glsl)
  glm::ivec3 dims{1};
  std::uint32_t maxPerCell = 0;
  int kernel = 0;            // photon.glsl KERNEL_*
  float minRadius = 0.f;     // the smallest splat radius h (photon_gi's h_min): readers' surface tests
  bool renormalize = true;   // divide by the coverage points' kernel mass
  gl::Buffer* splats = nullptr;  // photon_gi's splat and cell buffers, which hold the grid this frame
  gl::Buffer* cells = nullptr;
  // Binds the splat and cell buffers (kPhotonSplatBinding, kPhotonCellBinding).
  void bind() const {
    splats->bindBase(GL_SHADER_STORAGE_BUFFER, kPhotonSplatBinding);
    cells->bindBase(GL_SHADER_STORAGE_BUFFER, kPhotonCellBinding);
  }
};

// photon_gi: the buffers hold `grid` now (after its upload); publishes it on the frame's blackboard
// under its output "photon_grid" (FrameResources::publish), which marks it written.
inline void publishPhotonGrid(FrameResources& res, const PhotonGrid& grid) { res.publish("photon_grid", grid); }

// The grid photon_gi published this frame, or nullptr when it is not planned.
inline const PhotonGrid* publishedPhotonGrid(FrameResources& res) { return res.product<PhotonGrid>("photon_grid"); }

}  // namespace radiant
