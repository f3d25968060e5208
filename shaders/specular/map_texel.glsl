// A texel of one face of a layered-distance-map cube as a surface point (the compute passes over the
// maps' texels: map_indirect.comp, map_sky.comp): the reference point plus the texel centre's direction
// times its stored distance, and its stored normal turned towards the reference point, the map's viewer.
#ifndef RADIANT_SPECULAR_MAP_TEXEL
#define RADIANT_SPECULAR_MAP_TEXEL
#include "common/cube_texels.glsl"  // faceDirection
#include "common/octahedral.glsl"

uniform vec3 u_reference;
uniform int u_face;
uniform int u_size;  // texels per face side

// g: the texel of specular_ldm_geometry (oct normal xy, distance z, object code w).
vec3 texelPoint(ivec2 px, vec4 g) {
  return u_reference + normalize(faceDirection(u_face, (vec2(px) + 0.5) / float(u_size) * 2.0 - 1.0)) * g.z;
}
vec3 texelNormal(vec4 g, vec3 x) {
  vec3 n = normalize(octDecode(g.xy));
  return dot(n, x - u_reference) > 0.0 ? -n : n;
}
#endif
