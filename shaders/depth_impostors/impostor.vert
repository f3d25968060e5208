// Depth impostors (thesis 8.1.1): every particle of a block drawn as a quad into the block's tile,
// orthographically along the block's axis. The fragment shader takes the sphere's analytic depths.
#include "common/shared.h"
#include "depth_impostors/frame.glsl"

layout(std430, binding = kBindingMediaParticles) readonly buffer Particles { MediaParticle particles[]; };

uniform int u_axisMode;  // 0: u_axis is the axis; 1: u_axis is the eye or light position
uniform vec3 u_axis;
uniform int u_res;
uniform int u_tilesX;
uniform vec2 u_atlasSize;

out vec2 v_offset;        // the fragment's offset from the particle's centre in the block plane (metres)
flat out int v_particle;
flat out float v_depth;   // the particle centre's depth along the axis, relative to the block centre

void main() {
  const int i = gl_InstanceID;
  const MediaParticle p = particles[i];
  const ImpostorBlock B = blocks[p.models.z];
  const vec3 a = impostorAxis(u_axisMode, u_axis, B.centerRadius.xyz);
  vec3 u, v;
  impostorBasis(a, u, v);
  const vec3 rel = p.centerRadius.xyz - B.centerRadius.xyz;
  const float R = B.centerRadius.w, r = p.centerRadius.w;
  const int k = gl_VertexID;
  const vec2 corner = vec2((k == 1 || k == 2 || k == 4) ? 1.0 : -1.0, (k == 2 || k == 4 || k == 5) ? 1.0 : -1.0);
  const vec2 local = vec2(dot(rel, u), dot(rel, v)) + corner * r;
  const vec2 texel = vec2(tileOrigin(B.info.x, u_tilesX, u_res)) + (local / R * 0.5 + 0.5) * float(u_res);
  gl_Position = vec4(texel / u_atlasSize * 2.0 - 1.0, 0.5, 1.0);
  v_offset = corner * r;
  v_particle = i;
  v_depth = dot(rel, a);
}
