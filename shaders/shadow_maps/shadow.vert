layout(location = 0) in vec3 a_position;
layout(location = 2) in vec2 a_uv0;
layout(location = 3) in vec2 a_uv1;
uniform mat4 u_viewProj;
out vec3 v_position;
out vec2 v_uv0;  // the alpha test of MASK and BLEND materials (shadow.frag)
out vec2 v_uv1;
void main() {
  v_position = a_position;
  v_uv0 = a_uv0;
  v_uv1 = a_uv1;
  gl_Position = u_viewProj * vec4(a_position, 1.0);
}
