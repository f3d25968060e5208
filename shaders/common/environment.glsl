// The equirectangular environment, mapped exactly as renderer/scene/Environment.h maps it (nearest
// texel, row 0 = +Y, the image centre looks down -Z). Texture rows are uploaded top row first, so
// texel row v * height is the image's row.
#ifndef RADIANT_COMMON_ENVIRONMENT
#define RADIANT_COMMON_ENVIRONMENT
#include "common/constants.glsl"

vec3 environmentRadiance(sampler2D map, vec3 dir) {
  ivec2 size = textureSize(map, 0);
  float u = 0.5 + atan(dir.x, -dir.z) / (2.0 * PI);
  float v = acos(clamp(dir.y, -1.0, 1.0)) / PI;
  ivec2 texel = clamp(ivec2(vec2(u, v) * vec2(size)), ivec2(0), size - 1);
  return texelFetch(map, texel, 0).rgb;
}

// The mean radiance over a cone of directions `cone` radians wide about `dir`: what a ray that stands
// for a footprint of directions (a pixel's reflection off a curved mirror) integrates. The map carries a
// box-filtered mip chain (renderer/frame/FrameAllocation.cpp): level l's texel spans 2^l texels, i.e.
// 2^l pi / height radians of latitude, so the cone reads level log2(cone height / pi), bilinear and
// trilinear (u wraps). Cones up to a texel read the nearest texel, as environmentRadiance: a sharp
// reflection is unchanged, and a sun of a texel on a small mirror sphere gives each pixel its share of
// the sun instead of all or nothing at the sample that happens to hit it (issue 29).
vec3 environmentRadianceCone(sampler2D map, vec3 dir, float cone) {
  ivec2 size = textureSize(map, 0);
  float lod = log2(max(cone, 1e-30) * float(size.y) / PI);
  if (!(lod > 0.0)) return environmentRadiance(map, dir);
  float u = 0.5 + atan(dir.x, -dir.z) / (2.0 * PI);
  float v = acos(clamp(dir.y, -1.0, 1.0)) / PI;
  return textureLod(map, vec2(u, v), lod).rgb;
}
#endif
