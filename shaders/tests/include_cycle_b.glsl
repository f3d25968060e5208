// Test fixture: see include_cycle_a.glsl.
#include "tests/include_cycle_a.glsl"
