#include "renderer/scene/Scene.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace radiant {

SceneFeatures computeFeatures(const Scene& scene) {
  SceneFeatures f;
  for (const auto& l : scene.lights) {
    switch (l.type) {
      case LightType::Point: ++f.pointLights; break;
      case LightType::Spot: ++f.spotLights; break;
      case LightType::Directional: ++f.directionalLights; break;
    }
  }
  // Materials are counted once each, and only when some instance uses them: an unused material
  // cannot make a pass worth running. Index -1 is glTF's default material (diffuse, not emissive).
  std::vector<bool> used(scene.materials.size(), false);
  for (const auto& m : scene.meshes) {
    f.triangles += m.triangleCount();
    // Bounds from the positions rather than MeshInstance::bounds, so hand-built scenes work too.
    for (const auto& p : m.positions) f.bounds.extend(p);
    if (m.material >= 0 && m.material < static_cast<int>(scene.materials.size()))
      used[static_cast<std::size_t>(m.material)] = true;
    if (scene.material(m.material).isEmissive()) f.emissiveTriangles += static_cast<int>(m.triangleCount());
  }
  for (std::size_t i = 0; i < scene.materials.size(); ++i) {
    if (!used[i]) continue;
    // isSpecular() includes transmissive materials: smooth glass also makes caustics.
    if (scene.materials[i].isSpecular()) ++f.specularMaterials;
    if (scene.materials[i].isTransmissive()) ++f.transmissiveMaterials;
  }
  f.textures = static_cast<int>(scene.textures.size());
  f.hasCamera = scene.camera.fromFile;
  f = mediaFeatures(f, scene.media);
  // Particles are part of what the automatic camera frames.
  for (const auto& s : scene.media)
    for (const auto& p : s.particles) {
      f.bounds.extend(p.position - glm::vec3(p.radius));
      f.bounds.extend(p.position + glm::vec3(p.radius));
    }
  return f;
}

SceneFeatures mediaFeatures(const SceneFeatures& scene, const std::vector<api::ParticleSystem>& extra) {
  SceneFeatures f = scene;
  for (const auto& s : extra) {
    if (s.particles.empty()) continue;
    ++f.particleSystems;
    f.particles += s.particles.size();
    if (s.emits()) ++f.emissiveMedia;
    else ++f.scatteringMedia;
  }
  return f;
}

Camera defaultCameraFor(const Bounds& bounds, float aspect, float yfov) {
  Camera cam;
  cam.yfov = yfov;
  cam.name = "default";
  cam.projection = ProjectionType::Perspective;
  cam.fromFile = false;
  cam.aspectRatio = 0.f;  // any image aspect >= `aspect` still frames the bounds (see below)
  const glm::vec3 center = bounds.empty() ? glm::vec3(0.f) : bounds.center();
  float radius = bounds.empty() ? 1.f : bounds.radius();
  if (!(radius > 1e-6f) || !std::isfinite(radius)) radius = 1.f;
  // The bounding sphere fits a cone of half-angle a at distance radius / sin(a). The narrower of
  // the vertical half-fov and the horizontal one (tan(x/2) = aspect tan(y/2)) decides.
  const float a = std::max(aspect, 1e-3f);
  const float halfY = 0.5f * cam.yfov;
  const float halfX = std::atan(a * std::tan(halfY));
  const float half = std::min(halfX, halfY);
  const float distance = radius / std::sin(half);
  glm::mat4 world(1.f);
  world[3] = glm::vec4(center + glm::vec3(0.f, 0.f, distance), 1.f);  // looking down -Z at the centre
  cam.world = world;
  // Near plane in front of the sphere; the far plane stays infinite (reversed-Z keeps precision).
  cam.znear = std::max(0.5f * (distance - radius), 1e-4f * distance);
  cam.zfar = 0.f;
  return cam;
}

}  // namespace radiant
