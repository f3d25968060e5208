// Renders one layer of one face of a layered distance map (thesis 5.1.1): material data, normal and
// distance from the reference point. Diffuse surfaces store their reflected radiance towards the
// reference point: emission plus direct lighting of the punctual lights with the shared
// shadow-mapped code (common/direct_lighting.glsl), plus the environment's glossy reflection (the
// split-sum `direct` adds on screen, L(sky)GE, when u_iblMode is set). Mirrors store their F0 and the
// radiance of their diffuse lobe (ldm.glsl).
#include "common/direct_lighting.glsl"
#include "common/ibl.glsl"
#include "common/material.glsl"
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

layout(binding = kUnitPeel) uniform sampler2D t_peel;  // previous layer of this face (z = distance, 0 = empty)
layout(binding = kUnitIblDfg) uniform sampler2D t_dfg;
layout(binding = kUnitIblPrefiltered) uniform sampler2DArray t_prefiltered;

layout(location = 0) out vec4 o_material;
layout(location = 1) out vec4 o_geometry;
layout(location = 2) out float o_distance;  // cleared to kEmptyDistance
layout(location = 3) out vec4 o_albedo;     // rgb diffuse albedo of a non-specular, lit surface (a 1), a mirror's F0 (a 0), else 0
layout(location = 4) out vec4 o_diffuse;    // the Lambertian albedo the sky lights reach (map_sky.comp), else 0

void main() {
  SurfaceUv uv = SURFACE_UV_FRAGMENT(v_uv0, v_uv1);  // before any discard (common/material.glsl)
  if (u_faceMode == 0 && !gl_FrontFacing) discard;
  if (u_faceMode == 1 && gl_FrontFacing) discard;
  Material m = materials[u_material];
  if (materialMasked(m, decodeBaseColor(m, uv).a)) discard;

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

  MaterialParams p = decodeMaterial(m, uv);
  o_albedo = vec4(0.0);
  // Two-sided shading towards the viewer of the map, the reference point (view-dependent terms
  // are therefore evaluated for that viewer: the usual distance-map approximation).
  vec3 wo = dist > 1e-30 ? -toP / dist : n;
  vec3 ns = dot(n, wo) < 0.0 ? -n : n;
  vec3 ng = dot(faceNormal, wo) < 0.0 ? -faceNormal : faceNormal;
  float nv = dot(ns, wo);
  if (nv < 1e-3) ns = normalize(ns + wo * (1e-3 - nv));
  // glTF emission leaves the front face only unless the material is double-sided (as the reference).
  bool emits = gl_FrontFacing || materialDoubleSided(m);
  bool specular = u_objectCode > 0 && specularInMaps(p.surface.x, p.surface.z);
  vec4 texel = specular ? specularTexel(p.baseColor.rgb, p.surface.x, p.surface.z, p.surface.w) : vec4(0.0);
  bool mirror = specular && texel.a < 0.0;
  // One light loop for the two kinds of lit texel (llvmpipe runs both branches of an `if` with a loop in
  // each: two loops per fragment; docs/PERFORMANCE.md): a diffuse texel with every lobe, a mirror's
  // diffuse lobe with Dirac specular and coat lobes (lightsWithoutSpecular 0).
  // The sky lights are map_sky.comp's, per texel, on this Lambertian albedo; the others are lit here.
  vec3 diffuseAlbedo = materialUnlit(m) ? vec3(0.0) : p.baseColor.rgb * (1.0 - p.surface.x) * (1.0 - p.surface.z);
  int lights = min(u_lightCount, u_diffuseOnlyFrom);
  vec3 lit = vec3(0.0);
  o_diffuse = vec4(0.0);
  if (!specular || mirror) {
    lit = (emits ? p.emission.rgb : vec3(0.0)) + directLighting(v_position, ns, ns, ng, wo, p, lights,
                                                                mirror ? 0 : lights);
    o_diffuse = vec4(diffuseAlbedo, 1.0);
  }
  if (specular) {
    o_material = texel;
    if (mirror) {
      // A mirror keeps its F0 in the albedo map (a = 0: not a lit diffuse texel) and the radiance of
      // its diffuse lobe in the material map: its emission and the lights' direct light, which the
      // trace adds to what the mirror reflects, as `direct` lights the diffuse lobe of the mirror
      // pixels on screen. Without it a metallic 0.67 sphere seen in another mirror reflected only the
      // dark ground where the reference saw its sunlit dielectric third (MetalRoughSpheres' worst pixel).
      o_albedo = vec4(texel.rgb, 0.0);
      o_material = vec4(lit, -1.0);
    }
  } else {
    // The Lambertian part of the glTF BRDF (what the caustics pass lights at the maps' texels).
    if (!materialUnlit(m)) o_albedo = vec4(diffuseAlbedo, 1.0);
    vec3 L = lit;
    // The environment's glossy lobe (its diffuse lobe is photon_gi's photons, gathered into the maps
    // with the Lambertian term): without it a rough metal seen in a mirror was black but for its sun
    // glints (MetalRoughSpheres' mirror spheres reflecting their rough neighbours). Times the
    // material's baked occlusion, as on screen; the coat normal is the shading normal here.
    if (u_iblMode != IBL_NONE && !materialUnlit(m)) L += p.emission.a * iblSpecular(t_dfg, t_prefiltered, ns, ns, wo, p);
    if (materialUnlit(m)) L = p.baseColor.rgb;  // KHR_materials_unlit: its base colour, lit by nothing
    o_material = vec4(L, 0.0);
  }
  o_geometry = vec4(octEncode(n), max(dist, 1e-30), float(u_objectCode));
  o_distance = max(dist, 1e-30);
}
