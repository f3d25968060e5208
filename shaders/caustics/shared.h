// What C++ and GLSL share of the caustics pass: the caustic cube maps' texture unit.
// Same rules as common/shared.h (every struct member a vec4/ivec4/mat4, nothing included, constants
// declared with RADIANT_CONST): GLSL includes it after "common/shared.h"; C++ after
// renderer/frame/GpuTypes.h, inside namespace radiant::gpu (renderer/techniques/caustics/Caustics.cpp).
#ifndef RADIANT_CAUSTICS_SHARED_H
#define RADIANT_CAUSTICS_SHARED_H

RADIANT_CONST int kUnitCausticCube = 24;  // the caustic cube maps (irradiance per receiver area; lookup.glsl)

#endif
