// The sky lights on one face of a layered-distance-map cube (issue 31), after the face is drawn: the
// residual sky's lights (lights[u_diffuseOnlyFrom .. u_lightCount), EnvironmentLights::skyLights) at
// each lit texel's Lambertian term, albedo / pi x their shadowed irradiance (common/direct_lighting.glsl
// skyIrradiance), added to the texel's radiance (specular_ldm_material rgb). map.frag lights the texel
// with the other lights and writes the Lambertian albedo (a diffuse texel's, or a mirror's diffuse
// lobe's) to i_diffuse. Per texel here rather than per fragment there: the maps' level-of-detail
// triangles are about three a texel, and llvmpipe shades a block of lanes for each, so the sky loop per
// fragment was 7 of MetalRoughSpheres' 12.8 s of maps. The Lambertian term is how the maps also take
// photon_gi's photons (map_indirect.comp); against the full BSDF per sky light per fragment the frame
// moved by RMS 8.5e-5, max 0.016 on a sun glint of 29.7 (docs/performance/specular.md).
#include "common/direct_lighting.glsl"
#include "specular/map_texel.glsl"  // texelPoint, texelNormal; u_reference, u_face, u_size

layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, rgba32f) readonly uniform imageCubeArray i_geometry;  // oct normal, distance, object
layout(binding = 1, rgba8) readonly uniform image2D i_diffuse;            // this face's Lambertian albedo
layout(binding = 2, rgba16f) uniform imageCubeArray i_material;           // rgb radiance

uniform int u_layerFace;  // cube * 6 + face

void main() {
  ivec2 px = ivec2(gl_GlobalInvocationID.xy);
  if (px.x >= u_size || px.y >= u_size) return;
  vec3 albedo = imageLoad(i_diffuse, px).rgb;
  if (all(equal(albedo, vec3(0.0)))) return;
  ivec3 t = ivec3(px, u_layerFace);
  vec4 g = imageLoad(i_geometry, t);
  vec3 x = texelPoint(px, g);
  vec3 n = texelNormal(g, x);
  vec4 m = imageLoad(i_material, t);
  imageStore(i_material, t, vec4(m.rgb + albedo * INV_PI * skyIrradiance(x, n, n), m.a));
}
