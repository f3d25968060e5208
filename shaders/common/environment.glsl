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
#endif
