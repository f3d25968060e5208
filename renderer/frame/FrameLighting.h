#pragma once
// The first stage of a frame (issue 33: the Renderer as a driver over stages): which light the frame
// has. Rendered without ambient or environment, a scene is lit by the studio map
// (renderer/scene/StudioEnvironment.h) as if the request had named it when it brings no punctual light,
// whatever its emission (an emissive visor or screen lights little around it; every viewer shows such
// a model under its environment). Punctual lights of any type are a lighting set-up of their own (a
// room such as the Cornell boxes, a sun over an analytic test scene, a key light as GlamVelvetSofa's,
// which the reference path tracer renders near-black too): they stay the frame's only light, so that
// the default frame and the reference see the same scene. docs/API.md, "Default lighting".
#include <string>

#include "api/Types.h"
#include "renderer/Image.h"
#include "renderer/scene/Scene.h"

namespace radiant {

struct FrameLighting {
  api::RenderRequest request;          // the request the frame renders (environment = the studio's key when chosen)
  const Image* environment = nullptr;  // its environment map (the studio's when chosen, else the caller's)
  std::string lighting;                // stats.lighting: scene, scene+ambient, scene+environment, default, none, ...
  std::string reason;                  // stats.lighting_reason: why, in words
};

// Pure: no GL, no state. `environment` is the map the caller decoded for request.environment (or null).
FrameLighting frameLighting(const Scene& scene, const api::RenderRequest& request, const Image* environment);

}  // namespace radiant
