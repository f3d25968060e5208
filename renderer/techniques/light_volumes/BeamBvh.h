#pragma once
// The culled traversal of light_volumes (the paper's stated limit, §4.5, is a linear loop over every
// beam per fragment, O(W H B)): a BVH over each beam, cut into segments along its cone's axis (so that
// a long oblique beam is not one scene-sized box), each boxed by the hull of its end flux triangles
// (plus the glossy padding). A fragment gathers
// only the beams whose segment boxes contain it, and of those only the one segment whose axial
// range holds it (so a beam never counts twice). Beams are grouped (kBeamsPerGroup consecutive
// beams, one BVH each) so that one dispatch's traversal stays below llvmpipe's 65535 loop iterations.
#include <vector>

#include <glm/glm.hpp>

#include "renderer/scene/Scene.h"
#include "renderer/techniques/light_volumes/Beams.h"

namespace radiant::light_volumes {

inline constexpr int kBeamsPerGroup = 4096;
inline constexpr int kMaxSegmentsPerBeam = 8;
inline constexpr int kBvhLeafSize = 4;
inline constexpr int kBvhMaxDepth = 30;  // the shader's traversal stack holds 32 entries

struct BeamBvh {
  std::vector<BeamBvhNode> nodes;
  std::vector<glm::vec4> primitives;  // (s0, s1, beam index, 0)
  std::vector<int> roots;             // root node of each group (-1 when no beam of the group reaches the bounds)
  std::vector<int> groupBeams;        // beams per group, for the stats
  int depth = 0;
};

// The BVH of the beams (with their cones) inside `bounds` (the receivers' world bounds: nothing outside
// receives).
// Polls `cancel` per group of beams (throws rt::Cancelled).
BeamBvh buildBeamBvh(const std::vector<Beam>& beams, const std::vector<BeamCone>& cones, const Bounds& bounds,
                     const rt::Cancel& cancel = {});

}  // namespace radiant::light_volumes
