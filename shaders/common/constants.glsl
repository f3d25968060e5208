// Shared constants. Included as #include "common/constants.glsl".
#ifndef RADIANT_COMMON_CONSTANTS
#define RADIANT_COMMON_CONSTANTS
const float PI = 3.14159265358979323846;
const float INV_PI = 0.31830988618379067154;
#endif
