// Test fixture (tests/gl/gl/ShaderLibraryTest.cpp): must fail to compile, and the error must be
// reported on the line of UNDECLARED_IN_BROKEN_FRAG in this file although includes come before it.
#include "tests/include_ok.glsl"
#if 0
// A skipped include: its #line directives are skipped too, which must not shift the lines below.
#include "common/constants.glsl"
#endif
out vec4 color;
void main() {
  color = vec4(includeOk(), 0.0, 0.0, 1.0);
  color.g = UNDECLARED_IN_BROKEN_FRAG;
}
