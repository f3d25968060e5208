// Spherical billboards (thesis Algorithm 5): one quad per particle, covering the sphere's projection
// conservatively (common/sphere_quad.glsl). The fragment shader recomputes everything from the
// pixel's ray, so the quad's depth is irrelevant (depth test off, thesis 7.1).
#include "common/shared.h"
#include "common/sphere_quad.glsl"
#include "common/frame.glsl"

layout(std430, binding = kBindingMediaParticles) readonly buffer Particles { MediaParticle particles[]; };

uniform float u_znear;
uniform int u_firstInstance;  // drawn in stretches (renderer/shading/Stretches.h)

flat out int v_particle;

void main() {
  const int i = u_firstInstance + gl_InstanceID;
  v_particle = i;
  const vec4 cr = particles[i].centerRadius;
  gl_Position = sphereQuadVertex(cr.xyz, cr.w, gl_VertexID, u_frame.view, u_frame.proj, u_znear, u_frame.flags.x == 1);
}
