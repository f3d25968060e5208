// The G-buffer surface at a pixel, for splatting and gathering.
#ifndef RADIANT_PHOTON_GI_SURFACE
#define RADIANT_PHOTON_GI_SURFACE
#include "common/shared.h"
#include "common/material.glsl"  // decodeLayers (the G-buffer's layers target)
#include "common/gbuffer_geometry.glsl"
#include "common/frame.glsl"
layout(binding = kUnitGbufferPosition) uniform sampler2D t_position;
layout(binding = kUnitGbufferNormal) uniform sampler2D t_normal;
layout(binding = kUnitGbufferAlbedo) uniform sampler2D t_albedo;
layout(binding = kUnitGbufferMaterial) uniform sampler2D t_material;
layout(binding = kUnitGbufferEmission) uniform sampler2D t_emission;
layout(binding = kUnitGbufferGeometricNormal) uniform sampler2D t_geoNormal;
layout(binding = kUnitGbufferLayers) uniform usampler2D t_layers;    // common/material.glsl encodeLayers
layout(binding = kUnitGbufferSpecular) uniform sampler2D t_specular;  // gbuffer_specular


bool loadSurface(ivec2 px, out SplatSurface s) {
  vec4 P = texelFetch(t_position, px, 0);
  if (P.w <= 0.0) return false;  // no geometry
  s.x = P.xyz;
  vec4 N = texelFetch(t_normal, px, 0);
  if (N.w == 0.0) return false;  // KHR_materials_unlit: nothing lights it (gbuffer.frag)
  s.n = normalize(N.xyz);
  vec4 geo = texelFetch(t_geoNormal, px, 0);
  s.ng = normalize(geo.xyz);
  s.nw = normalize(gbufferWindingNormal(geo));
  s.wo = u_frame.flags.x != 0 ? -u_frame.viewForward.xyz : normalize(u_frame.eye.xyz - P.xyz);
  vec4 m = texelFetch(t_material, px, 0);
  s.p = materialParams(texelFetch(t_albedo, px, 0).rgb, m.x, m.y, m.w, texelFetch(t_emission, px, 0).a);
  // The layers, read and bent towards the viewer as the direct pass does (direct.frag).
  s.p.specular = texelFetch(t_specular, px, 0);
  s.nc = decodeLayers(texelFetch(t_layers, px, 0), s.p);
  float ncv = dot(s.nc, s.wo);
  if (ncv < 1e-3) s.nc = normalize(s.nc + s.wo * (1e-3 - ncv));
  return true;
}
#endif
