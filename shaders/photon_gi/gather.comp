// The gather baseline: per pixel, the sum over the photons (and coverage points) of the 27 grid cells
// around its surface point (photon_gi/grid.glsl), with the same kernel and surface test as the splats
// (photon.glsl). The walk meets every photon whose kernel reaches the pixel exactly once (grid.glsl).
#include "photon_gi/grid.glsl"
#include "photon_gi/photon.glsl"
#include "photon_gi/surface.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(rgba32f, binding = 0) uniform image2D i_accum;
// u_list = 1: the points to gather at, packed x | y << 16 (fixup_list.comp); count at [3].
layout(std430, binding = 4) readonly buffer FixupList { uint listHeader[4]; uint listPoints[]; };

uniform ivec2 u_size;     // the G-buffer's (full) resolution
// u_step > 1: one invocation per step x step block, at the block's centre pixel, written at the block's
// index (upsample.comp spreads it). u_list = 1: one invocation per entry of the fix-up list (pixels, or
// with u_step > 1 block indices, that upsample.comp left without a value), dispatched indirectly with
// as many workgroups as the list needs: the fix-ups are scattered edge pixels, and a full-resolution
// dispatch that skipped the others paid for whole SIMD rows around each of them.
uniform int u_step;
uniform ivec2 u_outSize;
uniform int u_list;
uniform int u_accumulate;

void main() {
  ivec2 out_;
  if (u_list != 0) {
    uint i = gl_WorkGroupID.x * 64u + gl_LocalInvocationIndex;
    if (i >= listHeader[3]) return;
    uint point = listPoints[i];
    out_ = ivec2(int(point & 0xffffu), int(point >> 16));
  } else {
    out_ = ivec2(gl_GlobalInvocationID.xy);
  }
  if (out_.x >= u_outSize.x || out_.y >= u_outSize.y) return;
  ivec2 px = min(out_ * u_step + u_step / 2, u_size - 1);
  SplatSurface s;
  vec4 acc = vec4(0.0);
  if (loadSurface(px, s)) {
    ivec3 c = photonCellOf(s.x);
    for (int k = 0; k < 27; ++k) {
      uint begin, end;
      if (!photonCellSlice(s.x, c, k, begin, end)) continue;
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
