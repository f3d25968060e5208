// The scene buffers. Their records are defined once for GLSL and C++ in common/shared.h
// (renderer/frame/GpuTypes.h static_asserts the C++ side).
#ifndef RADIANT_COMMON_SCENE
#define RADIANT_COMMON_SCENE
#include "common/shared.h"

#define LIGHT_DIRECTIONAL kLightDirectional
#define LIGHT_POINT kLightPoint
#define LIGHT_SPOT kLightSpot
#define SHADOW_NONE kShadowNone
#define SHADOW_CUBE kShadowCube
#define SHADOW_2D kShadow2D

layout(std430, binding = kBindingMaterials) readonly buffer Materials { Material materials[]; };
layout(std430, binding = kBindingLights) readonly buffer Lights { Light lights[]; };
layout(std430, binding = kBindingShadows) readonly buffer Shadows { ShadowInfo shadows[]; };

#endif
