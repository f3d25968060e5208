#pragma once
// The GPU half of photon GI, separate from where the photons come from so that tests can feed it
// photons of their own: a splat array (photons with their kernel radius, and the coverage points of
// the edge renormalisation), sorted into a uniform grid, turned into the `indirect` AOV either by
// splatting (Stürzlinger & Bastos §2.2: one quad per photon, additive blending) or by a per-pixel
// gather over the grid (the baseline of the issue: same photons, same kernel, same surface test,
// so the two differ only by float rounding).
#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "renderer/frame/FrameResources.h"
#include "renderer/frame/FrameView.h"
#include "renderer/gl/ShaderLibrary.h"
#include "renderer/scene/Scene.h"

namespace radiant::photon_gi {

// std430 mirror of GpuPhoton in shaders/photon_gi/photon.glsl.
// 48 bytes (std430: a vec3 and a uint share 16). The direction is octahedral-encoded with 15 bits per
// coordinate (within 2e-4 radians, tested; the BSDF it is evaluated with has roughness >= 0.2): 4M
// photons' grid is 78 MiB smaller on the CPU and again in its buffer than with a vec4, and the gather
// reads a quarter less per candidate (issue 30).
struct GpuSplat {
  glm::vec4 positionRadius;  // xyz world position, w kernel radius h
  glm::vec3 normal;          // unit normal on the side the photon arrived from
  std::uint32_t wiFlags;     // splatDirectionBits: wi (bits 0-29), kSplatDiffuseOnly, kSplatCopy
  glm::vec4 power;           // rgb phi = flux / photons used; a > 0: coverage point of weight A / n
};
static_assert(sizeof(GpuSplat) == 48, "std430 GpuSplat is vec4, vec3 + uint, vec4");
inline constexpr std::uint32_t kSplatDiffuseOnly = 1u << 30;  // splatted with the diffuse lobe only
inline constexpr std::uint32_t kSplatCopy = 1u << 31;         // a copy in another cell (buildSplatGrid)
// wi in bits 0-29 of wiFlags (two 15-bit signed coordinates of the octahedral map), and back.
std::uint32_t splatDirectionBits(const glm::vec3& wi);
glm::vec3 splatDirection(const GpuSplat& s);

// diffuseOnly: the photon is splatted with the diffuse lobe of the BRDF only (its glossy reflection is
// another technique's light path).
inline GpuSplat photonSplat(const glm::vec3& p, float h, const glm::vec3& n, const glm::vec3& wi, const glm::vec3& phi,
                            bool diffuseOnly = false) {
  return {glm::vec4(p, h), n, splatDirectionBits(wi) | (diffuseOnly ? kSplatDiffuseOnly : 0u), glm::vec4(phi, 0.f)};
}

// Appends n coverage points spread uniformly by area over `mesh` (stratified in the area CDF, R2
// low-discrepancy inside each triangle), each of weight area / n and kernel radius h.
void appendCoveragePoints(const MeshInstance& mesh, std::size_t n, float h, std::vector<GpuSplat>& out);
double meshArea(const MeshInstance& mesh);

enum class Method { Splat, Gather };
enum class Kernel { Biweight = 0, Epanechnikov = 1 };

struct SplatSettings {
  Method method = Method::Splat;
  Kernel kernel = Kernel::Biweight;
  bool renormalize = true;
  float minGlossyRoughness = 0.2f;
  // Gather only: one gather per gatherStep x gatherStep pixel block, spread to the block's pixels on
  // the same surface by shaders/photon_gi/upsample.comp (the others get a full-resolution gather).
  int gatherStep = 1;
};

// The splats sorted by grid cell, and the grid (cell c holds splats cellStart[c] .. cellStart[c+1]-1).
struct SplatGrid {
  std::vector<GpuSplat> splats;  // may be released once uploaded (count stays)
  std::size_t count = 0;         // entries in the grid: the splats and their copies (buildSplatGrid)
  std::size_t originals = 0;     // the splats (entries whose wi.w is 0)
  std::vector<std::uint32_t> cellStart;
  glm::vec3 origin{0.f};
  float cellSize = 1.f;
  glm::ivec3 dims{1};
  std::uint32_t maxPerCell = 0;  // the fullest cell's splats (the gather's dispatch count follows it)
  float hMin = 0.f;              // the smallest kernel radius
  // How far outside its cell any splat stored in a cell reaches (its distance to the cell's box plus h
  // sqrt(1 + tolerance^2)): the walk skips neighbour cells farther than this from the point (grid.glsl).
  // Infinite when the grid holds copies, whose cell is not their splat's.
  float walkReach = 0.f;
};
// A gather visits the 27 cells around a pixel. Cells are the reach h sqrt(1 + planeTolerance^2) of the
// largest kernel, or of a smaller percentile one when that walks fewer candidates with the wider
// splats' copies (stored every third cell across their reach, so that a walk meets each splat once;
// at most 3 x the splats and 2^20); at most 128 per axis.
SplatGrid buildSplatGrid(std::vector<GpuSplat> splats);

// Declares the splat buffers (at most 12.5% over the grid's size; over twice it, a buffer is reallocated
// only when `replacing`, i.e. the grid is uploaded next), the accumulation targets and `indirect`.
void declareSplatResources(FrameResources& res, const SplatGrid& grid, const SplatSettings& settings,
                           bool replacing);
// Uploads `grid` into the splat buffers (its CPU splats must still be there).
void uploadSplatGrid(FrameResources& res, const SplatGrid& grid);
// Uploads `grid` when `upload` (else the buffers hold it already), accumulates into the target and
// resolves into `indirect`, adding it to `beauty` when addToBeauty. Reads the G-buffer resources.
void splatAndResolve(FrameResources& res, gl::ShaderLibrary& shaders, const FrameView& view,
                     const SplatSettings& settings, const SplatGrid& grid, bool upload, bool addToBeauty);
// indirect = accum's radiance (divided by its kernel mass in alpha when renormalize), added to beauty
// when addToBeauty. The last step of splatAndResolve; photon_gi calls it again on the denoised indirect.
void resolve(FrameResources& res, gl::ShaderLibrary& shaders, const FrameView& view, const gl::Texture& accum,
             bool renormalize, bool addToBeauty);

}  // namespace radiant::photon_gi
