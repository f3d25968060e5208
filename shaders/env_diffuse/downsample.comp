// Box-filters a cube map face by face (thesis 3.1: "both radiance and distance values are averaged,
// thus finally we have larger lights having the average radiance of the small lights and placed at
// their average position"). Radiance averages over all texels. Distance averages over the texels that
// see a surface; only a block that sees open sky (distance +inf) everywhere stays at infinity. (The
// thesis has no open sky. Letting one sky texel send the whole block to infinity would turn the edge
// of an opening into a strip of wall radiance reaching to infinity, which points displaced towards
// the opening see much larger than the wall really is: +40% on the Cornell box's front-facing
// receiver pixels.) Normals are summed over the same texels and renormalised. radiance.a receives the solid angle of
// the destination texel (used by the convolution and the point lights).
#include "env_diffuse/form_factor.glsl"
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
layout(rgba32f, binding = 0) readonly uniform imageCube u_srcRadiance;
layout(rgba32f, binding = 1) readonly uniform imageCube u_srcGeometry;
layout(rgba32f, binding = 2) writeonly uniform imageCube u_dstRadiance;
layout(rgba32f, binding = 3) writeonly uniform imageCube u_dstGeometry;
uniform int u_srcSize;
uniform int u_dstSize;
void main() {
  ivec3 id = ivec3(gl_GlobalInvocationID);
  if (id.x >= u_dstSize || id.y >= u_dstSize) return;
  int block = u_srcSize / u_dstSize;
  vec3 L = vec3(0.0);
  float d = 0.0;
  float surfaces = 0.0;
  vec3 n = vec3(0.0);
  for (int j = 0; j < block; ++j)
    for (int i = 0; i < block; ++i) {
      ivec3 s = ivec3(id.x * block + i, id.y * block + j, id.z);
      L += imageLoad(u_srcRadiance, s).rgb;
      vec4 g = imageLoad(u_srcGeometry, s);
      if (!isinf(g.x) && g.x < 1e30) {
        d += g.x;
        surfaces += 1.0;
        n += g.yzw;
      }
    }
  float inv = 1.0 / float(block * block);
  float h = 2.0 / float(u_dstSize);
  float solidAngle = cubeTexelSolidAngle(-1.0 + h * id.x, -1.0 + h * id.y, -1.0 + h * (id.x + 1), -1.0 + h * (id.y + 1));
  float ln = length(n);
  imageStore(u_dstRadiance, id, vec4(L * inv, solidAngle));
  float distance = surfaces > 0.0 ? d / surfaces : uintBitsToFloat(0x7f800000u);  // +inf: open sky
  imageStore(u_dstGeometry, id, vec4(distance, ln > 0.0 ? n / ln : vec3(0.0)));
}
