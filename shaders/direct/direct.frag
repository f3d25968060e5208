// Direct lighting from punctual lights with shadow maps, plus emission, from the G-buffer.
// Writes the `direct` AOV and adds the same value to `beauty` (cleared to zero at the frame's start; every
// beauty writer composes into it, FrameAllocation.h).
#include "common/shared.h"
#include "common/direct_lighting.glsl"
#include "common/environment.glsl"
#include "common/ibl.glsl"
#include "common/material.glsl"
#include "common/gbuffer_geometry.glsl"
#include "common/frame.glsl"

in vec2 v_uv;

layout(binding = kUnitGbufferPosition) uniform sampler2D t_position;
layout(binding = kUnitGbufferNormal) uniform sampler2D t_normal;
layout(binding = kUnitGbufferAlbedo) uniform sampler2D t_albedo;
layout(binding = kUnitGbufferMaterial) uniform sampler2D t_material;
layout(binding = kUnitGbufferEmission) uniform sampler2D t_emission;
layout(binding = kUnitGbufferGeometricNormal) uniform sampler2D t_geoNormal;
layout(binding = kUnitGbufferLayers) uniform usampler2D t_layers;    // common/material.glsl encodeLayers
layout(binding = kUnitGbufferSpecular) uniform sampler2D t_specular;  // gbuffer_specular

layout(binding = kUnitEnvironment) uniform sampler2D t_environment;
layout(binding = kUnitIblDfg) uniform sampler2D t_dfg;
layout(binding = kUnitIblPrefiltered) uniform sampler2DArray t_prefiltered;

layout(location = 0) out vec4 o_direct;
layout(location = 1) out vec4 o_beauty;

void main() {
  ivec2 px = ivec2(gl_FragCoord.xy);
  vec4 P = texelFetch(t_position, px, 0);
  if (P.w <= 0.0) {
    vec3 sky = u_frame.background.rgb;
    if (u_frame.flags.y != 0) {
      // The camera ray through the pixel centre: unproject a point on the near plane (reversed-Z:
      // depth 1); orthographic cameras look along their forward axis.
      vec4 nearPoint = u_frame.invViewProj * vec4(v_uv * 2.0 - 1.0, 1.0, 1.0);
      vec3 dir = u_frame.flags.x != 0 ? u_frame.viewForward.xyz : normalize(nearPoint.xyz / nearPoint.w - u_frame.eye.xyz);
      sky = environmentRadiance(t_environment, dir);
    }
    o_direct = vec4(sky, 1.0);
    o_beauty = o_direct;
    return;
  }
  vec3 p = P.xyz;
  vec4 nUnlit = texelFetch(t_normal, px, 0);
  if (nUnlit.w < 0.5) {  // KHR_materials_unlit (gbuffer.frag): the stored base colour as it is
    o_direct = vec4(texelFetch(t_emission, px, 0).rgb, 1.0);
    o_beauty = o_direct;
    return;
  }
  // Renormalised: the RGBA16F target keeps a unit normal's length only to ~5e-4, and at a GGX peak
  // n.h = 0.9995 already costs 21% of D at roughness 0.3 (the glTF furnace, tests/gl/render/furnace_test).
  vec3 n = normalize(nUnlit.xyz);
  vec3 albedo = texelFetch(t_albedo, px, 0).rgb;
  vec4 mat = texelFetch(t_material, px, 0);
  vec4 emissionIor = texelFetch(t_emission, px, 0);
  vec3 emission = emissionIor.rgb;
  vec4 ngOwned = texelFetch(t_geoNormal, px, 0);
  vec3 ng = ngOwned.xyz;
  vec3 wo = u_frame.flags.x != 0 ? -u_frame.viewForward.xyz : normalize(u_frame.eye.xyz - p);
  // Interpolated or mapped normals can face away from the viewer at silhouettes; bend them back just
  // enough to be visible instead of shading them black (NdotV >= 1e-3).
  float nv = dot(n, wo);
  if (nv < 1e-3) n = normalize(n + wo * (1e-3 - nv));

  MaterialParams params = materialParams(albedo, mat.x, mat.y, mat.w, emissionIor.a);
  params.specular = texelFetch(t_specular, px, 0);
  vec3 nc = decodeLayers(texelFetch(t_layers, px, 0), params);
  float ncv = dot(nc, wo);
  if (ncv < 1e-3) nc = normalize(nc + wo * (1e-3 - ncv));
  // The environment's specular reflection (split-sum), times the material's baked occlusion: light
  // path L(sky)GE, which this pass owns (u_iblMode is IBL_NONE otherwise). Mirror-like metals and
  // transmissive materials belong to the specular pass (Material::isSpecular(), the same per-material
  // rule the planner and that pass use; the G-buffer carries it in ng.w): it sees the whole map in
  // their reflections, the environment's lights (after the scene's) included, so those lights reach
  // only their diffuse lobe here (a metallic 0.67 mirror is a third diffuse dielectric; it was black on
  // its sunlit side until 2026-12-05).
  bool specularOwned = gbufferSpecularOwned(ngOwned);
  float skyVisibility;
  vec3 L = emission + directLighting(p, n, nc, ng, wo, params, u_lightCount,
                                     specularOwned ? u_sceneLightCount : u_lightCount, skyVisibility);
  // Specular occlusion: the split-sum integrates the residual map without visibility; where the sky
  // lights (the same residual, with shadow maps) are partly hidden, Lagarde's specular occlusion of
  // their visibility scales it (1 on open surfaces and without sky lights). A dielectric of roughness
  // 0.6 in a contact shadow was 1.05-1.11 of the reference without it.
  if (u_iblMode != IBL_NONE && !specularOwned)
    L += mat.z * specularOcclusion(dot(n, wo), skyVisibility, params.surface.y) *
         iblSpecular(t_dfg, t_prefiltered, n, nc, wo, params);
  o_direct = vec4(L, 1.0);
  o_beauty = o_direct;
}
