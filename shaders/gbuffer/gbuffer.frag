#include "common/material.glsl"
#include "common/gbuffer_geometry.glsl"
#include "common/frame.glsl"

in vec3 v_position;
in vec3 v_normal;
in vec2 v_uv0;
in vec2 v_uv1;
in vec4 v_tangent;

uniform int u_material;

layout(location = 0) out vec4 o_position;  // xyz world, w = view depth (> 0 on geometry, 0 = none)
layout(location = 1) out vec4 o_normal;    // xyz shading normal, w = 1 (0: unlit, KHR_materials_unlit)
layout(location = 2) out vec4 o_albedo;    // rgb base colour
layout(location = 3) out vec4 o_material;  // metallic, roughness, occlusion, transmission
layout(location = 4) out vec4 o_emission;  // rgb emitted radiance, a = ior (KHR_materials_ior)
layout(location = 5) out vec4 o_geoNormal; // xyz geometric normal facing the viewer side, w flags:
                                           // common/material.glsl gbufferGeoFlags
layout(location = 6) out uvec4 o_layers;   // encodeLayers (common/material.glsl): clear coat, coat normal, sheen
layout(location = 7) out vec4 o_specular;  // rgb specular colour, a specular weight (KHR_materials_specular)

void main() {
  SurfaceUv uv = SURFACE_UV_FRAGMENT(v_uv0, v_uv1);  // before any discard (common/material.glsl)
  Material m = materials[u_material];
#ifndef OPAQUE
  if (materialMasked(m, decodeBaseColor(m, uv).a)) discard;
  // alphaMode BLEND: composited over the lit opaque frame by the transparency pass; the passes that
  // read the G-buffer light what lies behind it.
  if (materialAlphaMode(m) == 2) discard;
  // glTF: back faces of single-sided materials are not rendered.
  if (!gl_FrontFacing && !materialDoubleSided(m)) discard;
#endif
  // OPAQUE (GBufferPass draws its opaque materials with it): no discard, so that the depth test runs
  // before the shader and hidden layers are not shaded; single-sided back faces are culled instead.
  MaterialParams p = decodeMaterial(m, uv);

  vec3 faceNormal = materialSafeNormalize(cross(dFdx(v_position), dFdy(v_position)), vec3(0, 1, 0));
  // Geometric normal on the side the viewer sees: used for shadow normal-offset bias.
  vec3 geo = dot(faceNormal, u_frame.eye.xyz - v_position) < 0.0 ? -faceNormal : faceNormal;
  vec3 n = windingSideNormal(materialSafeNormalize(v_normal, faceNormal), geo, gl_FrontFacing);
  // KHR_materials_clearcoat: its own normal map (clearcoatNormalTexture) or none, never the base's.
  vec3 coatNormal = decodeCoatNormal(m, n, v_tangent, uv, gl_FrontFacing);
  n = decodeShadingNormal(m, n, v_tangent, uv, gl_FrontFacing);

  float viewDepth = max(dot(v_position - u_frame.eye.xyz, u_frame.viewForward.xyz), 1e-30);
  o_position = vec4(v_position, viewDepth);
  o_normal = vec4(n, 1.0);
  o_albedo = p.baseColor;
  o_material = vec4(p.surface.x, p.surface.y, p.emission.a, p.surface.z);
  o_emission = vec4(p.emission.rgb, p.surface.w);
  o_geoNormal = vec4(geo, gbufferGeoFlags(materialSpecularOwned(m), gl_FrontFacing));
  o_layers = encodeLayers(p, coatNormal);
  o_specular = p.specular;
  if (materialUnlit(m)) {
    // KHR_materials_unlit: the base colour is the radiance leaving the surface and nothing lights it;
    // normal.w = 0 tells the shading passes, and a black non-metal albedo keeps ambient terms out.
    o_normal.w = 0.0;
    o_albedo = vec4(0.0, 0.0, 0.0, p.baseColor.a);
    o_material = vec4(0.0, 1.0, 1.0, 0.0);
    o_emission = vec4(p.baseColor.rgb, kDefaultIor);
    o_layers = uvec4(0u);
    o_specular = vec4(1.0);
  }
}
