// The splatting baseline (thesis Fig. 6.1; Wyman & Davis 2006): every valid photon hit of the same
// hit image is drawn as a disk of world radius u_splatRadius in its receiver's tangent plane, with
// the uniform kernel dPhi / (pi r^2), into every face of the caustic cube map it touches.
layout(points) in;
layout(triangle_strip, max_vertices = 24) out;
#include "caustics/grid.glsl"
#include "caustics/cube.glsl"

flat in ivec2 v_texel[];
out vec3 g_irradiance;
out vec2 g_disk;
out vec3 g_position;
uniform float u_splatRadius;

void main() {
  ivec2 t = v_texel[0];
  if (!vertexValid(t)) return;
  vec3 p = vertexHit(t);
  vec3 n = vertexNormal(t);
  n = dot(n, n) > 0.0 ? normalize(n) : normalize(-p);
  vec3 a = normalize(abs(n.y) < 0.99 ? cross(n, vec3(0, 1, 0)) : cross(n, vec3(1, 0, 0)));
  vec3 b = cross(n, a);
  const float kPi = 3.14159265358979;
  vec3 E = vertexPower(t) / (kPi * u_splatRadius * u_splatRadius);
  const vec2 corners[4] = vec2[4](vec2(-1, -1), vec2(1, -1), vec2(-1, 1), vec2(1, 1));
  vec4 q[4];
  for (int f = 0; f < 6; ++f) {
    vec3 corner[4];
    for (int i = 0; i < 4; ++i) {
      corner[i] = p + u_splatRadius * (corners[i].x * a + corners[i].y * b);
      q[i] = u_faceViewProj[f] * vec4(corner[i], 1.0);
    }
    if (outsideFace(q, 4)) continue;
    for (int i = 0; i < 4; ++i) {
      gl_Layer = u_cubeLayer + f;
      g_irradiance = E;
      g_disk = corners[i];
      g_position = corner[i];
      gl_Position = q[i];
      EmitVertex();
    }
    EndPrimitive();
  }
}
