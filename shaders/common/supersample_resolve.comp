// The resolve of a supersampled AOV on the GPU (Renderer's readback; renderer/Renderer.cpp
// resolveSupersampled is the CPU twin and says what is resolved how): each output texel is the mean of
// the u_count x u_count samples from u_first within its k x k block, the whole block for radiance and
// reflectance (box average), the one sample nearest the pixel centre for geometry. Both in GL's row
// order (bottom first), so u_first.y is the CPU's k - 1 - k / 2 for the centre sample. Only the resolved
// frame is read back: k^2 times fewer bytes over the bus and no per-sample loop on the CPU.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D t_samples;
layout(rgba32f, binding = 0) writeonly uniform image2D i_resolved;
uniform ivec2 u_outSize;
uniform int u_k;
uniform ivec2 u_first;
uniform int u_count;

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(p, u_outSize))) return;
  vec4 sum = vec4(0.0);
  for (int sy = 0; sy < u_count; ++sy)
    for (int sx = 0; sx < u_count; ++sx) sum += texelFetch(t_samples, p * u_k + u_first + ivec2(sx, sy), 0);
  imageStore(i_resolved, p, sum / float(u_count * u_count));
}
