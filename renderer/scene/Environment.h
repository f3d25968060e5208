#pragma once
// The environment: an equirectangular radiance map around the scene (a request's `environment`), or
// a uniform sky (`ambient`). One mapping for every consumer (the reference path tracer, the raster
// background in shaders/common/environment.glsl, the ambient average), so they see the same sky:
//   u = 0.5 + atan2(dir.x, -dir.z) / (2 pi)   (the image centre looks down -Z)
//   v = acos(dir.y) / pi                      (row 0 is +Y, up)
// Texels are piecewise constant (nearest), which is what the reference importance-samples exactly.
#include <algorithm>
#include <cmath>

#include <glm/glm.hpp>

#include "renderer/Image.h"

namespace radiant {

inline glm::vec2 equirectUv(const glm::vec3& dir) {
  constexpr float kPi = 3.14159265358979323846f;
  return {0.5f + std::atan2(dir.x, -dir.z) / (2.f * kPi), std::acos(std::clamp(dir.y, -1.f, 1.f)) / kPi};
}

// The texel a direction falls in.
inline void equirectTexel(const Image& map, const glm::vec3& dir, int& x, int& y) {
  const glm::vec2 uv = equirectUv(dir);
  x = std::clamp(static_cast<int>(uv.x * map.width), 0, map.width - 1);
  y = std::clamp(static_cast<int>(uv.y * map.height), 0, map.height - 1);
}

// The map's mean radiance over the sphere of directions, each texel weighted by its solid angle
// (proportional to sin(theta) of its row): the uniform sky with the same total power. Ambient passes
// that model a uniform sky (ambient occlusion) use it; the reference uses the map itself.
inline glm::vec3 environmentAverage(const Image& map) {
  constexpr double kPi = 3.14159265358979323846;
  glm::dvec3 sum(0.0);
  double weight = 0.0;
  for (int y = 0; y < map.height; ++y) {
    const double w = std::sin(kPi * (y + 0.5) / map.height);
    for (int x = 0; x < map.width; ++x) {
      const float* p = map.at(x, y);
      sum += w * (map.channels >= 3 ? glm::dvec3(p[0], p[1], p[2]) : glm::dvec3(p[0]));
      weight += w;
    }
  }
  return weight > 0.0 ? glm::vec3(sum / weight) : glm::vec3(0.f);
}

}  // namespace radiant
