#pragma once
// Shared by the specular tests and the specular benchmark: scene variants and helpers.
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

#include <glm/gtc/matrix_transform.hpp>

#include "renderer/Renderer.h"
#include "renderer/scene/BuiltinScenes.h"
#include "tests/support/SceneBuilder.h"

namespace radiant::testing {

inline const Image& findAov(const RenderOutput& out, const std::string& name) {
  for (const auto& a : out.aovs)
    if (a.aov == name) return a;
  throw std::runtime_error("missing aov " + name);
}

// A camera-to-world matrix for a camera at `eye` looking along `forward` with `up` as image up.
inline glm::mat4 cameraWorld(glm::vec3 eye, glm::vec3 forward, glm::vec3 up) {
  const glm::vec3 f = glm::normalize(forward);
  const glm::vec3 r = glm::normalize(glm::cross(f, up));
  const glm::vec3 u = glm::cross(r, f);
  return glm::mat4(glm::vec4(r, 0), glm::vec4(u, 0), glm::vec4(-f, 0), glm::vec4(eye, 1));
}

inline Camera orthoCamera(glm::vec3 eye, glm::vec3 forward, glm::vec3 up, float half, float zfar) {
  Camera c;
  c.projection = ProjectionType::Orthographic;
  c.xmag = c.ymag = half;
  c.znear = 0.01f;
  c.zfar = zfar;
  c.world = cameraWorld(eye, forward, up);
  c.fromFile = true;
  return c;
}

inline Material emitter(glm::vec3 radiance, bool doubleSided = true) {
  Material m;
  m.name = "emitter";
  m.baseColorFactor = glm::vec4(0.f, 0.f, 0.f, 1.f);
  m.metallicFactor = 0.f;
  m.roughnessFactor = 1.f;
  m.emissiveFactor = radiance;
  m.doubleSided = doubleSided;
  return m;
}

inline Material mirror(glm::vec3 f0) {
  Material m;
  m.name = "mirror";
  m.baseColorFactor = glm::vec4(f0, 1.f);
  m.metallicFactor = 1.f;
  m.roughnessFactor = 0.f;
  return m;
}

inline Material glass(float ior) {
  Material m;
  m.name = "glass";
  m.baseColorFactor = glm::vec4(1.f);
  m.metallicFactor = 0.f;
  m.roughnessFactor = 0.f;
  m.transmissionFactor = 1.f;
  m.ior = ior;
  return m;
}

// A built-in Cornell box whose diffuse surfaces are replaced by black emitters of radiance equal to
// their base colour, with the punctual light removed. Every path the reference renderer finds is then
// camera -> (mirror | glass)^k -> emitter, exactly what direct (emission) + specular compute, so the
// error against the reference is the error of the layered-distance-map tracing alone (no diffuse
// interreflection, no shadow-map or direct-lighting error mixed in).
inline Scene radiancePaintedCornell(const std::string& name) {
  Scene s = loadBuiltinScene(name);
  for (Material& m : s.materials) {
    if (m.isSpecular()) continue;
    m.emissiveFactor = glm::vec3(m.baseColorFactor);
    m.emissiveStrength = 1.f;
    m.baseColorFactor = glm::vec4(0.f, 0.f, 0.f, 1.f);
    m.ior = 1.f;  // dielectric F0 = 0: only glTF's Schlick grazing term (1 - v.h)^5 still reflects
    m.doubleSided = true;
  }
  s.lights.clear();
  s.digest = s.digest + "|painted";
  s.features = computeFeatures(s);
  return s;
}

// Box-filters an image by an integer factor (first three channels): the reference renderer averages
// radiance over each pixel's square, a raster pass samples pixel centres; rendering at ss x ss the
// resolution and averaging makes the two comparable at silhouettes and material edges.
inline Image boxDownsample(const Image& src, int ss) {
  Image out = Image::make(src.aov, src.width / ss, src.height / ss, 3);
  for (int y = 0; y < out.height; ++y)
    for (int x = 0; x < out.width; ++x)
      for (int c = 0; c < 3; ++c) {
        double sum = 0;
        for (int j = 0; j < ss; ++j)
          for (int i = 0; i < ss; ++i) sum += src.at(x * ss + i, y * ss + j)[c];
        out.at(x, y)[c] = static_cast<float>(sum / (ss * ss));
      }
  return out;
}

// Root-mean-square difference over the colour channels of the pixels where mask (a 3-channel image)
// is non-zero; all pixels when mask is null.
inline double rmseMasked(const Image& a, const Image& b, const Image* mask, int* count = nullptr) {
  double sq = 0;
  int n = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      if (mask) {
        const float* m = mask->at(x, y);
        if (m[0] + m[1] + m[2] <= 0.f) continue;
      }
      for (int c = 0; c < 3; ++c) sq += std::pow(double(a.at(x, y)[c]) - double(b.at(x, y)[c]), 2.0);
      ++n;
    }
  if (count) *count = n;
  return n ? std::sqrt(sq / (3.0 * n)) : 0.0;
}

}  // namespace radiant::testing
