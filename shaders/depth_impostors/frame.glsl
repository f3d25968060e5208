// The impostor frame of a block (renderer/techniques/depth_impostors/Blocks.h): rays cross it along
// the axis a (fixed: an orthographic camera or a directional light; else from the eye or the light
// through the block's centre), and the orthonormal basis (u, v) of a (Duff et al. 2017, the twin of
// rt::ShadingFrame::fromNormal and impostors::impostorBasis) spans its tile of res x res texels over
// [-R, R]^2 around the centre. Tiles are laid out row by row, tilesX per row, in one atlas.
#ifndef RADIANT_DEPTH_IMPOSTORS_FRAME
#define RADIANT_DEPTH_IMPOSTORS_FRAME
#include "common/shared.h"
#include "depth_impostors/shared.h"

layout(std430, binding = kBindingImpostorBlocks) readonly buffer Blocks { ImpostorBlock blocks[]; };

vec3 impostorAxis(int mode, vec3 axisOrOrigin, vec3 center) {
  return mode == 0 ? axisOrOrigin : normalize(center - axisOrOrigin);
}

void impostorBasis(vec3 n, out vec3 u, out vec3 v) {
  const float s = n.z >= 0.0 ? 1.0 : -1.0;
  const float a = -1.0 / (s + n.z);
  const float b = n.x * n.y * a;
  u = vec3(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
  v = vec3(b, s + n.y * n.y * a, -n.y);
}

ivec2 tileOrigin(int tile, int tilesX, int res) { return ivec2(tile % tilesX, tile / tilesX) * res; }

// The texel of tile `tile` that local plane coordinates l (metres, |l| < R) fall in.
ivec2 tileTexel(int tile, int tilesX, int res, vec2 l, float R) {
  const ivec2 t = ivec2(floor((l / R * 0.5 + 0.5) * float(res)));
  return tileOrigin(tile, tilesX, res) + clamp(t, ivec2(0), ivec2(res - 1));
}
#endif
