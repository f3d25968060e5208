// The gather baseline: per pixel, the sum over the photons (and coverage points) of the 27 grid cells
// around its surface point, with the same kernel and surface test as the splats (photon.glsl). Cells
// are at least the largest kernel radius, so no photon whose kernel reaches the pixel is missed.
#include "photon_gi/photon.glsl"
#include "photon_gi/surface.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(std430, binding = 6) readonly buffer Cells { uint cellStart[]; };
layout(rgba32f, binding = 0) uniform image2D i_accum;
layout(r32f, binding = 1) uniform readonly image2D i_fixup;

uniform vec3 u_gridOrigin;
uniform float u_cellSize;
uniform ivec3 u_gridDims;
uniform ivec2 u_size;     // the G-buffer's (full) resolution
// u_step > 1: one invocation per step x step block, at the block's centre pixel, written at the block's
// index (upsample.comp spreads it). u_fixup = 1: full resolution, only the pixels upsample.comp marked
// (i_fixup 1; 2 is a pixel its neighbour fill gave a value).
// u_fixup = 2: block samples as for u_step > 1, but only at the blocks whose centre pixel is marked (the
// fix-up cascade of a supersampled frame, Splatting.cpp); the others get alpha -1, no sample.
uniform int u_step;
uniform ivec2 u_outSize;
uniform int u_fixup;
// This dispatch's slice of every cell: entries [u_sliceBegin, u_sliceBegin + u_sliceLength) of it.
// llvmpipe ends an invocation's loops after 65535 iterations in total (its loop limiter), so the CPU
// splits the cells into slices of at most 27 * u_sliceLength candidates per pixel and dispatches once
// per slice, accumulating (docs/DEVELOPMENT.md).
uniform uint u_sliceBegin;
uniform uint u_sliceLength;
uniform int u_accumulate;

void main() {
  ivec2 out_ = ivec2(gl_GlobalInvocationID.xy);
  if (out_.x >= u_outSize.x || out_.y >= u_outSize.y) return;
  if (u_fixup == 1 && imageLoad(i_fixup, out_).r != 1.0) return;  // 0 filled, 2 filled by a neighbour
  ivec2 px = min(out_ * u_step + u_step / 2, u_size - 1);
  if (u_fixup == 2 && imageLoad(i_fixup, px).r != 1.0) {
    imageStore(i_accum, out_, vec4(0.0, 0.0, 0.0, -1.0));
    return;
  }
  SplatSurface s;
  vec4 acc = vec4(0.0);
  if (loadSurface(px, s)) {
    ivec3 c = ivec3(floor((s.x - u_gridOrigin) / u_cellSize));
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          ivec3 q = c + ivec3(dx, dy, dz);
          if (any(lessThan(q, ivec3(0))) || any(greaterThanEqual(q, u_gridDims))) continue;
          int cell = (q.z * u_gridDims.y + q.y) * u_gridDims.x + q.x;
          uint begin = cellStart[cell] + u_sliceBegin, end = min(cellStart[cell + 1], begin + u_sliceLength);
          for (uint i = begin; i < end; ++i) {
            GpuPhoton p = photons[i];
            if (p.power.a > 0.0) acc.a += coverageContribution(p, s);
            else acc.rgb += photonContribution(p, s);
          }
        }
  }
  if (u_accumulate != 0) acc += imageLoad(i_accum, out_);
  imageStore(i_accum, out_, acc);
}
