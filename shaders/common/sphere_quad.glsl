// A screen quad covering a sphere's projection conservatively (the screen rectangle of its
// view-aligned bounding box; the whole screen when a perspective camera is within reach of the
// sphere's near side, so the camera can enter it). Vertex k of 6 (two triangles); the fragment shaders
// recompute everything from the pixel's ray, so the quad's depth is irrelevant. Media techniques.
#ifndef RADIANT_COMMON_SPHERE_QUAD
#define RADIANT_COMMON_SPHERE_QUAD
vec4 sphereQuadVertex(vec3 centerWorld, float r, int k, mat4 view, mat4 proj, float znear, bool orthographic) {
  const vec3 c = (view * vec4(centerWorld, 1.0)).xyz;
  const vec2 corner = vec2((k == 1 || k == 2 || k == 4) ? 1.0 : 0.0, (k == 2 || k == 4 || k == 5) ? 1.0 : 0.0);
  vec2 lo = vec2(-1.0), hi = vec2(1.0);
  if (orthographic || -c.z - r > 1.001 * znear) {
    lo = vec2(1e30), hi = vec2(-1e30);
    for (int b = 0; b < 8; ++b) {
      const vec3 p = c + r * vec3((b & 1) != 0 ? 1.0 : -1.0, (b & 2) != 0 ? 1.0 : -1.0, (b & 4) != 0 ? 1.0 : -1.0);
      const vec4 clip = proj * vec4(p, 1.0);
      const vec2 ndc = clip.xy / clip.w;
      lo = min(lo, ndc), hi = max(hi, ndc);
    }
    lo = max(lo, vec2(-1.0)), hi = min(hi, vec2(1.0));
  }
  return vec4(mix(lo, hi, corner), 0.5, 1.0);
}
#endif
