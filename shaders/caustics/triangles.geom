// Caustic triangles (thesis 6.1.2): each triangle of the photon hit image whose three vertices are
// valid photons on one surface is drawn into every face of the caustic cube map it touches, with the
// vertices' irradiance I_v interpolated (perspective-correct, so linearly on the receiver triangle:
// Gouraud, thesis 6.1.2). Additive blending. Invalid vertices drop their triangles.
//
// The focus (thesis 6.2, "oversampling"): a rasterised triangle deposits I at the texel centres it
// covers, so one smaller than a texel lands on one texel or none, and an island of them (a focus) can
// vanish altogether or be amplified many times. Triangles below a quarter of a texel's area (and at
// exactly zero area, where I_v is undefined) deposit their power instead, conserving it exactly:
// Phi_t = A_t (I_a + I_b + I_c) / 3, written as sum_v dPhi_v (A_t / sum A_v) / (3 k), which stays
// finite as the areas go to 0 (when a vertex's whole neighbourhood has zero area, its power is shared
// equally by its triangles). It goes to the four texels around the centroid with bilinear (tent)
// weights, each divided by its texel's area on the receiver, Omega_texel d^2 / cos: a dense field of
// small triangles then reconstructs smoothly instead of aliasing to one texel each. Larger triangles
// are rasterised: a regular grid of them tiles the face and covers every texel centre exactly once,
// which the tent does not (measured on the slab's caustic with triangles of 0.8 texels: rasterised,
// exact to float rounding; tent-deposited, ripples of 18%). At a quarter texel an island of triangles
// too small to cover a texel centre holds at most four of them. (With 1/64 as the bound, a paraxial
// focus lost all of its power: its slivers were between 1/64 and 1 texel.)
const float kPointTexels = 0.25;

layout(triangles) in;
layout(triangle_strip, max_vertices = 18) out;  // 6 faces x 3, or 4 texel quads x 4
#include "caustics/grid.glsl"
#include "caustics/cube.glsl"

flat in ivec2 v_texel[];
out vec3 g_irradiance;
out vec2 g_disk;
out vec3 g_position;

layout(binding = 3) uniform sampler2D t_vertex;  // rgb I_v, a sum A_t (area.comp)
uniform float u_areaWeight;

void main() {
  ivec2 t[3] = ivec2[3](v_texel[0], v_texel[1], v_texel[2]);
  if (!triangleValid(t[0], t[1], t[2])) return;
  vec3 p[3] = vec3[3](vertexHit(t[0]), vertexHit(t[1]), vertexHit(t[2]));
  vec4 V[3] = vec4[3](texelFetch(t_vertex, t[0], 0), texelFetch(t_vertex, t[1], 0), texelFetch(t_vertex, t[2], 0));
  vec3 mid = (p[0] + p[1] + p[2]) / 3.0;
  int face = majorFace(mid);
  vec4 q[4];
  for (int i = 0; i < 3; ++i) q[i] = u_faceViewProj[face] * vec4(p[i], 1.0);
  float texels2 = 0.0;  // area on the mid's face, in texels
  bool inFront = q[0].w > 0.0 && q[1].w > 0.0 && q[2].w > 0.0;
  if (inFront) {
    vec2 a = q[0].xy / q[0].w, b = q[1].xy / q[1].w, c = q[2].xy / q[2].w;
    vec2 ab = b - a, ac = c - a;
    texels2 = 0.5 * abs(ab.x * ac.y - ab.y * ac.x) * 0.25 * u_causticResolution * u_causticResolution;
  }
  if (inFront && texels2 < kPointTexels) {
    float At = triangleArea(t[0], t[1], t[2]);
    vec3 phi = vec3(0.0);
    for (int i = 0; i < 3; ++i) {
      float share;
      if (V[i].a > 0.0) {
        share = At / V[i].a;
      } else {
        int count;
        adjacentArea(t[i], count);
        share = 1.0 / float(max(count, 1));
      }
      phi += vertexPower(t[i]) * share;
    }
    phi /= 3.0 * u_areaWeight;
    vec4 qc = u_faceViewProj[face] * vec4(mid, 1.0);
    vec2 ndc = qc.xy / qc.w;
    vec2 pos = (ndc * 0.5 + 0.5) * u_causticResolution - 0.5;  // in texel centres
    vec2 base = floor(pos), f = pos - base;
    vec3 n = vertexNormal(t[0]) + vertexNormal(t[1]) + vertexNormal(t[2]);
    float cosR = dot(n, n) > 0.0 ? abs(dot(normalize(n), normalize(mid))) : 1.0;
    float d2 = dot(mid, mid);
    float h = 1.0 / u_causticResolution;  // half a texel in NDC
    const vec2 corners[4] = vec2[4](vec2(-1, -1), vec2(1, -1), vec2(-1, 1), vec2(1, 1));
    for (int j = 0; j < 4; ++j) {
      ivec2 o = ivec2(j & 1, j >> 1);
      float w = (o.x == 1 ? f.x : 1.0 - f.x) * (o.y == 1 ? f.y : 1.0 - f.y);
      if (!(w > 0.0)) continue;
      vec2 texel = clamp(base + vec2(o), vec2(0.0), vec2(u_causticResolution - 1.0));
      vec2 centre = (texel + 0.5) / u_causticResolution * 2.0 - 1.0;
      float receiverArea = texelSolidAngle(centre) * d2 / max(cosR, 1e-3);
      vec3 E = receiverArea > 0.0 ? w * phi / receiverArea : vec3(0.0);
      if (any(isnan(E)) || any(isinf(E))) continue;
      for (int i = 0; i < 4; ++i) {
        gl_Layer = u_cubeLayer + face;
        g_irradiance = E;
        g_disk = vec2(0.0);
        g_position = mid;
        gl_Position = vec4(centre + corners[i] * h, 0.5, 1.0);
        EmitVertex();
      }
      EndPrimitive();
    }
    return;
  }
  for (int f = 0; f < 6; ++f) {
    for (int i = 0; i < 3; ++i) q[i] = u_faceViewProj[f] * vec4(p[i], 1.0);
    if (outsideFace(q, 3)) continue;
    for (int i = 0; i < 3; ++i) {
      gl_Layer = u_cubeLayer + f;
      g_irradiance = V[i].rgb;
      g_disk = vec2(0.0);
      g_position = p[i];
      gl_Position = q[i];
      EmitVertex();
    }
    EndPrimitive();
  }
}
