// Test fixture: writes the interpolated colour.
in vec3 vColour;
out vec4 color;
void main() { color = vec4(vColour, 1.0); }
