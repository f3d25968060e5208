// Full-resolution resolve of the AO estimate: the depth-aware 4x4 box filter of thesis 4.1.3 (which,
// with the 4x4 interleaved pattern, averages all 16 kernel rotations), or depth-aware upsampling of a
// half-resolution estimate. Writes `ao` and, when blending is enabled on attachment 1, adds the ambient
// term to beauty: L^r = a L^a O (thesis eq. 4.1 with L^in = L^a mu), where a is the diffuse albedo
// baseColor (1 - metallic) (1 - transmission) times the material's baked occlusion. For an environment
// map L^a becomes E(n) / pi, its SH irradiance by the shading normal, and the glTF Fresnel weight of the
// diffuse base multiplies it (renderer/shading/ImageBasedLighting.h; 1 - ~1e-3 head-on).
// Metals have no diffuse lobe: their response to the environment is specular, which the direct pass
// adds (split-sum), unoccluded. The layers (KHR_materials_clearcoat, _sheen, _specular) attenuate the
// diffuse base as the direct pass's split-sum does (ibl.glsl's layered iblDiffuseWeight); their own
// reflections of the environment are the direct pass's.
#include "common/shared.h"
#include "ambient_occlusion/shared.h"
#include "common/brdf.glsl"
#include "common/material.glsl"  // decodeLayers
#include "common/ibl.glsl"
#include "common/frame.glsl"

in vec2 v_uv;

layout(binding = 0) uniform sampler2D t_ao;  // working resolution
layout(binding = 1) uniform sampler2D t_position;
layout(binding = 2) uniform sampler2D t_normal;
layout(binding = 3) uniform sampler2D t_albedo;
layout(binding = 4) uniform sampler2D t_material;  // metallic, roughness, occlusion, transmission
layout(binding = 5) uniform sampler2D t_geoNormal;
layout(binding = kUnitAoEmission) uniform sampler2D t_emission;  // a = ior
layout(binding = kUnitIblDfg) uniform sampler2D t_dfg;
layout(binding = kUnitGbufferLayers) uniform usampler2D t_layers;    // common/material.glsl encodeLayers
layout(binding = kUnitGbufferSpecular) uniform sampler2D t_specular;  // gbuffer_specular

uniform int u_scale;
uniform int u_blur;
uniform float u_radius;

layout(location = 0) out float o_ao;
layout(location = 1) out vec4 o_beauty;

// "We also check whether or not the depth difference of the current and the neighbor pixels exceeds a
// given limit" (thesis 4.1.3). The difference is measured from the centre's tangent plane, so a tilted
// flat region is not split by its own depth gradient; the limit is R / 10.
bool sameSurface(vec3 p, vec3 ng, vec4 Pq) {
  return Pq.w > 0.0 && abs(dot(Pq.xyz - p, ng)) <= 0.1 * u_radius;
}

void main() {
  ivec2 px = ivec2(gl_FragCoord.xy);
  vec4 P = texelFetch(t_position, px, 0);
  if (P.w <= 0.0) {
    o_ao = 1.0;
    o_beauty = vec4(0.0);
    return;
  }
  vec3 ng = texelFetch(t_geoNormal, px, 0).xyz;
  ivec2 wsize = textureSize(t_ao, 0);
  ivec2 fsize = textureSize(t_position, 0);
  ivec2 c = px / u_scale;
  float sum = 0.0, count = 0.0;
  if (u_blur != 0) {
    for (int dy = -2; dy <= 1; ++dy)
      for (int dx = -2; dx <= 1; ++dx) {
        ivec2 q = c + ivec2(dx, dy);
        if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, wsize))) continue;
        if (!sameSurface(P.xyz, ng, texelFetch(t_position, min(q * u_scale, fsize - 1), 0))) continue;
        sum += texelFetch(t_ao, q, 0).r;
        count += 1.0;
      }
  } else if (u_scale == 1) {
    sum = texelFetch(t_ao, px, 0).r;
    count = 1.0;
  } else {
    // Half resolution: of the 2x2 nearest estimates, the one closest to this pixel's tangent plane.
    ivec2 base = (px - 1) / 2;
    float best = 3.0e38;
    for (int dy = 0; dy <= 1; ++dy)
      for (int dx = 0; dx <= 1; ++dx) {
        ivec2 q = clamp(base + ivec2(dx, dy), ivec2(0), wsize - 1);
        vec4 Pq = texelFetch(t_position, min(q * u_scale, fsize - 1), 0);
        if (Pq.w <= 0.0) continue;
        float d = abs(dot(Pq.xyz - P.xyz, ng));
        if (d < best) {
          best = d;
          sum = texelFetch(t_ao, q, 0).r;
          count = 1.0;
        }
      }
  }
  float a = count > 0.0 ? sum / count : texelFetch(t_ao, min(c, wsize - 1), 0).r;
  a = isnan(a) ? 1.0 : clamp(a, 0.0, 1.0);
  o_ao = a;
  vec3 albedo = texelFetch(t_albedo, px, 0).rgb;
  vec4 m = texelFetch(t_material, px, 0);
  vec3 diffuseAlbedo = albedo * (1.0 - m.x) * (1.0 - m.w) * m.z;
  // The environment's diffuse light: SH irradiance by the shading normal (E / pi = L^a for a uniform
  // sky), with the Fresnel weight glTF's fresnel_mix leaves the diffuse base (ImageBasedLighting.h).
  vec3 n = texelFetch(t_normal, px, 0).xyz;
  vec3 wo = u_frame.flags.x != 0 ? -u_frame.viewForward.xyz : normalize(u_frame.eye.xyz - P.xyz);
  MaterialParams p = materialParams(albedo, m.x, m.y, m.w, texelFetch(t_emission, px, 0).a);
  p.specular = texelFetch(t_specular, px, 0);
  vec3 nc = decodeLayers(texelFetch(t_layers, px, 0), p);
  float w = iblDiffuseWeight(t_dfg, nc, wo, max(dot(n, wo), 0.0), p);
  o_beauty = vec4(iblIrradiance(n) * INV_PI * w * diffuseAlbedo * a, 0.0);
}
