// Test fixture: compiles except for an error inside the included file, which must be reported
// against shaders/tests/include_broken.glsl.
#include "tests/include_broken.glsl"
out vec4 color;
void main() { color = vec4(brokenHelper()); }
