#pragma once
// Camera matrices for one frame. Depth is reversed-Z with an infinite far plane for perspective
// cameras (depth = znear / z_view: 1 at the near plane, 0 at infinity), stored in a 32-bit float
// depth buffer with glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE). Floating-point precision is then
// nearly uniform in log depth, so scenes at 1e-3 m and 1e4 m scale render alike.
#include <cstdint>
#include <memory>
#include <set>

#include <glm/glm.hpp>

#include "api/Types.h"
#include "renderer/frame/GpuTypes.h"
#include "renderer/Image.h"
#include "renderer/scene/Scene.h"
#include "renderer/shading/EnvironmentLights.h"

namespace radiant {

struct FrameView {
  int width = 0, height = 0;  // the passes' size: k times the request's with supersampling k
  // Raster samples per output pixel axis (RenderRequest::supersampling as capped, stats.supersampling).
  // A pass whose sample spacing is a parameter in pixels (photon_gi's gather_step) counts it in output
  // pixels by scaling it with k, so its work per output pixel does not grow k^2-fold.
  int supersampling = 1;
  Camera camera;
  glm::mat4 view{1.f}, proj{1.f}, viewProj{1.f}, invViewProj{1.f};
  glm::vec3 eye{0.f};
  float exposure = 0.f;
  std::uint64_t seed = 0;
  glm::vec3 ambient{0.f};              // uniform sky radiance: request.ambient, or the map's average
  const Image* environment = nullptr;  // equirect radiance map (renderer/scene/Environment.h), or null
  std::string environmentKey;          // its digest, for cache keys
  // The raster's split of the map (renderer/shading/EnvironmentLights.h): its compact bright regions as
  // directional lights, which `direct` shadows, and the map without them (the residual), which
  // image-based lighting integrates and whose diffuse first hits the sky lights shade (photon_gi's
  // splats with sky_lights 0). Null, or without lights, when nothing was taken. The background and the reference see `environment` itself.
  std::shared_ptr<const EnvironmentLights> environmentLights;
  std::string environmentLightsKey;    // its options' key (with environmentKey: the split's digest)
  // The frame's lights: the scene's (same indices as scene.lights), then the environment's compact
  // lights, then its sky lights (EnvironmentLights::skyLights), which light diffuse lobes only.
  std::vector<Light> lights;
  int sceneLights = 0;  // how many of `lights` are the scene's
  // Meshes the shadow maps leave out: those whose shadows a planned pass supplies itself
  // (Technique::shadowMapExclusions, light_volumes' negative beams). Set with the frame's parameters,
  // before any pass validates them (Renderer::check, the frame's passParameters).
  std::set<int> shadowMapExclusions;
  // What image-based lighting integrates: the residual when the map was split, else the map.
  const Image* lightingEnvironment() const {
    return environmentLights && environmentLights->split() ? &environmentLights->residual : environment;
  }
  // How many of `lights` (the last ones) are sky lights.
  int skyLights() const { return environmentLights ? static_cast<int>(environmentLights->skyLights.size()) : 0; }
  // The key of what the raster lights with: the map, and the split's options when it took lights.
  std::string lightingEnvironmentKey() const {
    return environmentLights && (environmentLights->split() || !environmentLights->skyLights.empty())
               ? environmentKey + "|" + environmentLightsKey
               : environmentKey;
  }
  glm::vec3 target{0.f};               // the point looked at (for stats.camera)
  std::string cameraSource;            // "file", "auto", "request", or "request+file" / "request+auto" when partial
  // The frame's participating media: the scene's particle systems, then the request's (api/Media.h),
  // and their content digest (the cache key of derived media data).
  std::vector<api::ParticleSystem> media;
  std::string mediaKey;
};

// Reversed-Z, infinite far plane (see above).
glm::mat4 reversedZPerspective(float yfov, float aspect, float znear);
// Reversed-Z orthographic: depth 1 at znear, 0 at zfar.
glm::mat4 reversedZOrthographic(float xmag, float ymag, float znear, float zfar);
// The request's camera override if any, else the scene's camera, with the image's aspect.
// `environment` is the decoded request.environment (null when none).
FrameView makeFrameView(const Scene& scene, const api::RenderRequest& request, const Image* environment = nullptr);
// The unit direction the camera looks along (-z of its world matrix).
glm::vec3 viewForward(const FrameView& view);
// The frame's camera as the shaders read it (common/frame.glsl; FrameResources::beginFrame uploads it).
gpu::FrameConstants frameConstants(const FrameView& view);

}  // namespace radiant
