// Stores the light's distance measure: Euclidean distance to the light (point, spot) or the distance
// along the light direction from its origin plane (directional, orthographic).
//
// Coverage, as the reference's shadow rays see it (RayScene::passesThrough):
// - alphaMode MASK: a texel below the cutoff casts nothing (glTF 3.9.4);
// - alphaMode BLEND: the surface occludes a fraction alpha of the light. The map is binary, so the
//   fraction is dithered: a texel is kept when alpha exceeds its threshold in a 4x4 Bayer matrix
//   (ordered dithering; the stochastic-transparency shadow of Enderton et al. 2010 with a fixed
//   pattern), and the PCF kernel of the lookup averages the kept texels back into a transmittance
//   1 - alpha (exact over every 4x4 block; a 3x3 kernel sees it within +-1/9 per pixel).
// OPAQUE (the variant the pass draws opaque materials with): no material read and no discard, so
// that the depth test may run before the shader (a shader that can discard tests depth after it, and
// llvmpipe then shades every layer of layered geometry).
#include "common/material.glsl"

in vec3 v_position;
in vec2 v_uv0;
in vec2 v_uv1;
uniform int u_material;
uniform vec3 u_lightPosition;
uniform vec3 u_lightDirection;
uniform int u_orthographic;
layout(location = 0) out float o_distance;

// The 4x4 Bayer matrix's threshold (k + 0.5) / 16 of a texel.
float bayerThreshold(ivec2 texel) {
  const int bayer[16] = int[16](0, 8, 2, 10, 12, 4, 14, 6, 3, 11, 1, 9, 15, 7, 13, 5);
  return (float(bayer[(texel.y & 3) * 4 + (texel.x & 3)]) + 0.5) / 16.0;
}

void main() {
#ifndef OPAQUE
  SurfaceUv uv = SURFACE_UV_FRAGMENT(v_uv0, v_uv1);  // before any discard (common/material.glsl)
  Material m = materials[u_material];
  int mode = materialAlphaMode(m);
  if (mode != 0) {
    float alpha = decodeBaseColor(m, uv).a;
    if (materialMasked(m, alpha)) discard;
    if (mode == 2 && alpha <= bayerThreshold(ivec2(gl_FragCoord.xy))) discard;
  }
#endif
  o_distance = u_orthographic != 0 ? dot(v_position - u_lightPosition, u_lightDirection)
                                   : length(v_position - u_lightPosition);
}
