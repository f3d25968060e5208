// One quad per photon, an instanced 4-vertex strip pulled from the splat buffer: the square of side 2h
// in the photon's tangent plane that encloses its kernel disk (the paper's enclosing triangle, §2.2).
#include "photon_gi/photon.glsl"
#include "common/frame.glsl"

uniform int u_firstInstance;  // drawn in stretches (renderer/shading/Stretches.h)
flat out int v_photon;

void main() {
  int photon = u_firstInstance + gl_InstanceID;
  vec2 c = vec2((gl_VertexID & 1) != 0 ? 1.0 : -1.0, (gl_VertexID & 2) != 0 ? 1.0 : -1.0);
  GpuPhoton p = photons[photon];
  if (photonIsCopy(p)) {  // a copy in another cell of the grid (Splatting.cpp buildSplatGrid): its original draws it
    gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
    v_photon = photon;
    return;
  }
  vec3 n = p.normal;
  // Duff et al. 2017 orthonormal basis.
  float sgn = n.z >= 0.0 ? 1.0 : -1.0;
  float a = -1.0 / (sgn + n.z);
  float b = n.x * n.y * a;
  vec3 t = vec3(1.0 + sgn * n.x * n.x * a, sgn * b, -sgn * n.x);
  vec3 bt = vec3(b, sgn + n.y * n.y * a, -n.y);
  vec3 world = p.positionRadius.xyz + p.positionRadius.w * (c.x * t + c.y * bt);
  v_photon = photon;
  gl_Position = u_frame.viewProj * vec4(world, 1.0);
}
