// The G-buffer surface at a pixel, for splatting and gathering.
#ifndef RADIANT_PHOTON_GI_SURFACE
#define RADIANT_PHOTON_GI_SURFACE
layout(binding = 0) uniform sampler2D t_position;
layout(binding = 1) uniform sampler2D t_normal;
layout(binding = 2) uniform sampler2D t_albedo;
layout(binding = 3) uniform sampler2D t_material;
layout(binding = 4) uniform sampler2D t_emission;
layout(binding = 6) uniform sampler2D t_geoNormal;

uniform vec3 u_eye;
uniform vec3 u_viewForward;
uniform int u_orthographic;

bool loadSurface(ivec2 px, out SplatSurface s) {
  vec4 P = texelFetch(t_position, px, 0);
  if (P.w <= 0.0) return false;  // no geometry
  s.x = P.xyz;
  vec4 N = texelFetch(t_normal, px, 0);
  if (N.w == 0.0) return false;  // KHR_materials_unlit: nothing lights it (gbuffer.frag)
  s.n = normalize(N.xyz);
  s.ng = normalize(texelFetch(t_geoNormal, px, 0).xyz);
  s.wo = u_orthographic != 0 ? -u_viewForward : normalize(u_eye - P.xyz);
  s.baseColor = texelFetch(t_albedo, px, 0).rgb;
  vec4 m = texelFetch(t_material, px, 0);
  s.metallic = m.x;
  s.roughness = m.y;
  s.transmission = m.w;
  s.ior = texelFetch(t_emission, px, 0).a;
  return true;
}
#endif
