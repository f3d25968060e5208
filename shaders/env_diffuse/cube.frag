// One cube-map face of a receiver's environment (thesis 3.1): the radiance each visible surface sends
// toward the reference point o, and its distance from o.
// Radiance = emission + direct light through the full glTF BRDF with wo = direction to o (what an
// environment map stores; for the rough dielectrics a diffuse environment is made of this is the
// diffuse lobe plus a few per cent of broad specular), plus, from the second bounce on, the diffuse
// reflection of the previous bounce's environment: albedo (1 - metallic)(1 - transmission) / pi * E,
// E gathered from the previous low-resolution map with the polygon form factor.
#include "common/direct_lighting.glsl"
#include "common/material.glsl"
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

layout(location = 0) out vec4 o_radiance;  // rgb radiance toward o
layout(location = 1) out vec4 o_geometry;  // x distance to o, yzw shading normal (facing o)

void main() {
  SurfaceUv uv = SURFACE_UV_FRAGMENT(v_uv0, v_uv1);  // before any discard (common/material.glsl)
  Material m = materials[u_material];
  if (materialMasked(m, decodeBaseColor(m, uv).a)) discard;
  if (!gl_FrontFacing && !materialDoubleSided(m)) discard;  // glTF single-sided, as in the G-buffer
  MaterialParams p = decodeMaterial(m, uv);

  vec3 toO = u_origin - v_position;
  float dist = length(toO);
  vec3 wo = materialSafeNormalize(toO, vec3(0.0, 1.0, 0.0));
  vec3 faceNormal = materialSafeNormalize(cross(dFdx(v_position), dFdy(v_position)), wo);
  if (dot(faceNormal, wo) < 0.0) faceNormal = -faceNormal;
  vec3 n = windingSideNormal(materialSafeNormalize(v_normal, faceNormal), faceNormal, gl_FrontFacing);
  n = decodeShadingNormal(m, n, v_tangent, uv, gl_FrontFacing);
  float nv = dot(n, wo);
  if (nv < 1e-3) n = normalize(n + wo * (1e-3 - nv));

  vec3 L = p.emission.rgb + directLighting(v_position, n, faceNormal, wo, p);
  if (u_gatherPrevious != 0) {
    vec3 kd = p.baseColor.rgb * (1.0 - p.surface.x) * (1.0 - p.surface.z);
    L += kd * INV_PI * gatherIrradiance(v_position, n, ENV_METHOD_POLYGON, u_horizonClip != 0);
  }
  if (materialUnlit(m)) L = p.baseColor.rgb;  // KHR_materials_unlit: its base colour, lit by nothing
  o_radiance = vec4(L, 1.0);
  o_geometry = vec4(dist, n);
}
