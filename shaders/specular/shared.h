// What C++ and GLSL share of the specular pass's layered distance maps: their texture units (read by caustics too,
// through renderer/shading/SpecularMaps.h) and the maps' photon-gather counters.
// Same rules as common/shared.h (every struct member a vec4/ivec4/mat4, nothing included, constants
// declared with RADIANT_CONST): GLSL includes it after "common/shared.h"; C++ after
// renderer/frame/GpuTypes.h, inside namespace radiant::gpu (renderer/shading/SpecularMaps.h).
#ifndef RADIANT_SPECULAR_SHARED_H
#define RADIANT_SPECULAR_SHARED_H

RADIANT_CONST int kUnitPeel = 15;         // previous layer of a distance-map face (map.frag)
RADIANT_CONST int kUnitLdmMaterial = 16;  // the layered distance maps (ldm.glsl)
RADIANT_CONST int kUnitLdmGeometry = 17;
RADIANT_CONST int kUnitLdmDistance = 18;
RADIANT_CONST int kUnitLdmAlbedo = 25;  // the maps' diffuse albedo (caustics, at secondary hits) and mirrors' F0
// uint[3]: the photon gathers of the maps, per kind (map_indirect.comp, stats counters).
RADIANT_CONST int kBindingMapGatherCounts = 8;

#endif
