// Builds the area lights of one receiver from its M x M cube map (thesis Algorithm 1, the per-texel
// set-up hoisted out of the per-fragment loop): the texel corners' directions from the reference point
// scaled by their distances, the texel's radiance, and the point-light form of the same texel.
// A corner's distance is the average of the (up to four) texels that share it, so neighbouring quads
// share corners and the environment is one closed mesh of quads; the four texels are read with nearest
// filtering a quarter texel from the corner in each quadrant, which crosses face seams by itself (at the
// eight cube corners one of the three texels is read twice).
#include "env_diffuse/form_factor.glsl"
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
layout(rgba32f, binding = 0) readonly uniform imageCube u_radiance;
layout(rgba32f, binding = 1) readonly uniform imageCube u_geometry;
layout(binding = 0) uniform samplerCube t_geometry;  // the same texture as u_geometry, nearest filter

struct EnvQuad {
  vec4 corner[4];
  vec4 radiance;
  vec4 vplPosition;
  vec4 vplNormalArea;
};
layout(std430, binding = 4) writeonly buffer EnvQuads { EnvQuad envQuads[]; };
uniform int u_size;
uniform vec3 u_origin;

float finiteDistance(vec3 dir, inout float count) {
  float d = textureLod(t_geometry, dir, 0.0).x;
  if (isinf(d) || d > 1e30) return 0.0;
  count += 1.0;
  return d;
}

// The corner's distance: the average over the adjacent texels that see a surface (as downsample.comp
// averages distances); at infinity only when all of them see open sky.
vec4 cornerPoint(int face, float sc, float tc) {
  float e = 0.5 / float(u_size);
  float count = 0.0;
  float d = finiteDistance(cubeFaceDirection(face, sc - e, tc - e), count) +
            finiteDistance(cubeFaceDirection(face, sc + e, tc - e), count) +
            finiteDistance(cubeFaceDirection(face, sc + e, tc + e), count) +
            finiteDistance(cubeFaceDirection(face, sc - e, tc + e), count);
  vec3 w = normalize(cubeFaceDirection(face, sc, tc));
  return count == 0.0 ? vec4(w, 0.0) : vec4(u_origin + w * (d / count), 1.0);
}

void main() {
  ivec3 id = ivec3(gl_GlobalInvocationID);
  if (id.x >= u_size || id.y >= u_size) return;
  int face = id.z;
  float h = 2.0 / float(u_size);
  float u0 = -1.0 + h * id.x, u1 = u0 + h, v0 = -1.0 + h * id.y, v1 = v0 + h;
  int q = (face * u_size + id.y) * u_size + id.x;
  // Order (u0,v0) (u0,v1) (u1,v1) (u1,v0): (R_l x R_l+1) . n > 0 for a receiver facing the texel from
  // the reference point, the sign convention of formFactorQuadToPoint (checked for every face in
  // tests/unit/env_diffuse).
  envQuads[q].corner[0] = cornerPoint(face, u0, v0);
  envQuads[q].corner[1] = cornerPoint(face, u0, v1);
  envQuads[q].corner[2] = cornerPoint(face, u1, v1);
  envQuads[q].corner[3] = cornerPoint(face, u1, v0);
  vec4 L = imageLoad(u_radiance, id);
  vec4 g = imageLoad(u_geometry, id);
  envQuads[q].radiance = vec4(L.rgb, 0.0);
  vec3 w = normalize(cubeFaceDirection(face, u0 + 0.5 * h, v0 + 0.5 * h));
  float solidAngle = L.a;
  if (isinf(g.x) || g.x > 1e30) {
    envQuads[q].vplPosition = vec4(w, 0.0);
    envQuads[q].vplNormalArea = vec4(-w, solidAngle);
  } else {
    vec3 n = dot(g.yzw, g.yzw) > 0.0 ? normalize(g.yzw) : -w;
    envQuads[q].vplPosition = vec4(u_origin + w * g.x, 1.0);
    envQuads[q].vplNormalArea = vec4(n, vplArea(solidAngle, g.x, dot(n, -w)));
  }
}
