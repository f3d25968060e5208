// One cube-map face of a receiver's environment (thesis 3.1): the radiance each visible surface sends
// toward the reference point o, and its distance from o.
// Radiance = emission + direct light through the full glTF BRDF with wo = direction to o (what an
// environment map stores; for the rough dielectrics a diffuse environment is made of this is the
// diffuse lobe plus a few per cent of broad specular), plus, from the second bounce on, the diffuse
// reflection of the previous bounce's environment: albedo (1 - metallic)(1 - transmission) / pi * E,
// E gathered from the previous low-resolution map with the polygon form factor.
#include "common/direct_lighting.glsl"
#include "env_diffuse/gather.glsl"

in vec3 v_position;
in vec3 v_normal;
in vec2 v_uv0;
in vec2 v_uv1;
in vec4 v_tangent;

uniform int u_material;
uniform vec3 u_origin;
uniform int u_gatherPrevious;  // 1 from the second bounce on
uniform int u_horizonClip;

layout(binding = 8) uniform sampler2D t_baseColor;
layout(binding = 9) uniform sampler2D t_metallicRoughness;
layout(binding = 10) uniform sampler2D t_normal;
layout(binding = 12) uniform sampler2D t_emissive;

layout(location = 0) out vec4 o_radiance;  // rgb radiance toward o
layout(location = 1) out vec4 o_geometry;  // x distance to o, yzw shading normal (facing o)

vec2 uvSet(int set) { return set == 1 ? v_uv1 : v_uv0; }
vec3 safeNormalize(vec3 v, vec3 fallback) {
  float l2 = dot(v, v);
  return l2 > 1e-30 ? v * inversesqrt(l2) : fallback;
}

void main() {
  Material m = materials[u_material];
  vec4 base = m.baseColorFactor;
  if (m.texturesA.x >= 0) base *= texture(t_baseColor, materialUv(m, SLOT_BASE_COLOR, uvSet(m.texturesA.x)));
  if (int(m.scales.w) == 1 && base.a < m.scales.z) discard;
  if (!gl_FrontFacing && m.texturesB.y == 0) discard;  // glTF single-sided, as in the G-buffer

  vec3 toO = u_origin - v_position;
  float dist = length(toO);
  vec3 wo = safeNormalize(toO, vec3(0.0, 1.0, 0.0));
  vec3 faceNormal = safeNormalize(cross(dFdx(v_position), dFdy(v_position)), wo);
  if (dot(faceNormal, wo) < 0.0) faceNormal = -faceNormal;
  vec3 n = safeNormalize(v_normal, faceNormal);
  if (!gl_FrontFacing) n = -n;
  if (m.texturesA.z >= 0) {
    vec3 t = safeNormalize(v_tangent.xyz - n * dot(n, v_tangent.xyz), vec3(1, 0, 0));
    vec3 b = cross(n, t) * (v_tangent.w < 0.0 ? -1.0 : 1.0);
    vec3 tn = texture(t_normal, materialUv(m, SLOT_NORMAL, uvSet(m.texturesA.z))).xyz * 2.0 - 1.0;
    tn.xy *= m.scales.x;
    n = safeNormalize(t * tn.x + b * tn.y + n * tn.z, n);
  }
  float nv = dot(n, wo);
  if (nv < 1e-3) n = normalize(n + wo * (1e-3 - nv));

  float metallic = m.metallicRoughness.x, roughness = m.metallicRoughness.y;
  if (m.texturesA.y >= 0) {
    vec4 mr = texture(t_metallicRoughness, materialUv(m, SLOT_METALLIC_ROUGHNESS, uvSet(m.texturesA.y)));
    roughness *= mr.g;
    metallic *= mr.b;
  }
  metallic = clamp(metallic, 0.0, 1.0);
  roughness = clamp(roughness, 0.0, 1.0);
  float transmission = m.metallicRoughness.z;
  vec3 emission = m.emission.rgb;
  if (m.texturesB.x >= 0) emission *= texture(t_emissive, materialUv(m, SLOT_EMISSIVE, uvSet(m.texturesB.x))).rgb;

  vec3 L = emission + directLighting(v_position, n, faceNormal, wo, base.rgb, metallic, roughness, transmission,
                                     m.metallicRoughness.w);
  if (u_gatherPrevious != 0) {
    vec3 kd = base.rgb * (1.0 - metallic) * (1.0 - transmission);
    L += kd * INV_PI * gatherIrradiance(v_position, n, ENV_METHOD_POLYGON, u_horizonClip != 0);
  }
  if (m.texturesB.z != 0) L = base.rgb;  // KHR_materials_unlit: its base colour, lit by nothing
  o_radiance = vec4(L, 1.0);
  o_geometry = vec4(dist, n);
}
