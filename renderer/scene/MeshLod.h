#pragma once
// Coarser index lists over a mesh's own vertices, for the passes that draw the whole scene many times
// into texels far coarser than the screen's: the shadow maps (one per light, sky lights included) and
// the specular pass's layered distance maps (6 faces x layers per object). On MetalRoughSpheres (98
// spheres, 1.04M triangles) these drew every triangle 17 + 216 times and took 12 of the cold frame's
// 16 s (docs/PERFORMANCE.md, "Levels of detail for the maps").
//
// meshopt_simplify (quadric edge collapse; meshoptimizer 0.18) keeps the surface within a bound of the
// original (world units); border and attribute-seam vertices stay where they are. Only positions
// count: normals, uvs and tangents are the kept vertices' own. Each level is simplified from the
// previous one (the two steps' errors add up within the level's bound); a pass draws, per mesh, the
// coarsest level whose bound is within what its texels allow (GpuScene::drawMeshes).
#include <cstdint>
#include <vector>

#include "renderer/scene/Scene.h"

namespace radiant {

struct MeshLodLevel {
  std::vector<std::uint32_t> indices;  // triangle list over the mesh's vertices
  float error = 0.f;                   // bound on the distance to the full mesh's surface (world units)
};

// Up to `levels` levels within baseError x factor^k of the full surface (k = 0, 1, ...); a level is kept
// only when it has at most 3/4 of the triangles of the one before it (the first: of the full mesh).
// Empty for meshes under minTriangles.
std::vector<MeshLodLevel> buildMeshLods(const MeshInstance& mesh, float baseError, int levels = 4, float factor = 4.f,
                                        std::size_t minTriangles = 2048);

// The first level's bound for a scene: a quarter of the texel of a 4096-texel orthographic shadow
// map of the whole scene (2 r / 4096, r its bounding radius), the finest texel any pass draws into.
float lodBaseError(const Bounds& sceneBounds);

}  // namespace radiant
