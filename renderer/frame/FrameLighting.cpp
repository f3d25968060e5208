#include "renderer/frame/FrameLighting.h"

#include "renderer/scene/StudioEnvironment.h"

namespace radiant {

FrameLighting frameLighting(const Scene& scene, const api::RenderRequest& request, const Image* environment) {
  FrameLighting out{request, environment, "", ""};
  const bool sceneLit = !scene.lights.empty() || scene.features.hasEmissive();
  const bool ambientGiven = request.ambient != glm::vec3(0.f);
  const std::string own = !scene.lights.empty() && scene.features.hasEmissive() ? "lights and emissive surfaces"
                          : !scene.lights.empty()                               ? "lights"
                          : scene.features.hasEmissive()                        ? "emissive surfaces"
                                                                                : "";
  std::string sky;
  if (!request.environment.empty()) {
    sky = "environment";
    out.reason = "the request's environment map";
  } else if (ambientGiven) {
    sky = "ambient";
    out.reason = "the request's ambient";
  } else if (request.defaultLighting && scene.lights.empty()) {
    sky = "default";
    out.request.environment = kStudioEnvironmentKey;
    out.environment = &studioEnvironment();
    out.reason = !sceneLit ? "the scene has no lights or emissive surfaces"
                           : "the scene has no punctual lights (its emissive surfaces light little beyond themselves)";
    out.reason += ", and the request names no ambient or environment";
  } else if (!request.defaultLighting) {
    out.reason = "default_lighting is false";
  } else {
    out.reason = "the scene has punctual lights, a lighting set-up of its own (a room such as the Cornell boxes)";
  }
  out.lighting = sceneLit ? (sky.empty() ? "scene" : "scene+" + sky) : (sky.empty() ? "none" : sky);
  if (!own.empty()) out.reason += (sky.empty() ? ": the scene's own " : "; with the scene's own ") + own;
  else if (sky.empty()) out.reason += ", and the scene has no lights or emissive surfaces: nothing";
  return out;
}

}  // namespace radiant
