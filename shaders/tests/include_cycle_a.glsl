// Test fixture: a -> b -> a include cycle, which the preprocessor must reject.
#include "tests/include_cycle_b.glsl"
