// What C++ and GLSL share of ambient_occlusion: the resolve's texture unit.
// Same rules as common/shared.h (every struct member a vec4/ivec4/mat4, nothing included, constants
// declared with RADIANT_CONST): GLSL includes it after "common/shared.h"; C++ after
// renderer/frame/GpuTypes.h, inside namespace radiant::gpu (renderer/techniques/ambient_occlusion/AmbientOcclusion.cpp).
#ifndef RADIANT_AMBIENT_OCCLUSION_SHARED_H
#define RADIANT_AMBIENT_OCCLUSION_SHARED_H

RADIANT_CONST int kUnitAoEmission = 21;  // the resolve's emission target (a = ior; ao_resolve.frag)

#endif
