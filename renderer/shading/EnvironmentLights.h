#pragma once
// The environment's compact bright regions (a sun, a studio key) as directional lights for the raster,
// and the map without them. Image-based lighting (renderer/shading/ImageBasedLighting.h) has no
// visibility: a sun in the prefiltered map and the SH irradiance casts no shadow, has no specular
// occlusion, and its 64 x 32 GGX prefilter turns a 0.5 degree sun of radiance 1e5 into sparkle. So the
// raster splits the map exactly in two (issue 29, item 3):
//
//   L(w) = R(w) + S(w),   R(w) = L(w) min(1, T / Y(w)),   S(w) = L(w) max(0, 1 - T / Y(w)),
//
// with Y the luminance and T = threshold x the map's solid-angle-weighted mean luminance. S is the part
// above the threshold; its texels are grouped into connected regions (4-neighbours, u wraps), and each
// region that is compact (solid angle <= maxSolidAngle) and carries at least minPowerFraction of the
// map's power becomes one directional light:
//   E = sum over its texels of S dw   (the irradiance it gives a surface facing it; the cosine is taken
//                                      at the region's centre, exact to 1 - cos(radius)),
//   direction: the E-weighted mean of its texel directions, angular radius: the uniform cap with the same
//                                      E-weighted mean cosine about it, acos(2 mean cos - 1) (a uniform
//                                      disc: its own radius; a core in a halo: the core's), at least a texel.
// The raster lights with R through image-based lighting and the lights through `direct` with shadow
// maps; regions not taken (too broad, too weak, beyond maxLights) keep their full radiance in R. Every
// texel's light is counted once: R + sum of the lights' S = L per texel, per channel (tested). The
// reference path tracer and the background see L itself.
//
// Sky lights (skyLights > 0): the residual R itself, partitioned by median cut (P. Debevec, "A Median
// Cut Algorithm for Light Probe Sampling", SIGGRAPH 2005 poster): the map's rectangle is split
// recursively along its longer side (the width measured at the rectangle's mean latitude, cos-scaled)
// where the luminous power Y(R) dw halves, always splitting the region of most power, until there are
// skyLights regions (the first cut is the horizon); each becomes a directional light from its
// power-weighted mean direction d with the region's vector irradiance along d, sum R (w . d) dw (rgb),
// shaded as the cap of the region's mean cosine clipped by the receiver's horizon. They carry R's
// diffuse light only (L(sky)DE; the frame shades them with Dirac specular lobes, its glossy part
// staying image-based lighting's L(sky)GE): with shadow maps the broad sky then has visibility (contact shadows), which photon_gi's first-hit sky photons had only
// at the scale of their kernel (docs/TECHNIQUES.md, direct, "Sky lights").
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "renderer/Image.h"
#include "renderer/raytracing/Cancel.h"
#include "renderer/scene/Scene.h"

namespace radiant {

struct EnvironmentLightOptions {
  int maxLights = 4;                // 0: no split (R = L)
  float threshold = 10.f;           // T in multiples of the map's mean luminance
  float maxSolidAngle = 0.1f;       // sr (a cone of about 10 degrees' radius)
  float minPowerFraction = 0.01f;   // of the map's luminous power
  int skyLights = 0;                // median-cut lights of the residual (0: none)
  std::string key() const;          // for cache keys
};

struct EnvironmentLights {
  std::vector<Light> lights;  // directional: color = E (rgb irradiance), intensity 1, angularRadius set
  Image residual;             // R, the map's size and channels (empty when no light was taken)
  float threshold = 0.f;      // T (luminance)
  float fraction = 0.f;       // the lights' share of the map's luminous power
  // The residual's median-cut lights (directional, color = sum R (w . d) dw, intensity 1; angularRadius
  // the cap with the region's mean cosine): empty unless options.skyLights > 0 (the map itself when no
  // compact light was taken). Together they give a surface that sees whole regions the residual's
  // cosine-weighted irradiance (their vector irradiances sum to the residual's).
  std::vector<Light> skyLights;
  bool split() const { return !lights.empty(); }
  // The share of `map`'s radiance in direction `dir` (towards the sky) that the residual keeps: T / Y
  // in the lights' texels, 1 elsewhere (photon_gi scales its first-hit sky photons by it).
  float residualShare(const Image& map, const glm::vec3& dir) const;
};

// Linear in the map's texels; `cancel` is polled every 64 rows and every 65,536 texels of a region.
EnvironmentLights extractEnvironmentLights(const Image& map, const EnvironmentLightOptions& options = {},
                                           const rt::Cancel& cancel = {});

}  // namespace radiant
