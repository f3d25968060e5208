// Forward shading of one alphaMode BLEND primitive (renderer/techniques/transparency): the radiance
// leaving the surface towards the eye, with the material's alpha as coverage; the blend state
// composites it over beauty (Porter-Duff over: L = a Ls + (1 - a) L_behind, glTF 3.9.4). The same
// decoder, BSDF and light code as the opaque passes; unlit BLEND surfaces show their base colour.
#include "common/direct_lighting.glsl"
#include "common/ibl.glsl"
#include "common/material.glsl"
#include "common/frame.glsl"

in vec3 v_position;
in vec3 v_normal;
in vec2 v_uv0;
in vec2 v_uv1;
in vec4 v_tangent;

uniform int u_material;
uniform int u_diffuseIbl;  // 1: add the environment's diffuse light (SH irradiance) to the surface
layout(binding = kUnitIblDfg) uniform sampler2D t_dfg;
layout(binding = kUnitIblPrefiltered) uniform sampler2DArray t_prefiltered;

layout(location = 0) out vec4 o_beauty;

void main() {
  SurfaceUv uv = SURFACE_UV_FRAGMENT(v_uv0, v_uv1);  // before any discard (common/material.glsl)
  Material m = materials[u_material];
  if (!gl_FrontFacing && !materialDoubleSided(m)) discard;
  MaterialParams p = decodeMaterial(m, uv);
  float alpha = clamp(p.baseColor.a, 0.0, 1.0);
  if (alpha <= 0.0) discard;
  if (materialUnlit(m)) {
    o_beauty = vec4(p.baseColor.rgb, alpha);
    return;
  }
  vec3 faceNormal = materialSafeNormalize(cross(dFdx(v_position), dFdy(v_position)), vec3(0, 1, 0));
  vec3 wo = u_frame.flags.x != 0 ? -u_frame.viewForward.xyz : normalize(u_frame.eye.xyz - v_position);
  vec3 ng = dot(faceNormal, wo) < 0.0 ? -faceNormal : faceNormal;
  vec3 n0 = windingSideNormal(materialSafeNormalize(v_normal, faceNormal), ng, gl_FrontFacing);
  vec3 nc = decodeCoatNormal(m, n0, v_tangent, uv, gl_FrontFacing);  // KHR_materials_clearcoat
  vec3 n = decodeShadingNormal(m, n0, v_tangent, uv, gl_FrontFacing);
  float nv = dot(n, wo);
  if (nv < 1e-3) n = normalize(n + wo * (1e-3 - nv));
  float ncv = dot(nc, wo);
  if (ncv < 1e-3) nc = normalize(nc + wo * (1e-3 - ncv));
  vec3 L = p.emission.rgb + directLighting(v_position, n, nc, ng, wo, p);
  if (u_iblMode != IBL_NONE) {
    float occlusion = p.emission.a;
    L += occlusion * iblSpecular(t_dfg, t_prefiltered, n, nc, wo, p);
    if (u_diffuseIbl != 0) {
      float mu = max(dot(n, wo), 0.0);
      vec3 diffuse = (1.0 - p.surface.x) * (1.0 - p.surface.z) * iblDiffuseWeight(t_dfg, nc, wo, mu, p) *
                     p.baseColor.rgb * iblIrradiance(n) * INV_PI;
      L += occlusion * diffuse;
    }
  }
  o_beauty = vec4(L, alpha);
}
