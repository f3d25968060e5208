#pragma once
// Test support for GL tests: one Renderer per test process, and lookups into a RenderOutput.
#include <memory>
#include <stdexcept>
#include <string>

#include "renderer/Renderer.h"

namespace radiant::testing {

// The process's renderer: creating an EGL context per test would dominate the run time.
inline Renderer& renderer() {
  static std::unique_ptr<Renderer> r = std::make_unique<Renderer>();
  return *r;
}

// A square request for an EXR of the beauty AOV.
inline api::RenderRequest exrRequest(int size) {
  api::RenderRequest req;
  req.width = req.height = size;
  req.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"beauty"}, false}};
  return req;
}

inline const Image& aov(const RenderOutput& out, const std::string& name) {
  for (const auto& a : out.aovs)
    if (a.aov == name) return a;
  throw std::runtime_error("missing aov " + name);
}

inline const api::PassStats* pass(const RenderOutput& out, const std::string& name) {
  for (const auto& p : out.stats.passes)
    if (p.name == name) return &p;
  return nullptr;
}

// -1 when the cache was not consulted, 0 for a miss, 1 for a hit.
inline int cacheEvent(const RenderOutput& out, const std::string& what) {
  for (const auto& e : out.stats.cache)
    if (e.what == what) return e.hit ? 1 : 0;
  return -1;
}

// The renderer replaces NaN and Inf by 0 and counts them in the last pass's counters; a frame is
// finite when nothing had to be replaced.
inline bool allFinite(const RenderOutput& out) {
  for (const auto& p : out.stats.passes)
    if (p.counters.count("non_finite_pixels_zeroed")) return false;
  return true;
}

}  // namespace radiant::testing
