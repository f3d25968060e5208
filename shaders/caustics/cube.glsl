// Drawing into the caustic cube map (one cube per generator, centred on its reference point c_G):
// the six face transforms of the distance maps (ShadowMapsPass::cubeFaceViewProj at the origin, so
// positions relative to c_G go in as they are) and face culling for the geometry shaders.
#ifndef RADIANT_CAUSTICS_CUBE
#define RADIANT_CAUSTICS_CUBE
#include "common/cube_texels.glsl"  // majorFace, faceDirection, cubeTexelCentre
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
