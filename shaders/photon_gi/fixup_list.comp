// The fix-up list (gather.comp's u_list): the points still without a value after upsample.comp, packed
// x | y << 16. One invocation per output point: a full-resolution pixel marked 1 in i_fixup (u_step 1),
// or a block of the fix-up cascade (u_step > 1) whose centre pixel is marked 1. Header: the indirect
// dispatch's workgroup counts (x, 1, 1), x = ceil(count / 64) counted as entries 0, 64, 128, ... are
// taken, and the count. The CPU zeroes x and the count and sets y = z = 1 before this pass.
layout(local_size_x = 8, local_size_y = 8) in;
layout(r32f, binding = 1) uniform readonly image2D i_fixup;
layout(std430, binding = 4) buffer FixupList { uint listHeader[4]; uint listPoints[]; };

uniform ivec2 u_size;     // full resolution
uniform ivec2 u_outSize;  // the output grid: u_size, or the cascade's blocks
uniform int u_step;

void main() {
  ivec2 out_ = ivec2(gl_GlobalInvocationID.xy);
  if (out_.x >= u_outSize.x || out_.y >= u_outSize.y) return;
  ivec2 px = min(out_ * u_step + u_step / 2, u_size - 1);
  if (imageLoad(i_fixup, px).r != 1.0) return;
  uint i = atomicAdd(listHeader[3], 1u);
  if (i % 64u == 0u) atomicAdd(listHeader[0], 1u);
  listPoints[i] = uint(out_.x) | (uint(out_.y) << 16);
}
