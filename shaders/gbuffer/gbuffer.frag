#include "common/scene.glsl"

in vec3 v_position;
in vec3 v_normal;
in vec2 v_uv0;
in vec2 v_uv1;
in vec4 v_tangent;

uniform int u_material;
uniform vec3 u_eye;
uniform vec3 u_viewForward;  // unit vector the camera looks along

layout(binding = 8) uniform sampler2D t_baseColor;
layout(binding = 9) uniform sampler2D t_metallicRoughness;
layout(binding = 10) uniform sampler2D t_normal;
layout(binding = 11) uniform sampler2D t_occlusion;
layout(binding = 12) uniform sampler2D t_emissive;

layout(location = 0) out vec4 o_position;  // xyz world, w = view depth (> 0 on geometry, 0 = none)
layout(location = 1) out vec4 o_normal;    // xyz shading normal, w = 1
layout(location = 2) out vec4 o_albedo;    // rgb base colour
layout(location = 3) out vec4 o_material;  // metallic, roughness, occlusion, transmission
layout(location = 4) out vec4 o_emission;  // rgb emitted radiance, a = ior (KHR_materials_ior)
layout(location = 5) out vec4 o_geoNormal; // xyz geometric normal facing the viewer side, w = 1 when the
                                           // specular pass owns the surface's reflections (isSpecular())

vec2 uvSet(int set) { return set == 1 ? v_uv1 : v_uv0; }

vec3 safeNormalize(vec3 v, vec3 fallback) {
  float l2 = dot(v, v);
  return l2 > 1e-30 ? v * inversesqrt(l2) : fallback;
}

void main() {
  Material m = materials[u_material];
  vec4 base = m.baseColorFactor;
  if (m.texturesA.x >= 0) base *= texture(t_baseColor, materialUv(m, SLOT_BASE_COLOR, uvSet(m.texturesA.x)));
  int alphaMode = int(m.scales.w);
  if (alphaMode == 1 && base.a < m.scales.z) discard;

  bool doubleSided = m.texturesB.y != 0;
  // glTF: back faces of single-sided materials are not rendered.
  if (!gl_FrontFacing && !doubleSided) discard;

  vec3 faceNormal = safeNormalize(cross(dFdx(v_position), dFdy(v_position)), vec3(0, 1, 0));
  vec3 n = safeNormalize(v_normal, faceNormal);
  if (!gl_FrontFacing) n = -n;

  if (m.texturesA.z >= 0) {
    vec3 t = safeNormalize(v_tangent.xyz - n * dot(n, v_tangent.xyz), vec3(1, 0, 0));
    vec3 b = cross(n, t) * (v_tangent.w < 0.0 ? -1.0 : 1.0);
    vec3 tn = texture(t_normal, materialUv(m, SLOT_NORMAL, uvSet(m.texturesA.z))).xyz * 2.0 - 1.0;
    tn.xy *= m.scales.x;
    n = safeNormalize(t * tn.x + b * tn.y + n * tn.z, n);
  }

  float metallic = m.metallicRoughness.x;
  float roughness = m.metallicRoughness.y;
  if (m.texturesA.y >= 0) {
    vec4 mr = texture(t_metallicRoughness, materialUv(m, SLOT_METALLIC_ROUGHNESS, uvSet(m.texturesA.y)));
    roughness *= mr.g;
    metallic *= mr.b;
  }
  float occlusion = 1.0;
  if (m.texturesA.w >= 0) occlusion = 1.0 + m.scales.y * (texture(t_occlusion, materialUv(m, SLOT_OCCLUSION, uvSet(m.texturesA.w))).r - 1.0);
  vec3 emission = m.emission.rgb;
  if (m.texturesB.x >= 0) emission *= texture(t_emissive, materialUv(m, SLOT_EMISSIVE, uvSet(m.texturesB.x))).rgb;

  // Geometric normal on the side the viewer sees: used for shadow normal-offset bias.
  vec3 geo = dot(faceNormal, u_eye - v_position) < 0.0 ? -faceNormal : faceNormal;

  float viewDepth = max(dot(v_position - u_eye, u_viewForward), 1e-30);
  o_position = vec4(v_position, viewDepth);
  o_normal = vec4(n, 1.0);
  o_albedo = vec4(base.rgb, base.a);
  o_material = vec4(clamp(metallic, 0.0, 1.0), clamp(roughness, 0.0, 1.0), occlusion, m.metallicRoughness.z);
  o_emission = vec4(emission, m.metallicRoughness.w);
  o_geoNormal = vec4(geo, m.texturesB.w != 0 ? 1.0 : 0.0);
  if (m.texturesB.z != 0) {
    // KHR_materials_unlit: the base colour is the radiance leaving the surface and nothing lights it;
    // normal.w = 0 tells the shading passes, and a black non-metal albedo keeps ambient terms out.
    o_normal.w = 0.0;
    o_albedo = vec4(0.0, 0.0, 0.0, base.a);
    o_material = vec4(0.0, 1.0, 1.0, 0.0);
    o_emission = vec4(base.rgb, 1.5);
  }
}
