// Cube-map texel geometry shared by the passes that address cube maps texel by texel (the caustic
// cubes, the specular pass's layered distance maps): GL 4.5's face selection (section 8.13, table 8.19).
#ifndef RADIANT_COMMON_CUBE_TEXELS
#define RADIANT_COMMON_CUBE_TEXELS

// The face whose frustum holds direction d (the major axis, GL's face order +x -x +y -y +z -z).
int majorFace(vec3 d) {
  vec3 a = abs(d);
  if (a.x >= a.y && a.x >= a.z) return d.x >= 0.0 ? 0 : 1;
  if (a.y >= a.z) return d.y >= 0.0 ? 2 : 3;
  return d.z >= 0.0 ? 4 : 5;
}

// Direction of a point (s, t) in [-1, 1]^2 of cube face `face` (GL 4.5 table 8.19, inverted).
vec3 faceDirection(int face, vec2 st) {
  if (face == 0) return vec3(1.0, -st.y, -st.x);
  if (face == 1) return vec3(-1.0, -st.y, st.x);
  if (face == 2) return vec3(st.x, 1.0, st.y);
  if (face == 3) return vec3(st.x, -1.0, -st.y);
  if (face == 4) return vec3(st.x, -st.y, 1.0);
  return vec3(-st.x, -st.y, -1.0);
}

// The centre direction of the texel of a cube map of side `res` that direction d falls in.
vec3 cubeTexelCentre(vec3 d, float res) {
  int face = majorFace(d);
  vec3 a = abs(d);
  vec2 sc;
  float ma;
  if (face == 0) { sc = vec2(-d.z, -d.y); ma = a.x; }
  else if (face == 1) { sc = vec2(d.z, -d.y); ma = a.x; }
  else if (face == 2) { sc = vec2(d.x, d.z); ma = a.y; }
  else if (face == 3) { sc = vec2(d.x, -d.z); ma = a.y; }
  else if (face == 4) { sc = vec2(d.x, -d.y); ma = a.z; }
  else { sc = vec2(-d.x, -d.y); ma = a.z; }
  vec2 st = sc / max(ma, 1e-30);
  vec2 texel = clamp(floor((st * 0.5 + 0.5) * res), vec2(0.0), vec2(res - 1.0));
  return faceDirection(face, (texel + 0.5) / res * 2.0 - 1.0);
}
#endif
