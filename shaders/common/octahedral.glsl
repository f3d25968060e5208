// Octahedral normal encoding (Cigolle et al. 2014): unit vector <-> [-1,1]^2. Used by the specular
// pass's distance maps and the G-buffer's coat normal (common/material.glsl).
#ifndef RADIANT_COMMON_OCTAHEDRAL
#define RADIANT_COMMON_OCTAHEDRAL
vec2 octEncode(vec3 n) {
  n /= abs(n.x) + abs(n.y) + abs(n.z);
  vec2 p = n.xy;
  if (n.z < 0.0) p = (1.0 - abs(n.yx)) * vec2(n.x >= 0.0 ? 1.0 : -1.0, n.y >= 0.0 ? 1.0 : -1.0);
  return p;
}
vec3 octDecode(vec2 p) {
  vec3 n = vec3(p, 1.0 - abs(p.x) - abs(p.y));
  if (n.z < 0.0) n.xy = (1.0 - abs(n.yx)) * vec2(n.x >= 0.0 ? 1.0 : -1.0, n.y >= 0.0 ? 1.0 : -1.0);
  return normalize(n);
}

#endif
