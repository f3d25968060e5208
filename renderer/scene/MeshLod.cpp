#include "renderer/scene/MeshLod.h"

#include <algorithm>

#include <meshoptimizer.h>

namespace radiant {

std::vector<MeshLodLevel> buildMeshLods(const MeshInstance& mesh, float baseError, int levels, float factor,
                                        std::size_t minTriangles) {
  std::vector<MeshLodLevel> out;
  if (mesh.triangleCount() < minTriangles || mesh.positions.empty() || !(baseError > 0.f)) return out;
  const float* positions = &mesh.positions[0].x;
  const std::size_t vertexCount = mesh.positions.size();
  // meshopt_simplify takes errors relative to the mesh's extent.
  const float scale = meshopt_simplifyScale(positions, vertexCount, sizeof(glm::vec3));
  if (!(scale > 0.f)) return out;
  out.reserve(std::max(levels, 0));  // `previous` points into it
  const std::vector<std::uint32_t>* previous = &mesh.indices;
  float bound = baseError;
  for (int level = 0; level < levels; ++level, bound *= factor) {
    MeshLodLevel l;
    l.indices.resize(previous->size());
    // Simplifying the previous level: its distance to the full surface and this step's add up, so the
    // step may move the surface by what the level's bound leaves. meshopt's quadric error estimates the
    // distance but does not bound it (a UV sphere's levels went up to 19% past their target:
    // MeshLod.EveryLevelStaysWithinItsBoundOfTheFullSurface), so each step asks for half its share.
    const float step = 0.5f * (bound - (out.empty() ? 0.f : out.back().error));
    const std::size_t count = meshopt_simplify(l.indices.data(), previous->data(), previous->size(), positions,
                                               vertexCount, sizeof(glm::vec3), 0, step / scale, 0, nullptr);
    if (count == 0 || count * 4 > previous->size() * 3) {
      if (out.empty() && level + 1 < levels) continue;  // the finest bound gained nothing: try the next
      break;
    }
    l.indices.resize(count);
    l.indices.shrink_to_fit();
    l.error = bound;
    out.push_back(std::move(l));
    previous = &out.back().indices;
  }
  return out;
}

float lodBaseError(const Bounds& sceneBounds) {
  return 0.25f * 2.f * std::max(sceneBounds.radius(), 1e-30f) / 4096.f;
}

}  // namespace radiant
