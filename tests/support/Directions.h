#pragma once
// Test support: unit directions that cover the sphere densely and hit the places encodings break.
#include <cmath>
#include <vector>

#include <glm/glm.hpp>

namespace radiant::testing {

// A spherical Fibonacci set of n directions, the six axes (both signs) and the octants' diagonals with
// z in {-1, 0, 1}: the dense cover and the octahedral map's corners, folds and poles.
inline std::vector<glm::vec3> testDirections(int n) {
  std::vector<glm::vec3> dirs;
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - (i + 0.5) * 2.0 / n, r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const double phi = i * 2.399963229728653;  // the golden angle
    dirs.emplace_back(float(r * std::cos(phi)), float(r * std::sin(phi)), float(z));
  }
  for (int a = 0; a < 3; ++a)
    for (float sgn : {-1.f, 1.f}) {
      glm::vec3 v(0.f);
      v[a] = sgn;
      dirs.push_back(v);
    }
  for (float x : {-1.f, 1.f})
    for (float y : {-1.f, 1.f})
      for (float z : {-1.f, 0.f, 1.f}) dirs.push_back(glm::normalize(glm::vec3(x, y, z)));
  return dirs;
}

}  // namespace radiant::testing
