// Spherical billboards (thesis Algorithm 5): one quad per particle, covering the sphere's projection
// conservatively (the screen rectangle of its view-aligned bounding box; the whole screen when a
// perspective camera is within reach of the sphere's near side, so the camera can enter a particle).
// The fragment shader recomputes everything from the pixel's ray, so the quad's depth is irrelevant
// (depth test off, thesis 7.1).
#include "common/shared.h"

layout(std430, binding = kBindingMediaParticles) readonly buffer Particles { MediaParticle particles[]; };

uniform mat4 u_view;  // world -> view (the camera looks down -z)
uniform mat4 u_proj;
uniform float u_znear;
uniform int u_orthographic;

flat out int v_particle;

void main() {
  const int i = gl_InstanceID;
  v_particle = i;
  const vec4 cr = particles[i].centerRadius;
  const vec3 c = (u_view * vec4(cr.xyz, 1.0)).xyz;
  const float r = cr.w;
  const int k = gl_VertexID;
  const vec2 corner = vec2((k == 1 || k == 2 || k == 4) ? 1.0 : 0.0, (k == 2 || k == 4 || k == 5) ? 1.0 : 0.0);
  vec2 lo = vec2(-1.0), hi = vec2(1.0);
  if (u_orthographic == 1 || -c.z - r > 1.001 * u_znear) {
    lo = vec2(1e30), hi = vec2(-1e30);
    for (int b = 0; b < 8; ++b) {
      const vec3 p = c + r * vec3((b & 1) != 0 ? 1.0 : -1.0, (b & 2) != 0 ? 1.0 : -1.0, (b & 4) != 0 ? 1.0 : -1.0);
      const vec4 clip = u_proj * vec4(p, 1.0);
      const vec2 ndc = clip.xy / clip.w;
      lo = min(lo, ndc), hi = max(hi, ndc);
    }
    lo = max(lo, vec2(-1.0)), hi = min(hi, vec2(1.0));
  }
  gl_Position = vec4(mix(lo, hi, corner), 0.5, 1.0);
}
