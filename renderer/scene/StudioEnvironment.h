#pragma once
// The default lighting of a scene that brings none (no lights, no emissive surfaces, and a request
// with no ambient and no environment): a neutral photo studio as an equirectangular radiance map,
// mapped like every environment (renderer/scene/Environment.h). Grey (R = G = B) everywhere, so it
// never tints a material; its radiance is chosen so that a white Lambertian surface comes out near
// display white (about 0.5-1.3 linear) at exposure 0. See docs/API.md, "Default lighting".
//
//   fill:   upper hemisphere L = 0.5 + 0.3 y (0.5 at the horizon, 0.8 at the zenith: a soft
//           overhead softbox look), lower hemisphere L = 0.2 (a dark studio floor), blended over
//           |y| < 0.05 so the horizon has no seam;
//   key:    a soft round area light of angular radius 15 degrees towards (1, 1.25, 1)/|.| (above,
//           in front of and to the right of the automatic camera, which looks down -Z from +Z),
//           radiance 8 at its centre falling off as a smoothstep to 0 at its rim.
// Its solid-angle mean radiance is 0.466 (environmentAverage()), the value passes that model
// a uniform sky (ambient occlusion) use; the reference path tracer samples the map itself.
#include <string>

#include <glm/glm.hpp>

#include "renderer/Image.h"

namespace radiant {

constexpr const char* kStudioEnvironmentKey = "default:studio-1";  // cache key of the map (bump when it changes)
constexpr int kStudioEnvironmentWidth = 256, kStudioEnvironmentHeight = 128;

// The studio's radiance in world direction `dir` (unit), before texel quantisation.
float studioRadiance(const glm::vec3& dir);
// The map, built once (thread-safe).
const Image& studioEnvironment();

}  // namespace radiant
