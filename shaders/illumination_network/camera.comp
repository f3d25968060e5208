// Final gathering (Algorithm 7, "Final render"): the radiance each node sends towards the camera per
// unit opacity, J_p = e_p(w_c) + a_p sum_d W_d(w_c) I[p,d] with the phase column for w_c normalised
// like the network's, written as the source of the node's splat (a spherical billboard, slot s holds
// node order[s] in back-to-front order). With u_includeLights = 0 the directional lights' single
// scattering is left out (J_ms: emission, the sky scattered once and more, the lights twice and more):
// the march (march.frag) adds the lights exactly along the view ray.
#include "illumination_network/network.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Nodes { NetworkNode nodes[]; };
layout(std430, binding = 1) readonly buffer Directions { NetworkDirection dirs[]; };
layout(std430, binding = 10) readonly buffer Radiance { vec4 radiance[]; };
layout(std430, binding = 12) readonly buffer Lights { NetworkLight lights[]; };
layout(std430, binding = 13) readonly buffer Transmittance { float transmittance[]; };
layout(std430, binding = 15) buffer Splats { MediaParticle splats[]; };
layout(std430, binding = 16) readonly buffer Order { int order[]; };

uniform int u_lightCount;
uniform int u_includeLights;
uniform int u_excludeSky;  // leave out the sky scattered once: a_p sky sum_d W_d(w_c) T0[p,d]
uniform vec3 u_sky;
layout(std430, binding = 17) readonly buffer SkyTransmittance { float skyTransmittance[]; };
uniform int u_phaseModel;
uniform float u_phaseG;
uniform int u_orthographic;
uniform vec3 u_eye;
uniform vec3 u_toCamera;  // orthographic: the direction towards the camera

void main() {
  const int s = int(gl_GlobalInvocationID.x);
  if (s >= u_nodes) return;
  const int p = order[s];
  const vec3 x = nodes[p].positionTau.xyz;
  const vec3 w = u_orthographic == 1 ? u_toCamera : normalize(u_eye - x);
  vec3 S = vec3(0.0);
  float sum = 0.0;
  for (int d = 0; d < u_directions; ++d) {
    const float P = phaseValue(u_phaseModel, u_phaseG, dot(dirs[d].w.xyz, w));
    S += P * radiance[p * u_directions + d].rgb;
    if (u_excludeSky == 1) S -= P * u_sky * skyTransmittance[p * u_directions + d];
    sum += P;
  }
  // Without the sky scattered once, S is non-negative only once every chain has been iterated (I >= sky
  // T0 from then on); a cold request with fewer iterations than the longest chain may dip below.
  vec3 J = nodes[p].emission.rgb + nodes[p].albedo.rgb * (sum > 0.0 ? max(S / sum, vec3(0.0)) : vec3(0.0));
  for (int l = 0; l < (u_includeLights == 1 ? u_lightCount : 0); ++l)
    J += nodes[p].albedo.rgb * phaseValue(u_phaseModel, u_phaseG, dot(lights[l].direction.xyz, w)) *
         lights[l].irradiance.rgb * transmittance[p * u_lightCount + l];
  splats[s].sourceTau.rgb = J;
}
