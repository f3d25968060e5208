// The G-buffer's geometric-normal target (gbuffer/gbuffer.frag o_geoNormal): xyz the geometric normal
// on the side the viewer sees, w two flags: 1 the specular pass owns the surface's reflections
// (Material::isSpecular()), 2 the viewer sees the back of the triangle's winding (so the winding's front
// normal is -xyz: photon_gi's coverage points carry the winding's front, photon_gi/photon.glsl).
#ifndef RADIANT_COMMON_GBUFFER_GEOMETRY
#define RADIANT_COMMON_GBUFFER_GEOMETRY
float gbufferGeoFlags(bool specularOwned, bool frontFacing) {
  return (specularOwned ? 1.0 : 0.0) + (frontFacing ? 0.0 : 2.0);
}
bool gbufferSpecularOwned(vec4 geo) { return (int(geo.w + 0.5) & 1) != 0; }
vec3 gbufferWindingNormal(vec4 geo) { return (int(geo.w + 0.5) & 2) != 0 ? -geo.xyz : geo.xyz; }
#endif
