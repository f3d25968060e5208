// Test fixture: one colour everywhere (the blend tests of tests/gl/render/beauty_test.cpp).
uniform vec4 u_colour;
out vec4 o_colour;
void main() { o_colour = u_colour; }
