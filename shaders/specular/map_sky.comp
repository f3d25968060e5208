// The sky lights on one face of a layered-distance-map cube (issue 31), after the face is drawn: the
// residual sky's lights (lights[u_diffuseOnlyFrom .. u_lightCount), EnvironmentLights::skyLights) at
// each lit texel's Lambertian term, albedo / pi x their shadowed irradiance (common/direct_lighting.glsl
// skyIrradiance), added to the texel's radiance (specular_ldm_material rgb). map.frag lights the texel
// with the other lights and writes the Lambertian albedo (a diffuse texel's, or a mirror's diffuse
// lobe's) to i_diffuse. Per texel here rather than per fragment there: the maps' level-of-detail
// triangles are about three a texel, and llvmpipe shades a block of lanes for each, so the sky loop per
// fragment was 7 of MetalRoughSpheres' 12.8 s of maps. The Lambertian term is how the maps also take
// photon_gi's photons (map_indirect.comp); against the full BSDF per sky light the frame moved by RMS
// 4e-5 (docs/PERFORMANCE.md).
#include "common/cube_texels.glsl"  // faceDirection
#include "common/direct_lighting.glsl"
#include "common/octahedral.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, rgba32f) readonly uniform imageCubeArray i_geometry;  // oct normal, distance, object
layout(binding = 1, rgba8) readonly uniform image2D i_diffuse;            // this face's Lambertian albedo
layout(binding = 2, rgba16f) uniform imageCubeArray i_material;           // rgb radiance

uniform vec3 u_reference;
uniform int u_layerFace;  // cube * 6 + face
uniform int u_face;
uniform int u_size;

void main() {
  ivec2 px = ivec2(gl_GlobalInvocationID.xy);
  if (px.x >= u_size || px.y >= u_size) return;
  vec3 albedo = imageLoad(i_diffuse, px).rgb;
  if (all(equal(albedo, vec3(0.0)))) return;
  ivec3 t = ivec3(px, u_layerFace);
  vec4 g = imageLoad(i_geometry, t);
  vec3 x = u_reference + normalize(faceDirection(u_face, (vec2(px) + 0.5) / float(u_size) * 2.0 - 1.0)) * g.z;
  vec3 n = normalize(octDecode(g.xy));
  if (dot(n, x - u_reference) > 0.0) n = -n;  // facing the reference point, the map's viewer
  vec4 m = imageLoad(i_material, t);
  imageStore(i_material, t, vec4(m.rgb + albedo * INV_PI * skyIrradiance(x, n, n), m.a));
}
