// Final gathering on a receiver's visible fragments (thesis Algorithm 1). The receiver's meshes are
// drawn with the camera; a fragment is shaded only where the G-buffer holds this very surface (its view
// depth matches), and all surface attributes come from the G-buffer. Output: the diffusely reflected
// indirect light L_o = albedo (1 - metallic)(1 - transmission) / pi * E, to `indirect_diffuse` and,
// blended additively, to `beauty`.
#include "common/shared.h"
#include "common/constants.glsl"
#include "env_diffuse/gather.glsl"
#include "common/frame.glsl"

in vec3 v_position;

layout(binding = kUnitGbufferPosition) uniform sampler2D t_position;
layout(binding = kUnitGbufferNormal) uniform sampler2D t_normal;
layout(binding = kUnitGbufferAlbedo) uniform sampler2D t_albedo;
layout(binding = kUnitGbufferMaterial) uniform sampler2D t_material;
layout(binding = 5) uniform samplerCube t_irradiance;

uniform int u_method;
uniform int u_horizonClip;

layout(location = 0) out vec4 o_indirect;
layout(location = 1) out vec4 o_beauty;

void main() {
  ivec2 px = ivec2(gl_FragCoord.xy);
  vec4 P = texelFetch(t_position, px, 0);
  float depth = max(dot(v_position - u_frame.eye.xyz, u_frame.viewForward.xyz), 1e-30);
  if (P.w <= 0.0 || abs(depth - P.w) > 1e-3 * P.w) discard;
  vec3 x = P.xyz;
  vec3 n = normalize(texelFetch(t_normal, px, 0).xyz);
  vec3 albedo = texelFetch(t_albedo, px, 0).rgb;
  vec4 mat = texelFetch(t_material, px, 0);
  vec3 kd = albedo * (1.0 - mat.x) * (1.0 - mat.w);
  vec3 E = u_method == ENV_METHOD_CLASSIC ? textureLod(t_irradiance, n, 0.0).rgb
                                          : gatherIrradiance(x, n, u_method, u_horizonClip != 0);
  vec3 L = kd * INV_PI * E;
  o_indirect = vec4(L, 1.0);
  o_beauty = vec4(L, 0.0);
}
