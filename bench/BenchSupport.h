#pragma once
// Helpers shared by the C++ benchmarks in bench/ (not by the renderer or the tests).
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "renderer/Renderer.h"

namespace radiant::bench {

// The AOV `name` of a frame; throws when the frame has none (a benchmark mistake, not a result).
inline const Image& aovOf(const RenderOutput& out, const std::string& name) {
  for (const auto& a : out.aovs)
    if (a.aov == name) return a;
  throw std::runtime_error("missing aov " + name);
}

// RMSE of `a` against `ref`, divided by the mean of `ref` (same size and channels).
inline double relativeRmse(const Image& a, const Image& ref) {
  double s = 0, m = 0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i) s += std::pow(a.pixels[i] - ref.pixels[i], 2), m += ref.pixels[i];
  return std::sqrt(s / a.pixels.size()) / std::max(m / a.pixels.size(), 1e-12);
}

}  // namespace radiant::bench
