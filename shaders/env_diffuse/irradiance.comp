// Classic diffuse environment mapping (thesis 3.2, first column): the irradiance at the reference
// point for every normal, E(n) = sum_j L_j cos+(n . w_j) dw_j, pre-convolved once so that shading is a
// single lookup. The source is the cube map box-filtered to a small size whose radiance.a holds dw_j.
#include "env_diffuse/form_factor.glsl"
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
layout(rgba32f, binding = 0) readonly uniform imageCube u_source;
layout(rgba32f, binding = 2) writeonly uniform imageCube u_irradiance;
uniform int u_sourceSize;
uniform int u_size;
void main() {
  ivec3 id = ivec3(gl_GlobalInvocationID);
  if (id.x >= u_size || id.y >= u_size) return;
  float h = 2.0 / float(u_size);
  vec3 n = normalize(cubeFaceDirection(id.z, -1.0 + h * (id.x + 0.5), -1.0 + h * (id.y + 0.5)));
  float hs = 2.0 / float(u_sourceSize);
  vec3 E = vec3(0.0);
  for (int f = 0; f < 6; ++f)
    for (int j = 0; j < u_sourceSize; ++j)
      for (int i = 0; i < u_sourceSize; ++i) {
        vec3 w = normalize(cubeFaceDirection(f, -1.0 + hs * (i + 0.5), -1.0 + hs * (j + 0.5)));
        float c = dot(n, w);
        if (c <= 0.0) continue;
        vec4 L = imageLoad(u_source, ivec3(i, j, f));
        E += L.rgb * (c * L.a);
      }
  imageStore(u_irradiance, id, vec4(E, 1.0));
}
