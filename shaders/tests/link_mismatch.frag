// Test fixture: reads an input that tests/triangle.vert does not write, so linking fails.
in vec3 vNotWritten;
out vec4 color;
void main() { color = vec4(vNotWritten, 1.0); }
