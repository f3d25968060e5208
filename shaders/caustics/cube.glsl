// Drawing into the caustic cube map (one cube per generator, centred on its reference point c_G):
// the six face transforms of the distance maps (ShadowMapsPass::cubeFaceViewProj at the origin, so
// positions relative to c_G go in as they are) and face culling for the geometry shaders.
#ifndef RADIANT_CAUSTICS_CUBE
#define RADIANT_CAUSTICS_CUBE
uniform mat4 u_faceViewProj[6];
uniform int u_cubeLayer;       // 6 * generator: first layer-face of this generator's cube
uniform float u_causticResolution;  // C

// True when the clip-space points all lie outside one plane of the face's frustum (x, y in [-w, w],
// in front of the eye): the primitive cannot touch the face.
bool outsideFace(vec4 q[4], int n) {
  bvec4 allOut = bvec4(true);
  bool behind = true;
  for (int i = 0; i < n; ++i) {
    allOut = bvec4(allOut.x && q[i].x < -q[i].w, allOut.y && q[i].x > q[i].w,
                   allOut.z && q[i].y < -q[i].w, allOut.w && q[i].y > q[i].w);
    behind = behind && q[i].w <= 0.0;
  }
  return any(allOut) || behind;
}

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

// Solid angle of a face texel whose centre is at (u, v) on the face plane at unit distance, side 2 / C.
float texelSolidAngle(vec2 uv) {
  float s = 2.0 / u_causticResolution;
  float r2 = 1.0 + dot(uv, uv);
  return s * s / (r2 * sqrt(r2));
}
// Mean distance from c_G of the receivers deposited into a caustic cube texel (deposit.frag), 0 where
// nothing was deposited.
float depositDistance(vec4 texel) {
  float w = texel.r + texel.g + texel.b;
  return w > 0.0 ? texel.a / w : 0.0;
}
#endif
