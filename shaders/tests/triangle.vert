// Test fixture: passes a position and a colour through.
layout(location = 0) in vec2 position;
layout(location = 1) in vec3 colour;
out vec3 vColour;
void main() {
  vColour = colour;
  gl_Position = vec4(position, 0.0, 1.0);
}
