// Renders one layer of one face of a layered distance map (thesis 5.1.1): material data, normal and
// distance from the reference point. Diffuse surfaces store their reflected radiance towards the
// reference point: emission plus direct lighting of the punctual lights with the shared
// shadow-mapped code (common/direct_lighting.glsl).
#include "common/direct_lighting.glsl"
#include "specular/ldm.glsl"

in vec3 v_position;
in vec3 v_normal;
in vec2 v_uv0;
in vec2 v_uv1;

uniform int u_material;
uniform vec3 u_reference;
uniform int u_faceMode;    // 0 front faces only, 1 back faces only, 2 both (as seen from the reference point)
uniform int u_peel;        // 1: keep only surfaces beyond the previous layer (depth peeling)
uniform int u_objectCode;  // specular object index + 1 of this mesh, 0 = diffuse

layout(binding = 8) uniform sampler2D t_baseColor;
layout(binding = 9) uniform sampler2D t_metallicRoughness;
layout(binding = 12) uniform sampler2D t_emissive;
layout(binding = 13) uniform sampler2D t_peel;  // previous layer of this face (z = distance, 0 = empty)

layout(location = 0) out vec4 o_material;
layout(location = 1) out vec4 o_geometry;
layout(location = 2) out float o_distance;  // cleared to kEmptyDistance

vec2 uvSet(int set) { return set == 1 ? v_uv1 : v_uv0; }

void main() {
  if (u_faceMode == 0 && !gl_FrontFacing) discard;
  if (u_faceMode == 1 && gl_FrontFacing) discard;
  Material m = materials[u_material];
  vec4 base = m.baseColorFactor;
  if (m.texturesA.x >= 0) base *= texture(t_baseColor, materialUv(m, SLOT_BASE_COLOR, uvSet(m.texturesA.x)));
  if (int(m.scales.w) == 1 && base.a < m.scales.z) discard;

  vec3 toP = v_position - u_reference;
  float dist = length(toP);
  if (u_peel != 0) {
    // The distance is computed per fragment (non-linear in clip space, thesis 5.1.1), so peeling
    // compares distances, with a relative slack against re-finding the previous layer's surface.
    float prev = texelFetch(t_peel, ivec2(gl_FragCoord.xy), 0).z;
    if (prev <= 0.0 || dist <= prev * (1.0 + 1e-3)) discard;
  }

  vec3 faceNormal = cross(dFdx(v_position), dFdy(v_position));
  faceNormal = dot(faceNormal, faceNormal) > 1e-30 ? normalize(faceNormal) : vec3(0, 1, 0);
  vec3 n = dot(v_normal, v_normal) > 1e-30 ? normalize(v_normal) : faceNormal;

  float metallic = m.metallicRoughness.x;
  float roughness = m.metallicRoughness.y;
  if (m.texturesA.y >= 0) {
    vec4 mr = texture(t_metallicRoughness, materialUv(m, SLOT_METALLIC_ROUGHNESS, uvSet(m.texturesA.y)));
    roughness *= mr.g;
    metallic *= mr.b;
  }
  float transmission = m.metallicRoughness.z;
  float ior = m.metallicRoughness.w;

  if (u_objectCode > 0) {
    o_material = specularTexel(base.rgb, clamp(metallic, 0.0, 1.0), transmission, ior);
  } else {
    // Two-sided shading towards the viewer of the map, the reference point (view-dependent terms
    // are therefore evaluated for that viewer: the usual distance-map approximation).
    vec3 wo = dist > 1e-30 ? -toP / dist : n;
    vec3 ns = dot(n, wo) < 0.0 ? -n : n;
    vec3 ng = dot(faceNormal, wo) < 0.0 ? -faceNormal : faceNormal;
    float nv = dot(ns, wo);
    if (nv < 1e-3) ns = normalize(ns + wo * (1e-3 - nv));
    vec3 emission = m.emission.rgb;
    if (m.texturesB.x >= 0) emission *= texture(t_emissive, materialUv(m, SLOT_EMISSIVE, uvSet(m.texturesB.x))).rgb;
    // glTF emission leaves the front face only unless the material is double-sided (as the reference).
    bool emits = gl_FrontFacing || m.texturesB.y != 0;
    vec3 L = (emits ? emission : vec3(0.0)) +
             directLighting(v_position, ns, ng, wo, base.rgb, clamp(metallic, 0.0, 1.0),
                            clamp(roughness, 0.0, 1.0), transmission, ior);
    if (m.texturesB.z != 0) L = base.rgb;  // KHR_materials_unlit: its base colour, lit by nothing
    o_material = vec4(L, 0.0);
  }
  o_geometry = vec4(octEncode(n), max(dist, 1e-30), float(u_objectCode));
  o_distance = max(dist, 1e-30);
}
