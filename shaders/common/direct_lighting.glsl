// Direct lighting of a surface point by every punctual light, with PCF shadow maps: the code the
// `direct` pass runs per pixel and that other passes (environment cube maps, ...) run per fragment.
// C++ side: renderer/shading/DirectLighting.h binds what this needs.
#ifndef RADIANT_COMMON_DIRECT_LIGHTING
#define RADIANT_COMMON_DIRECT_LIGHTING
#include "common/brdf.glsl"
#include "common/lights.glsl"

layout(binding = kUnitShadowCube) uniform samplerCubeArray t_shadowCube;
layout(binding = kUnitShadow2D) uniform sampler2DArray t_shadow2D;
uniform int u_lightCount;
uniform int u_sceneLightCount;  // lights[u_sceneLightCount ..] are the environment's (EnvironmentLights.h)
// lights[u_diffuseOnlyFrom ..] are the sky lights (EnvironmentLights::skyLights): the residual map's
// diffuse light, shaded with Dirac specular and coat lobes (its glossy part is image-based lighting's).
// Programs that do not bind the frame's lights keep the initialiser: none.
uniform int u_diffuseOnlyFrom = 1073741824;
uniform int u_hasShadows;
uniform int u_pcfRadius;

// Fraction of the PCF kernel that sees the light. Biases are in shadow-map texels converted to world
// units at the receiver, so they scale with the scene: the receiver is pushed along its geometric
// normal by `normalOffset` texels, then compared with a constant `bias` texels of slack.
// The 2D map's kernel (spot and directional lights), r texels around the receiver's texel.
float shadowVisibility2D(int li, vec3 p, vec3 ng, float lightDist, int r) {
  ShadowInfo si = shadows[li];
  if (u_hasShadows == 0 || int(si.params.x) == SHADOW_NONE) return 1.0;
  Light l = lights[li];
  bool ortho = si.params2.x > 0.5;
  float texel = ortho ? si.params.z : si.params.z * lightDist;
  vec3 q = p + ng * (si.params.w * texel);
  float bias = si.params2.y * texel;
  vec4 c = si.viewProj * vec4(q, 1.0);
  if (c.w <= 0.0) return 1.0;
  vec2 uv = c.xy / c.w * 0.5 + 0.5;
  float dist = ortho ? dot(q, l.directionRange.xyz) : length(q - l.positionType.xyz);
  vec2 texelUv = 1.0 / vec2(textureSize(t_shadow2D, 0).xy);
  float lit = 0.0;
  for (int i = -r; i <= r; ++i)
    for (int j = -r; j <= r; ++j) {
      vec2 s = uv + vec2(i, j) * texelUv;
      // Outside the map: nothing was rendered there, so nothing occludes.
      float stored = any(lessThan(s, vec2(0.0))) || any(greaterThan(s, vec2(1.0)))
                         ? 1e30 : texture(t_shadow2D, vec3(s, si.params.y)).r;
      lit += dist - bias <= stored ? 1.0 : 0.0;
    }
  return lit / float((2 * r + 1) * (2 * r + 1));
}
float shadowVisibility(int li, vec3 p, vec3 ng, float lightDist) {
  ShadowInfo si = shadows[li];
  int kind = int(si.params.x);
  if (u_hasShadows == 0 || kind == SHADOW_NONE) return 1.0;
  int r = u_pcfRadius;
  if (kind != SHADOW_CUBE) return shadowVisibility2D(li, p, ng, lightDist, r);
  Light l = lights[li];
  float texel = si.params.z * lightDist;
  vec3 q = p + ng * (si.params.w * texel);
  float bias = si.params2.y * texel;
  vec3 d = q - l.positionType.xyz;
  float dist = length(d);
  vec3 dir = d / max(dist, 1e-30);
  vec3 t = normalize(abs(dir.y) < 0.99 ? cross(dir, vec3(0, 1, 0)) : cross(dir, vec3(1, 0, 0)));
  vec3 b = cross(dir, t);
  float lit = 0.0;
  for (int i = -r; i <= r; ++i)
    for (int j = -r; j <= r; ++j) {
      vec3 sd = dir + (t * float(i) + b * float(j)) * si.params.z;
      float stored = texture(t_shadowCube, vec4(sd, si.params.y)).r;
      lit += dist - bias <= stored ? 1.0 : 0.0;
    }
  return lit / float((2 * r + 1) * (2 * r + 1));
}

// The cosine factor of a sky light (EnvironmentLights::skyLights): its region of the sky as a uniform
// cap of angular radius sigma (the cap with the region's mean cosine about its direction) clipped by
// the receiver's horizon, over the unclipped cap's pi sin^2 sigma. Equal to max(0, cos theta) where
// the whole cap is above the horizon (the light's irradiance is the region's vector irradiance), and
// smooth across it, where a direction alone would switch a broad region's light on or off (walls lit
// by half of a region; contact shadows lit by the regions on the horizon). The clipped cap's
// illuminance is Lagarde and de Rousiers' ("Moving Frostbite to PBR", SIGGRAPH 2014, sphere and disk
// lights with the horizon), from Snyder's closed form.
float skyCapCosine(float cosTheta, float sigma) {
  float sin2 = min(1.0, sin(sigma) * sin(sigma));
  if (sin2 < 1e-6 || cosTheta * cosTheta > sin2) return max(cosTheta, 0.0);
  float sinTheta = sqrt(max(0.0, 1.0 - cosTheta * cosTheta));
  float x = sqrt(max(0.0, 1.0 / sin2 - 1.0));
  float y = clamp(-x * cosTheta / max(sinTheta, 1e-6), -1.0, 1.0);
  float sinThetaSqrtY = sinTheta * sqrt(max(0.0, 1.0 - y * y));
  float e = (cosTheta * acos(y) - x * sinThetaSqrtY) * sin2 + atan(sinThetaSqrtY, x);
  return max(e, 0.0) / (3.14159265358979 * sin2);
}

// The sky lights' (lights[u_diffuseOnlyFrom .. u_lightCount)) irradiance at p, shadowed: what the sky
// loop of directLighting below gives a Lambertian lobe, times pi / albedo (specular/map_sky.comp).
vec3 skyIrradiance(vec3 p, vec3 n, vec3 ng) {
  vec3 E = vec3(0.0);
  for (int i = u_diffuseOnlyFrom; i < u_lightCount; ++i) {
    LightSample s = sampleLight(lights[i], p);
    float k = skyCapCosine(dot(n, s.wi), max(lights[i].spotCone.z, 0.0));
    if (k <= 0.0) continue;
    E += k * s.intensity * shadowVisibility2D(i, p, ng, s.dist, u_pcfRadius);
  }
  return E;
}

// Sum over the first `count` lights of f(wi, wo) cos(theta_i) E_light V_shadow (no emission). n is the
// shading normal (facing wo), ng the geometric normal on the same side (used for the shadow normal
// offset). nc is the clear coat's normal (KHR_materials_clearcoat; n when there is no coat).
// A light with an angular radius (an environment light: a disc of the sky, not a delta) is reflected
// by a lobe at least as wide as the disc's mirror image: GGX's D falls to half at tan(theta_h) = 0.64
// alpha, and the disc's half-vectors reach radius / 2, so alpha >= 0.78 radius (roughness = sqrt).
// lightsWithoutSpecular: lights from this index on are evaluated with Dirac specular and coat lobes
// (roughness 0: only the diffuse lobe, under their Fresnel weights, carries light to a light's
// direction). `direct` passes u_sceneLightCount on pixels the specular pass owns: that pass reflects the
// whole environment map, its lights included, so their glossy lobes are its; their diffuse lobe (a
// metal of metallic 0.67 is a third dielectric) is this pass's.
// skyVisibility: the shadow maps' visibility of the sky lights, weighted by the light each gives the
// surface (luminance of E times skyCapCosine), 1 where no sky light reaches it: the residual sky's
// diffuse visibility, which `direct` turns into specular occlusion (specularOcclusion below).
vec3 directLighting(vec3 p, vec3 n, vec3 nc, vec3 ng, vec3 wo, MaterialParams material, int count,
                    int lightsWithoutSpecular, out float skyVisibility) {
  vec3 L = vec3(0.0);
  lightsWithoutSpecular = min(lightsWithoutSpecular, u_diffuseOnlyFrom);
  // The scene's lights and the environment's compact lights.
  int skyFrom = min(count, u_diffuseOnlyFrom);
  for (int i = 0; i < skyFrom; ++i) {
    LightSample s = sampleLight(lights[i], p);
    MaterialParams m = material;
    float radius = lights[i].spotCone.z;
    if (i >= lightsWithoutSpecular) {
      m.surface.y = 0.0;
      m.clearcoat.y = 0.0;
    } else if (radius > 0.0) {
      float floorRoughness = sqrt(0.78 * radius);
      m.surface.y = max(m.surface.y, floorRoughness);
      m.clearcoat.y = max(m.clearcoat.y, floorRoughness);
    }
    vec3 f = gltfBsdfCos(n, nc, wo, s.wi, m, m.surface.w);
    if (all(equal(f, vec3(0.0)))) continue;
    L += f * s.intensity * shadowVisibility(i, p, ng, s.dist);
  }
  // The sky lights, in a loop of their own: directional, 2D shadow maps, Dirac specular lobes. (A
  // software rasteriser runs every branch of a loop body for every light: one shared loop made each
  // sky light pay for the cube-map kernel and a second BSDF evaluation; docs/PERFORMANCE.md.)
  MaterialParams m = material;
  m.surface.y = 0.0;
  m.clearcoat.y = 0.0;
  float skyOpen = 0.0, skySeen = 0.0;
  for (int i = skyFrom; i < count; ++i) {
    // A sky light: its region's cap clipped by the horizon (skyCapCosine). The diffuse lobe is
    // evaluated towards the light, or just above the horizon when the light's centre is below it.
    LightSample s = sampleLight(lights[i], p);
    float c = dot(n, s.wi);
    float k = skyCapCosine(c, max(lights[i].spotCone.z, 0.0));
    if (k <= 0.0) continue;
    float y = k * dot(s.intensity, vec3(0.2126, 0.7152, 0.0722));
    float v = shadowVisibility2D(i, p, ng, s.dist, u_pcfRadius);
    skyOpen += y;
    skySeen += y * v;
    vec3 wi = c >= 0.05 ? s.wi : normalize(s.wi + n * (0.05 - c));
    L += gltfBsdfCos(n, nc, wo, wi, m, m.surface.w) * (k / max(dot(n, wi), 1e-4)) * s.intensity * v;
  }
  skyVisibility = skyOpen > 0.0 ? clamp(skySeen / skyOpen, 0.0, 1.0) : 1.0;
  return L;
}
vec3 directLighting(vec3 p, vec3 n, vec3 nc, vec3 ng, vec3 wo, MaterialParams material, int count,
                    int lightsWithoutSpecular) {
  float unused;
  return directLighting(p, n, nc, ng, wo, material, count, lightsWithoutSpecular, unused);
}
vec3 directLighting(vec3 p, vec3 n, vec3 nc, vec3 ng, vec3 wo, MaterialParams material) {
  return directLighting(p, n, nc, ng, wo, material, u_lightCount, u_lightCount);
}

// Specular occlusion from a diffuse visibility `ao` (Lagarde and de Rousiers, "Moving Frostbite to
// PBR", SIGGRAPH 2014, section 4.10.2): saturate((n.v + ao)^(2^(-16 alpha - 1)) - 1 + ao), alpha the
// GGX roughness (glTF roughness squared). It is ao for rough lobes and tends to 1 for smooth ones seen
// head-on; 1 where ao is 1.
float specularOcclusion(float nv, float ao, float roughness) {
  float alpha = roughness * roughness;
  return clamp(pow(max(nv, 0.0) + ao, exp2(-16.0 * alpha - 1.0)) - 1.0 + ao, 0.0, 1.0);
}
vec3 directLighting(vec3 p, vec3 n, vec3 ng, vec3 wo, MaterialParams material) {
  return directLighting(p, n, n, ng, wo, material);
}
// The former positional signature, kept for callers not yet on MaterialParams.
vec3 directLighting(vec3 p, vec3 n, vec3 ng, vec3 wo, vec3 albedo, float metallic, float roughness,
                    float transmission, float ior) {
  return directLighting(p, n, ng, wo, materialParams(albedo, metallic, roughness, transmission, ior));
}
#endif
