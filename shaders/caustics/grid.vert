// Vertex pulling for the reconstruction passes (thesis 6.1.2: "vertices are sent with photon hit
// location image coordinates"): no vertex buffer, the vertex index names a texel of the hit image.
//   u_mode 0 (triangles): vertex 3 t + j is corner j of triangle t = 2 cell + side (grid.glsl order);
//   u_gridMode 1 (splats):    vertex i is texel i.
uniform int u_gridMode;
uniform int u_gridResolution;  // P
flat out ivec2 v_texel;

void main() {
  int id = gl_VertexID;
  if (u_gridMode == 0) {
    int tri = id / 3, corner = id - 3 * (id / 3);
    int cell = tri / 2, side = tri - 2 * (tri / 2);
    ivec2 c = ivec2(cell % (u_gridResolution - 1), cell / (u_gridResolution - 1));
    const ivec2 t0[3] = ivec2[3](ivec2(0, 0), ivec2(1, 0), ivec2(0, 1));
    const ivec2 t1[3] = ivec2[3](ivec2(1, 0), ivec2(1, 1), ivec2(0, 1));
    v_texel = c + (side == 0 ? t0[corner] : t1[corner]);
  } else {
    v_texel = ivec2(id % u_gridResolution, id / u_gridResolution);
  }
  gl_Position = vec4(0.0, 0.0, 0.0, 1.0);
}
