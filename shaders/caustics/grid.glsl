// The photon hit image as a grid of caustic triangles (thesis 6.1.2, Fig. 6.5). Shared by the area
// pass (area.comp), the triangle pass (triangles.vert/.geom) and the splat baseline (splat.geom).
//
// Photon hit image (three P x P targets written by photon.frag, per light and generator):
//   t_hit    xyz = h - c_G, the first non-specular hit relative to the generator's reference point
//   t_power  rgb = dPhi, the photon's power; a = 1 for a valid photon, -1 where the generator is not
//            seen or the path was lost (cleared to negative power, thesis 6.1.1)
//   t_normal xyz = the receiver's normal at h (as modelled, from the distance map)
// Cell (x, y) between vertices (x, y) .. (x + 1, y + 1) holds two triangles:
//   T0 = (x, y), (x + 1, y), (x, y + 1)    T1 = (x + 1, y), (x + 1, y + 1), (x, y + 1)
// so 2 (P - 1)^2 triangles in all, and a vertex belongs to at most six.
#ifndef RADIANT_CAUSTICS_GRID
#define RADIANT_CAUSTICS_GRID

layout(binding = 0) uniform sampler2D t_hit;
layout(binding = 1) uniform sampler2D t_power;
layout(binding = 2) uniform sampler2D t_normal;
uniform int u_photonResolution;

// Vertices whose receivers' normals differ by more than 60 degrees lie on different surfaces (a
// floor and a wall): a triangle between them would smear power across the corner. Such triangles are
// not drawn and, so that the energy identity still holds, not counted in any vertex area.
const float kSameSurfaceCos = 0.5;

bool vertexValid(ivec2 v) {
  if (any(lessThan(v, ivec2(0))) || any(greaterThanEqual(v, ivec2(u_photonResolution)))) return false;
  return texelFetch(t_power, v, 0).a > 0.0;
}
vec3 vertexHit(ivec2 v) { return texelFetch(t_hit, v, 0).xyz; }
vec3 vertexPower(ivec2 v) { return texelFetch(t_power, v, 0).rgb; }
vec3 vertexNormal(ivec2 v) { return texelFetch(t_normal, v, 0).xyz; }

bool triangleValid(ivec2 a, ivec2 b, ivec2 c) {
  if (!vertexValid(a) || !vertexValid(b) || !vertexValid(c)) return false;
  vec3 na = vertexNormal(a), nb = vertexNormal(b), nc = vertexNormal(c);
  return dot(na, nb) >= kSameSurfaceCos && dot(nb, nc) >= kSameSurfaceCos && dot(na, nc) >= kSameSurfaceCos;
}

// A_t = 1/2 |(h_b - h_a) x (h_c - h_a)|: the triangle's area on the receivers (world units).
float triangleArea(ivec2 a, ivec2 b, ivec2 c) {
  vec3 pa = vertexHit(a);
  return 0.5 * length(cross(vertexHit(b) - pa, vertexHit(c) - pa));
}

// The vertices of triangle `side` (0: T0, 1: T1) of cell `cell`.
void cellTriangle(ivec2 cell, int side, out ivec2 a, out ivec2 b, out ivec2 c) {
  if (side == 0) { a = cell; b = cell + ivec2(1, 0); c = cell + ivec2(0, 1); }
  else { a = cell + ivec2(1, 0); b = cell + ivec2(1, 1); c = cell + ivec2(0, 1); }
}

// Sum of the areas of the drawn triangles around vertex v, and their number (thesis 6.2: dA_v = k times
// this sum).
float adjacentArea(ivec2 v, out int count) {
  // T0 of cells v, v - (1,0), v - (0,1); T1 of cells v - (1,0), v - (0,1), v - (1,1).
  const ivec3 tris[6] = ivec3[6](ivec3(0, 0, 0), ivec3(-1, 0, 0), ivec3(0, -1, 0),
                                 ivec3(-1, 0, 1), ivec3(0, -1, 1), ivec3(-1, -1, 1));
  float sum = 0.0;
  count = 0;
  for (int i = 0; i < 6; ++i) {
    ivec2 a, b, c;
    cellTriangle(v + tris[i].xy, tris[i].z, a, b, c);
    if (!triangleValid(a, b, c)) continue;
    sum += triangleArea(a, b, c);
    ++count;
  }
  return sum;
}

#endif
