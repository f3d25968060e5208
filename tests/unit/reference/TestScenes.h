#pragma once
// Scenes built in code for the reference renderer's tests (no glTF loader involved).
#include <cmath>
#include <functional>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "renderer/Image.h"
#include "renderer/raytracing/Bsdf.h"
#include "renderer/scene/Scene.h"

namespace radiant::testing {

// Unpolarised Fresnel reflectance written out from the Fresnel equations (independent of Brdf.h).
inline double fresnelUnpolarised(double cosI, double n1, double n2) {
  const double sinT = n1 / n2 * std::sqrt(1 - cosI * cosI);
  if (sinT >= 1) return 1;
  const double cosT = std::sqrt(1 - sinT * sinT);
  const double rs = (n1 * cosI - n2 * cosT) / (n1 * cosI + n2 * cosT);
  const double rp = (n2 * cosI - n1 * cosT) / (n2 * cosI + n1 * cosT);
  return 0.5 * (rs * rs + rp * rp);
}

inline Material lambert(glm::vec3 albedo) {
  // glTF has no pure Lambertian material: the dielectric always carries a Fresnel-weighted GGX layer.
  // ior = 1 makes f0 = 0, so Schlick's F = (1 - v.h)^5 vanishes for small angles between v and l
  // (<1e-5 for the configurations used here); where it does not, the tests integrate the full BRDF.
  Material m;
  m.baseColorFactor = glm::vec4(albedo, 1.f);
  m.metallicFactor = 0.f;
  m.roughnessFactor = 1.f;
  m.ior = 1.f;
  m.doubleSided = true;
  return m;
}

inline Material emitter(glm::vec3 radiance, bool doubleSided = false) {
  Material m;
  // As black as glTF allows: a black metal (f0 = 0) reflects only Schlick's (1 - v.h)^5, nothing near
  // normal incidence. (A black dielectric would still reflect 4%.)
  m.baseColorFactor = glm::vec4(0.f, 0.f, 0.f, 1.f);
  m.metallicFactor = 1.f;
  m.emissiveFactor = radiance;
  m.doubleSided = doubleSided;
  return m;
}

// A smooth, clear dielectric (KHR_materials_transmission 1, roughness 0) of index `ior`.
inline Material smoothGlass(float ior) {
  Material m;
  m.baseColorFactor = glm::vec4(1.f);
  m.metallicFactor = 0.f;
  m.roughnessFactor = 0.f;
  m.transmissionFactor = 1.f;
  m.ior = ior;
  return m;
}

// smoothGlass bounding an absorbing medium (KHR_materials_volume): white light turns into `color`
// after `distance` inside.
inline Material absorbingGlass(float ior, glm::vec3 color, float distance) {
  Material m = smoothGlass(ior);
  m.thicknessFactor = 1.f;
  m.attenuationColor = color;
  m.attenuationDistance = distance;
  return m;
}

// The BSDF of a material's factors (no textures), outside any scene.
inline rt::GltfBsdf bsdfOf(const Material& m) {
  rt::GltfBsdf b;
  b.baseColor = glm::vec3(m.baseColorFactor);
  b.metallic = m.metallicFactor;
  b.roughness = m.roughnessFactor;
  b.transmission = m.transmissionFactor;
  b.ior = m.ior;
  return b;
}

inline int addMaterial(Scene& s, const Material& m) {
  s.materials.push_back(m);
  return static_cast<int>(s.materials.size()) - 1;
}

inline void finishMesh(MeshInstance& m) {
  for (const auto& p : m.positions) m.bounds.extend(p);
}

// Parallelogram corner, corner + u, corner + u + v, corner + v; front face (CCW) normal = u x v.
inline MeshInstance quad(glm::vec3 corner, glm::vec3 u, glm::vec3 v, int material) {
  MeshInstance m;
  m.name = "quad";
  m.material = material;
  m.positions = {corner, corner + u, corner + u + v, corner + v};
  const glm::vec3 n = glm::normalize(glm::cross(u, v));
  m.normals.assign(4, n);
  m.indices = {0, 1, 2, 0, 2, 3};
  finishMesh(m);
  return m;
}

// Square of half-size `half` centred at c, perpendicular to axis n (front = n).
inline MeshInstance square(glm::vec3 c, glm::vec3 n, float half, int material) {
  n = glm::normalize(n);
  const rt::ShadingFrame f = rt::ShadingFrame::fromNormal(n);
  glm::vec3 u = f.t * (2.f * half), v = f.b * (2.f * half);
  if (glm::dot(glm::cross(u, v), n) < 0.f) std::swap(u, v);
  return quad(c - 0.5f * u - 0.5f * v, u, v, material);
}

// Axis-aligned box with outward-facing, flat-shaded faces.
inline MeshInstance box(glm::vec3 lo, glm::vec3 hi, int material) {
  MeshInstance m;
  m.name = "box";
  m.material = material;
  auto face = [&](glm::vec3 c, glm::vec3 u, glm::vec3 v) {
    const MeshInstance q = quad(c, u, v, material);
    const auto base = static_cast<std::uint32_t>(m.positions.size());
    for (size_t i = 0; i < 4; ++i) { m.positions.push_back(q.positions[i]); m.normals.push_back(q.normals[i]); }
    for (auto i : q.indices) m.indices.push_back(base + i);
  };
  const glm::vec3 d = hi - lo;
  const glm::vec3 X(d.x, 0, 0), Y(0, d.y, 0), Z(0, 0, d.z);
  face(lo, Y, X);                 // -z
  face(lo + Z, X, Y);             // +z
  face(lo, X, Z);                 // -y
  face(lo + Y, Z, X);             // +y
  face(lo, Z, Y);                 // -x
  face(lo + X, Y, Z);             // +x
  finishMesh(m);
  return m;
}

// UV sphere with flat (per-face) normals and outward CCW winding, so every facet sees only the sky.
inline MeshInstance sphere(glm::vec3 c, float r, int stacks, int slices, int material) {
  MeshInstance m;
  m.name = "sphere";
  m.material = material;
  auto point = [&](int i, int j) {
    const float theta = rt::kPi * i / stacks, phi = 2.f * rt::kPi * j / slices;
    return c + r * glm::vec3(std::sin(theta) * std::cos(phi), std::cos(theta), -std::sin(theta) * std::sin(phi));
  };
  auto tri = [&](glm::vec3 a, glm::vec3 b, glm::vec3 d) {
    glm::vec3 n = glm::cross(b - a, d - a);
    if (glm::dot(n, n) < 1e-20f * r * r * r * r) return;  // degenerate at the poles
    n = glm::normalize(n);
    if (glm::dot(n, (a + b + d) / 3.f - c) < 0.f) { std::swap(b, d); n = -n; }
    const auto base = static_cast<std::uint32_t>(m.positions.size());
    m.positions.insert(m.positions.end(), {a, b, d});
    m.normals.insert(m.normals.end(), {n, n, n});
    m.indices.insert(m.indices.end(), {base, base + 1, base + 2});
  };
  for (int i = 0; i < stacks; ++i)
    for (int j = 0; j < slices; ++j) {
      tri(point(i, j), point(i + 1, j), point(i + 1, j + 1));
      tri(point(i, j), point(i + 1, j + 1), point(i, j + 1));
    }
  finishMesh(m);
  return m;
}

inline Camera lookAtCamera(glm::vec3 eye, glm::vec3 target, glm::vec3 up, bool ortho, float size) {
  Camera c;
  c.projection = ortho ? ProjectionType::Orthographic : ProjectionType::Perspective;
  c.world = glm::inverse(glm::lookAt(eye, target, up));
  if (ortho) { c.xmag = size; c.ymag = size; } else { c.yfov = size; }
  c.znear = 0.f;
  return c;
}
inline glm::vec3 anyUp(glm::vec3 dir) {
  dir = glm::normalize(dir);
  return std::abs(dir.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
}
// An orthographic camera looking at `target` from direction `towardsEye` with a tiny footprint.
inline Camera pinpointCamera(glm::vec3 target, glm::vec3 towardsEye, float distance = 1.f, float footprint = 1e-4f) {
  towardsEye = glm::normalize(towardsEye);
  return lookAtCamera(target + distance * towardsEye, target, anyUp(towardsEye), true, footprint);
}

inline glm::dvec3 meanPixel(const Image& img) {
  glm::dvec3 s(0.0);
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) s += glm::dvec3(img.at(x, y)[0], img.at(x, y)[1], img.at(x, y)[2]);
  return s / double(img.width * img.height);
}

// Directional albedo E(wo) = \int f(wo, wi) cos(theta_i) dwi of a BSDF over the upper hemisphere, by
// midpoint quadrature in (theta, phi) -- independent of all the sampling code.
inline glm::dvec3 directionalAlbedo(const rt::GltfBsdf& bsdf, float cosThetaO, int nTheta = 600,
                                    int nPhi = 720) {
  const glm::vec3 wo(std::sqrt(std::max(0.f, 1.f - cosThetaO * cosThetaO)), 0.f, cosThetaO);
  glm::dvec3 sum(0.0);
  const double dTheta = 0.5 * M_PI / nTheta, dPhi = 2.0 * M_PI / nPhi;
  for (int i = 0; i < nTheta; ++i) {
    const double theta = (i + 0.5) * dTheta;
    const double st = std::sin(theta), ct = std::cos(theta);
    for (int j = 0; j < nPhi; ++j) {
      const double phi = (j + 0.5) * dPhi;
      const glm::vec3 wi(float(st * std::cos(phi)), float(st * std::sin(phi)), float(ct));
      sum += glm::dvec3(bsdf.eval(wo, wi)) * (ct * st * dTheta * dPhi);
    }
  }
  return sum;
}

}  // namespace radiant::testing
