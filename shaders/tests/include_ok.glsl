// Test fixture: a valid include that itself includes a guarded common file.
#ifndef RADIANT_TESTS_INCLUDE_OK
#define RADIANT_TESTS_INCLUDE_OK
#include "common/constants.glsl"
float includeOk() { return PI * INV_PI; }
#endif
