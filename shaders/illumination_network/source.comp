// The first half of one iteration of the illumination network: every node's source towards every
// direction, src[p,i] = e_p(w_i) + a_p sum_d W[d,i] I[p,d] (Network.cpp iterate; the thesis' "S = I R"
// product, §9.1.2's optimisation). e_p is the emission plus the directional lights scattered once at
// their exact directions, attenuated by T_l(p). iterate.comp then moves it along the links.
#include "illumination_network/network.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Nodes { NetworkNode nodes[]; };
layout(std430, binding = 1) readonly buffer Directions { NetworkDirection dirs[]; };
layout(std430, binding = 9) readonly buffer Weights { float weights[]; };
layout(std430, binding = 10) readonly buffer RadianceIn { vec4 radianceIn[]; };
layout(std430, binding = 12) readonly buffer Lights { NetworkLight lights[]; };
layout(std430, binding = 13) readonly buffer Transmittance { float transmittance[]; };
layout(std430, binding = 18) writeonly buffer Source { vec4 source[]; };

uniform int u_lightCount;
uniform int u_phaseModel;
uniform float u_phaseG;

void main() {
  const int link = int(gl_GlobalInvocationID.x);
  if (link >= u_nodes * u_directions) return;
  const int p = link / u_directions, i = link - p * u_directions;
  vec3 S = vec3(0.0);
  for (int d = 0; d < u_directions; ++d) S += weights[d * u_directions + i] * radianceIn[p * u_directions + d].rgb;
  vec3 e = nodes[p].emission.rgb;
  for (int l = 0; l < u_lightCount; ++l)
    e += nodes[p].albedo.rgb * phaseValue(u_phaseModel, u_phaseG, dot(lights[l].direction.xyz, dirs[i].w.xyz)) *
         lights[l].irradiance.rgb * transmittance[p * u_lightCount + l];
  source[link] = vec4(e + nodes[p].albedo.rgb * S, 0.0);
}
