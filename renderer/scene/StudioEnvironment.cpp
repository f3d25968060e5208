#include "renderer/scene/StudioEnvironment.h"

#include <algorithm>
#include <cmath>

namespace radiant {

float studioRadiance(const glm::vec3& dir) {
  const float y = std::clamp(dir.y, -1.f, 1.f);
  const float sky = 0.5f + 0.3f * std::max(y, 0.f), floor = 0.2f;
  const float t = std::clamp((y + 0.05f) / 0.1f, 0.f, 1.f);
  float L = floor + (sky - floor) * t * t * (3.f - 2.f * t);
  const glm::vec3 key = glm::normalize(glm::vec3(1.f, 1.25f, 1.f));
  const float angle = std::acos(std::clamp(glm::dot(dir, key), -1.f, 1.f));
  const float radius = glm::radians(15.f);
  if (angle < radius) {
    const float s = 1.f - angle / radius;  // 1 at the centre, 0 at the rim
    L += 8.f * s * s * (3.f - 2.f * s);
  }
  return L;
}

const Image& studioEnvironment() {
  static const Image map = [] {
    constexpr float kPi = 3.14159265358979323846f;
    Image m = Image::make("environment", kStudioEnvironmentWidth, kStudioEnvironmentHeight, 3);
    for (int y = 0; y < m.height; ++y)
      for (int x = 0; x < m.width; ++x) {
        // Inverse of equirectUv() at the texel centre.
        const float u = (x + 0.5f) / m.width, v = (y + 0.5f) / m.height;
        const float phi = (u - 0.5f) * 2.f * kPi, theta = v * kPi;
        const glm::vec3 dir(std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi));
        const float L = studioRadiance(dir);
        float* p = m.at(x, y);
        p[0] = p[1] = p[2] = L;
      }
    return m;
  }();
  return map;
}

}  // namespace radiant
