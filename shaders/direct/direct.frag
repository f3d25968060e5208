// Direct lighting from punctual lights with shadow maps, plus emission, from the G-buffer.
// Writes the `direct` AOV and initialises `beauty` with the same value (later passes add to beauty).
#include "common/brdf.glsl"
#include "common/lights.glsl"

in vec2 v_uv;

layout(binding = 0) uniform sampler2D t_position;
layout(binding = 1) uniform sampler2D t_normal;
layout(binding = 2) uniform sampler2D t_albedo;
layout(binding = 3) uniform sampler2D t_material;
layout(binding = 4) uniform sampler2D t_emission;
layout(binding = 5) uniform sampler2D t_geoNormal;
layout(binding = 6) uniform samplerCubeArray t_shadowCube;
layout(binding = 7) uniform sampler2DArray t_shadow2D;

uniform int u_lightCount;
uniform int u_hasShadows;
uniform int u_pcfRadius;
uniform vec3 u_eye;
uniform vec3 u_viewForward;
uniform int u_orthographic;
uniform vec3 u_background;  // radiance seen where no surface is (the uniform sky)

layout(location = 0) out vec4 o_direct;
layout(location = 1) out vec4 o_beauty;

// Fraction of the PCF kernel that sees the light. Biases are in shadow-map texels converted to world
// units at the receiver, so they scale with the scene: the receiver is pushed along its geometric
// normal by `normalOffset` texels, then compared with a constant `bias` texels of slack.
float shadowVisibility(int li, vec3 p, vec3 ng, float lightDist) {
  ShadowInfo si = shadows[li];
  int kind = int(si.params.x);
  if (u_hasShadows == 0 || kind == SHADOW_NONE) return 1.0;
  Light l = lights[li];
  bool ortho = si.params2.x > 0.5;
  float texel = ortho ? si.params.z : si.params.z * lightDist;
  vec3 q = p + ng * (si.params.w * texel);
  float bias = si.params2.y * texel;
  float layer = si.params.y;
  int r = u_pcfRadius;
  float lit = 0.0;
  float count = 0.0;
  if (kind == SHADOW_CUBE) {
    vec3 d = q - l.positionType.xyz;
    float dist = length(d);
    vec3 dir = d / max(dist, 1e-30);
    vec3 t = normalize(abs(dir.y) < 0.99 ? cross(dir, vec3(0, 1, 0)) : cross(dir, vec3(1, 0, 0)));
    vec3 b = cross(dir, t);
    for (int i = -r; i <= r; ++i)
      for (int j = -r; j <= r; ++j) {
        vec3 sd = dir + (t * float(i) + b * float(j)) * si.params.z;
        float stored = texture(t_shadowCube, vec4(sd, layer)).r;
        lit += dist - bias <= stored ? 1.0 : 0.0;
        count += 1.0;
      }
  } else {
    vec4 c = si.viewProj * vec4(q, 1.0);
    if (c.w <= 0.0) return 1.0;
    vec2 uv = c.xy / c.w * 0.5 + 0.5;
    float dist = ortho ? dot(q, l.directionRange.xyz) : length(q - l.positionType.xyz);
    vec2 texelUv = 1.0 / vec2(textureSize(t_shadow2D, 0).xy);
    for (int i = -r; i <= r; ++i)
      for (int j = -r; j <= r; ++j) {
        vec2 s = uv + vec2(i, j) * texelUv;
        // Outside the map: nothing was rendered there, so nothing occludes.
        float stored = any(lessThan(s, vec2(0.0))) || any(greaterThan(s, vec2(1.0)))
                           ? 1e30 : texture(t_shadow2D, vec3(s, layer)).r;
        lit += dist - bias <= stored ? 1.0 : 0.0;
        count += 1.0;
      }
  }
  return lit / count;
}

void main() {
  ivec2 px = ivec2(gl_FragCoord.xy);
  vec4 P = texelFetch(t_position, px, 0);
  if (P.w <= 0.0) {
    o_direct = vec4(u_background, 1.0);
    o_beauty = o_direct;
    return;
  }
  vec3 p = P.xyz;
  vec3 n = texelFetch(t_normal, px, 0).xyz;
  vec3 albedo = texelFetch(t_albedo, px, 0).rgb;
  vec4 mat = texelFetch(t_material, px, 0);
  vec4 emissionIor = texelFetch(t_emission, px, 0);
  vec3 emission = emissionIor.rgb;
  vec3 ng = texelFetch(t_geoNormal, px, 0).xyz;
  vec3 wo = u_orthographic != 0 ? -u_viewForward : normalize(u_eye - p);
  // Interpolated or mapped normals can face away from the viewer at silhouettes; bend them back just
  // enough to be visible instead of shading them black (NdotV >= 1e-3).
  float nv = dot(n, wo);
  if (nv < 1e-3) n = normalize(n + wo * (1e-3 - nv));

  vec3 L = emission;
  for (int i = 0; i < u_lightCount; ++i) {
    LightSample s = sampleLight(lights[i], p);
    vec3 f = gltfBrdfCos(n, wo, s.wi, albedo, mat.x, mat.y, mat.w, emissionIor.a);
    if (all(equal(f, vec3(0.0)))) continue;
    L += f * s.intensity * shadowVisibility(i, p, ng, s.dist);
  }
  o_direct = vec4(L, 1.0);
  o_beauty = o_direct;
}
