// Photon tracing pass (thesis 6.1.1): the generator rasterised from the light, P x P pixels; per
// pixel the light ray is followed through the generator and the environment in the layered distance
// maps of the specular pass (ch. 5, Algorithm 3) to its first non-specular hit h. One path, no
// branching: a reflection multiplies the power by F, a refraction by (1 - F) and the transmission
// tint (power, not radiance: no 1 / eta^2), total internal reflection reflects with F = 1. A
// refractor's entry reflection (F) is a second hit image of its own (u_reflectFirst), so that the
// weak reflection caustic is not lost (the thesis follows the refraction only).
// The power of a pixel is the light's power through it (exact solid angle x intensity for point and
// spot lights, pixel area x irradiance for directional lights).
#define LDM_TRACING
#include "common/direct_lighting.glsl"
#include "common/material.glsl"
#include "specular/ldm.glsl"
#include "caustics/cube.glsl"

in vec3 v_position;
in vec3 v_normal;
in vec2 v_uv0;
in vec2 v_uv1;

uniform int u_material;
uniform int u_object;   // the generator (its maps are searched first, its reference point is c_G)
uniform int u_light;
uniform int u_orthographic;  // 1: directional light (orthographic light camera)
uniform float u_halfExtent;  // tan(half field of view) (perspective) or half the side (orthographic)
uniform int u_maxDepth;
uniform int u_reflectFirst;  // 1: at a refractor's entry take the Fresnel reflection (second hit image)
uniform int u_photonResolution;

layout(location = 0) out vec4 o_hit;
layout(location = 1) out vec4 o_power;
layout(location = 2) out vec4 o_normal;

// Solid angle of the rectangle [lo, hi] on the plane at unit distance in front of the eye:
// sum over corners of +-atan(x y / sqrt(1 + x^2 + y^2)).
float rectangleSolidAngle(vec2 lo, vec2 hi) {
  #define CORNER(x, y) atan((x) * (y) / sqrt(1.0 + (x) * (x) + (y) * (y)))
  return CORNER(hi.x, hi.y) - CORNER(lo.x, hi.y) - CORNER(hi.x, lo.y) + CORNER(lo.x, lo.y);
  #undef CORNER
}

vec3 schlick(vec3 f0, float cosTheta) {
  float m = clamp(1.0 - cosTheta, 0.0, 1.0);
  float m2 = m * m;
  return f0 + (1.0 - f0) * (m2 * m2 * m);
}

void invalid() {
  o_hit = vec4(0.0);
  o_power = vec4(0.0, 0.0, 0.0, -1.0);
  o_normal = vec4(0.0);
}

void main() {
  SurfaceUv uv = SURFACE_UV_FRAGMENT(v_uv0, v_uv1);  // before any discard (common/material.glsl)
  Material m = materials[u_material];
  if (materialMasked(m, decodeBaseColor(m, uv).a)) discard;
  MaterialParams p = decodeMaterial(m, uv);
  Light light = lights[u_light];

  // This pixel's share of the light's power.
  float P = float(u_photonResolution);
  vec2 cellLo = (floor(gl_FragCoord.xy) / P * 2.0 - 1.0) * u_halfExtent;
  vec2 cellHi = cellLo + 2.0 * u_halfExtent / P;
  vec3 R;
  vec3 power;
  float lightDist;
  if (u_orthographic != 0) {
    R = light.directionRange.xyz;
    power = light.radiantIntensity.rgb * (cellHi.x - cellLo.x) * (cellHi.y - cellLo.y);
    lightDist = 1e30;
  } else {
    vec3 toP = v_position - light.positionType.xyz;
    lightDist = length(toP);
    R = toP / max(lightDist, 1e-30);
    power = light.radiantIntensity.rgb * rectangleSolidAngle(cellLo, cellHi) * rangeWindow(lightDist, light.directionRange.w);
    if (int(light.positionType.w) == LIGHT_SPOT) power *= spotFalloff(light, -R);
  }
  // Occluders between the light and the generator: the light's shadow map (the generator is in it,
  // so its own entry point is lit).
  vec3 faceNormal = cross(dFdx(v_position), dFdy(v_position));
  faceNormal = dot(faceNormal, faceNormal) > 1e-30 ? normalize(faceNormal) : -R;
  vec3 ng = dot(faceNormal, R) > 0.0 ? -faceNormal : faceNormal;
  power *= shadowVisibility(u_light, v_position, ng, lightDist);

  vec3 n = dot(v_normal, v_normal) > 1e-30 ? normalize(v_normal) : faceNormal;
  vec4 texel = specularTexel(p.baseColor.rgb, p.surface.x, p.surface.z, p.surface.w);
  vec3 pos = v_position;
  int object = u_object;
  vec3 origin = objects[u_object].referenceRadius.xyz;
  bool inside = false;  // the photon travels inside `object`, whose KHR_materials_volume medium absorbs
  for (int depth = 1; depth <= u_maxDepth; ++depth) {
    // One ideal specular interaction at pos (n as modelled: outward).
    bool entering = dot(n, R) < 0.0;
    vec3 nn = entering ? n : -n;  // faces the incoming ray
    float cosI = clamp(-dot(R, nn), 0.0, 1.0);
    float eps = objects[object].referenceRadius.w * (1e-3 + 0.5 / u_cubeResolution);
    vec3 surface = pos;  // the interaction point, before the self-intersection offset
    if (texel.a < 0.0) {
      power *= schlick(texel.rgb, cosI);
      R = normalize(reflect(R, nn));
      pos += nn * eps;
      inside = !entering;
    } else {
      float ior = texel.a;
      float eta = entering ? ior : 1.0 / ior;  // n_t / n_i
      float F = fresnelDielectric(cosI, eta);
      vec3 rf = refract(R, nn, 1.0 / eta);
      if (depth == 1 && u_reflectFirst != 0) {  // the reflection branch of the entry: power x F
        power *= F;
        R = normalize(reflect(R, nn));
        pos += nn * eps;
        inside = !entering;
      } else if (F >= 1.0 || dot(rf, rf) == 0.0) {  // total internal reflection
        R = normalize(reflect(R, nn));
        pos += nn * eps;
        inside = !entering;
      } else {
        power *= (1.0 - F) * texel.rgb;
        R = normalize(rf);
        pos -= nn * eps;
        inside = entering;
      }
    }
    if (!(max(power.r, max(power.g, power.b)) > 0.0)) break;
    float d;
    int layer;
    if (!traceLayers(object, pos, R, d, layer)) break;  // leaves the scene: no receiver
    vec3 hit = pos + R * d;
    // KHR_materials_volume: Beer-Lambert over the traced length inside (specular/ldm.glsl), from the
    // interaction point: the origin's offset (~0.3% of the object's radius) would otherwise go unabsorbed.
    if (inside) power *= volumeTransmittance(object, length(hit - surface));
    vec3 dir = hit - objects[object].referenceRadius.xyz;
    if (dot(dir, dir) < 1e-30) dir = R;
    float cube = float(object * u_layers + layer);
    vec4 hitTexel = texture(t_ldmMaterial, vec4(dir, cube));
    vec4 geo = texture(t_ldmGeometry, vec4(dir, cube));
    int code = int(geo.w + 0.5);
    if (hitTexel.a == 0.0 || code == 0) {
      // The first non-specular surface: a photon hit. The search converges on the linearly filtered
      // distance, which bulges between texels; the triangle areas are differences of hit positions,
      // so that noise would become noise in I = dPhi / dA. The hit is therefore moved onto the
      // tangent plane of the nearest texel's surface point (exact for planar receivers) when that
      // plane is within a few texels of the search's answer.
      vec3 ns = octDecode(geo.xy);
      vec3 centre = normalize(cubeTexelCentre(dir, u_cubeResolution));
      vec3 S = objects[object].referenceRadius.xyz + centre * geo.z;
      float rn = dot(R, ns);
      if (abs(rn) > 1e-3) {
        float dPlane = dot(S - pos, ns) / rn;
        float slack = 4.0 * 2.0 * geo.z / u_cubeResolution / abs(rn);
        if (dPlane > 0.0 && abs(dPlane - d) < slack) hit = pos + R * dPlane;
      }
      o_hit = vec4(hit - origin, 1.0);
      o_power = vec4(power, 1.0);
      o_normal = vec4(octDecode(geo.xy), 0.0);
      return;
    }
    n = octDecode(geo.xy);
    texel = mapSpecularTexel(hitTexel, dir, cube);
    object = code - 1;
    pos = hit;
  }
  invalid();  // lost: no receiver within max_depth interactions, or no power left
}
