#pragma once
// Builds small scenes in code for tests: quads, boxes and spheres with given materials and lights.
#include <cmath>
#include <string>

#include <glm/gtc/constants.hpp>

#include "renderer/scene/Scene.h"

namespace radiant::testing {

// A white material that is exactly Lambertian at normal incidence: KHR_materials_ior 1.0 makes the
// dielectric Fresnel F0 = 0, so the glTF BRDF reduces to baseColor/pi wherever (1 - VdotH)^5 ~ 0.
inline Material lambertian(glm::vec3 albedo = glm::vec3(1.f)) {
  Material m;
  m.name = "lambertian";
  m.baseColorFactor = glm::vec4(albedo, 1.f);
  m.metallicFactor = 0.f;
  m.roughnessFactor = 1.f;
  m.ior = 1.f;
  return m;
}

class SceneBuilder {
public:
  SceneBuilder() { scene_.name = "test"; }
  int material(const Material& m) { scene_.materials.push_back(m); return static_cast<int>(scene_.materials.size()) - 1; }

  // A quad centred at `c` spanned by half-vectors `u` and `v`; its normal is normalize(cross(u, v)).
  SceneBuilder& quad(glm::vec3 c, glm::vec3 u, glm::vec3 v, int mat, const std::string& name = "quad") {
    MeshInstance m;
    m.name = name;
    m.material = mat;
    const glm::vec3 n = glm::normalize(glm::cross(u, v));
    m.positions = {c - u - v, c + u - v, c + u + v, c - u + v};
    m.normals = {n, n, n, n};
    m.uv0 = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
    m.indices = {0, 1, 2, 0, 2, 3};
    for (auto& p : m.positions) m.bounds.extend(p);
    scene_.meshes.push_back(std::move(m));
    return *this;
  }

  // An n x n x 2 triangle grid in the plane y = c.y spanning c.x +- half, c.z +- half, facing +y (up) or
  // -y: a finely tessellated quad (light_volumes builds one beam per triangle).
  SceneBuilder& gridY(glm::vec3 c, float half, int n, bool up, int mat, const std::string& name = "grid") {
    MeshInstance m;
    m.name = name;
    m.material = mat;
    for (int i = 0; i <= n; ++i)
      for (int j = 0; j <= n; ++j) {
        m.positions.push_back({c.x - half + 2.f * half * i / n, c.y, c.z - half + 2.f * half * j / n});
        m.normals.push_back({0.f, up ? 1.f : -1.f, 0.f});
      }
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        const std::uint32_t a = i * (n + 1) + j, b = a + n + 1;
        if (up) m.indices.insert(m.indices.end(), {a, a + 1, b, a + 1, b + 1, b});  // counter-clockwise from +y
        else m.indices.insert(m.indices.end(), {a, b, a + 1, a + 1, b, b + 1});
      }
    for (auto& p : m.positions) m.bounds.extend(p);
    scene_.meshes.push_back(std::move(m));
    return *this;
  }

  // An axis-aligned solid box of outward-facing quads (names "<name>+x", "<name>-y", ...).
  SceneBuilder& box(glm::vec3 lo, glm::vec3 hi, int mat, const std::string& name = "box") {
    const glm::vec3 c = 0.5f * (lo + hi), e = 0.5f * (hi - lo);
    quad(c + glm::vec3(e.x, 0, 0), {0, e.y, 0}, {0, 0, e.z}, mat, name + "+x");
    quad(c - glm::vec3(e.x, 0, 0), {0, 0, e.z}, {0, e.y, 0}, mat, name + "-x");
    quad(c + glm::vec3(0, e.y, 0), {0, 0, e.z}, {e.x, 0, 0}, mat, name + "+y");
    quad(c - glm::vec3(0, e.y, 0), {e.x, 0, 0}, {0, 0, e.z}, mat, name + "-y");
    quad(c + glm::vec3(0, 0, e.z), {e.x, 0, 0}, {0, e.y, 0}, mat, name + "+z");
    quad(c - glm::vec3(0, 0, e.z), {0, e.y, 0}, {e.x, 0, 0}, mat, name + "-z");
    return *this;
  }

  // The same box as one mesh (one MeshInstance, outward normals): a solid the specular and caustics
  // passes treat as one object with one reference point, as a glTF file's box primitive would be.
  SceneBuilder& solidBox(glm::vec3 lo, glm::vec3 hi, int mat, const std::string& name = "solid") {
    const std::size_t first = scene_.meshes.size();
    box(lo, hi, mat, name);
    return merge(first, scene_.meshes.size() - first, name);
  }

  // Merges the `count` meshes from index `first` on into one MeshInstance (the first one's material)
  // at index `first`: one primitive made of several, e.g. five faces of a box.
  SceneBuilder& merge(std::size_t first, std::size_t count, const std::string& name) {
    MeshInstance merged = std::move(scene_.meshes[first]);
    merged.name = name;
    for (std::size_t i = first + 1; i < first + count; ++i) {
      const auto base = static_cast<std::uint32_t>(merged.positions.size());
      const MeshInstance& q = scene_.meshes[i];
      merged.positions.insert(merged.positions.end(), q.positions.begin(), q.positions.end());
      merged.normals.insert(merged.normals.end(), q.normals.begin(), q.normals.end());
      merged.uv0.insert(merged.uv0.end(), q.uv0.begin(), q.uv0.end());
      for (std::uint32_t idx : q.indices) merged.indices.push_back(base + idx);
      merged.bounds.extend(q.bounds);
    }
    scene_.meshes.erase(scene_.meshes.begin() + static_cast<std::ptrdiff_t>(first + 1),
                        scene_.meshes.begin() + static_cast<std::ptrdiff_t>(first + count));
    scene_.meshes[first] = std::move(merged);
    return *this;
  }

  // A UV sphere with outward normals.
  SceneBuilder& sphere(glm::vec3 c, float r, int mat, int segments = 48, int rings = 24, const std::string& name = "sphere") {
    MeshInstance m;
    m.name = name;
    m.material = mat;
    for (int i = 0; i <= rings; ++i) {
      const float th = glm::pi<float>() * i / rings;
      for (int j = 0; j <= segments; ++j) {
        const float ph = glm::two_pi<float>() * j / segments;
        const glm::vec3 n(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph));
        m.positions.push_back(c + r * n);
        m.normals.push_back(n);
        m.uv0.push_back({static_cast<float>(j) / segments, static_cast<float>(i) / rings});
      }
    }
    for (int i = 0; i < rings; ++i)
      for (int j = 0; j < segments; ++j) {
        const unsigned a = i * (segments + 1) + j, b = a + segments + 1;
        m.indices.insert(m.indices.end(), {a, a + 1, b, a + 1, b + 1, b});
      }
    for (auto& p : m.positions) m.bounds.extend(p);
    scene_.meshes.push_back(std::move(m));
    return *this;
  }

  SceneBuilder& pointLight(glm::vec3 p, float intensity, glm::vec3 color = glm::vec3(1.f)) {
    Light l;
    l.type = LightType::Point;
    l.position = p;
    l.intensity = intensity;
    l.color = color;
    scene_.lights.push_back(l);
    return *this;
  }
  SceneBuilder& spotLight(glm::vec3 p, glm::vec3 dir, float intensity, float inner, float outer) {
    Light l;
    l.type = LightType::Spot;
    l.position = p;
    l.direction = glm::normalize(dir);
    l.intensity = intensity;
    l.innerConeAngle = inner;
    l.outerConeAngle = outer;
    scene_.lights.push_back(l);
    return *this;
  }
  SceneBuilder& directionalLight(glm::vec3 dir, float intensity) {
    Light l;
    l.type = LightType::Directional;
    l.direction = glm::normalize(dir);
    l.intensity = intensity;
    scene_.lights.push_back(l);
    return *this;
  }
  // Orthographic camera looking straight down -Y from height `h`, covering [-half, half]^2 in x,z.
  SceneBuilder& topDownOrtho(float h, float half) {
    Camera c;
    c.projection = ProjectionType::Orthographic;
    c.xmag = c.ymag = half;
    c.znear = 0.01f * h;
    c.zfar = 2.f * h;
    // Camera -Z looks down -Y; camera +Y (image up) is world -Z.
    c.world = glm::mat4(glm::vec4(1, 0, 0, 0), glm::vec4(0, 0, -1, 0), glm::vec4(0, 1, 0, 0), glm::vec4(0, h, 0, 1));
    c.fromFile = true;
    scene_.camera = c;
    return *this;
  }
  Scene build(const std::string& digest = "") {
    scene_.digest = digest;
    scene_.features = computeFeatures(scene_);
    return scene_;
  }
  Scene& scene() { return scene_; }

private:
  Scene scene_;
};

// An orthographic camera at z = 10 looking down -z, covering [-half, half]^2 in x, y (znear 0.01).
inline Camera orthoCameraAlongZ(float half) {
  Camera c;
  c.projection = ProjectionType::Orthographic;
  c.xmag = c.ymag = half;
  c.znear = 0.01f;
  c.zfar = 100.f;
  c.world = glm::mat4(1.f);
  c.world[3] = glm::vec4(0, 0, 10, 1);
  c.fromFile = true;
  return c;
}

// World x,z of the centre of pixel (px, py) for topDownOrtho(h, half) at the given resolution
// (row 0 = top of the image = world -z).
inline glm::vec2 topDownPixelToWorld(int px, int py, int size, float half) {
  const float x = (-1.f + 2.f * (px + 0.5f) / size) * half;
  const float z = (-1.f + 2.f * (py + 0.5f) / size) * half;
  return {x, z};
}

}  // namespace radiant::testing
