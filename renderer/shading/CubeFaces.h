#pragma once
// The six 90-degree views of a cube map around a point, for every pass that renders one (shadow cube
// maps, specular distance maps, caustic cube maps, env_diffuse's distance cube maps).
#include <cmath>

#include <glm/glm.hpp>
#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "renderer/frame/FrameView.h"

namespace radiant {

// World -> clip of cube face `face` (GL order +X, -X, +Y, -Y, +Z, -Z) seen from p, reversed-Z with near
// plane znear. GL cube map face orientation (GL 4.5 spec table 8.19): the up vectors make a lookAt
// camera's image match the face's (s,t) layout when rendered with the lower-left origin.
inline glm::mat4 cubeFaceViewProj(const glm::vec3& p, int face, float znear) {
  static const glm::vec3 dirs[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  static const glm::vec3 ups[6] = {{0, -1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}, {0, -1, 0}, {0, -1, 0}};
  return reversedZPerspective(glm::half_pi<float>(), 1.f, znear) * glm::lookAt(p, p + dirs[face], ups[face]);
}

// Whether a sphere (centre c, radius r) reaches cube face `face`'s 90-degree frustum around p (its four
// side planes; the near plane is ignored): a pass drawing the whole scene into each face skips the
// meshes that lie in other faces (conservative: a sphere near a side plane is drawn into both faces).
inline bool sphereInCubeFace(const glm::vec3& p, int face, const glm::vec3& c, float r) {
  const glm::vec3 d = c - p;
  const int axis = face / 2;
  const float forward = face % 2 == 0 ? d[axis] : -d[axis];
  const float slack = r * 1.41421356f;
  return forward - std::abs(d[(axis + 1) % 3]) >= -slack && forward - std::abs(d[(axis + 2) % 3]) >= -slack;
}

}  // namespace radiant
