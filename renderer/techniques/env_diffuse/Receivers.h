#pragma once
// Which scene nodes receive env_diffuse's indirect light, and from which reference point (GL-free, so
// tests/unit/env_diffuse checks the rules).
//
// Default rule, in this order:
//  1. the request's `receivers`: comma-separated node names (every name must exist);
//  2. else, if any node carries the glTF extra "radiant_receiver" (boolean), exactly the nodes where it
//     is true (the built-in Cornell boxes flag their sphere and tall box);
//  3. else a size heuristic for "an object standing in a room": a node whose bounds are compact (the
//     smallest extent at least kCompactness of the largest, so not a wall, floor or ceiling) and small
//     (bounds diagonal at most kMaxSceneFraction of the scene's), at most kMaxReceivers of them,
//     smallest first.
// Every other node is environment. A receiver's reference point is the centre of its bounds unless the
// request's `reference_points` ("name=x,y,z;name=x,y,z") names it.
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "renderer/scene/Scene.h"

namespace radiant::env_diffuse {

constexpr float kCompactness = 0.1f;
constexpr float kMaxSceneFraction = 0.5f;
constexpr int kMaxReceivers = 8;

struct Receiver {
  std::string name;           // node name
  std::vector<int> meshes;    // indices into Scene::meshes
  Bounds bounds;
  glm::vec3 referencePoint{0.f};
};

// Throws api::ApiError 422 (pointer /passes/env_diffuse/receivers or .../reference_points) for an
// unknown node, a malformed point or more than kMaxReceivers named receivers.
std::vector<Receiver> selectReceivers(const Scene& scene, const std::string& receiversParam,
                                      const std::string& referencePointsParam);

}  // namespace radiant::env_diffuse
