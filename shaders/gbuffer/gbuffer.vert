// Positions are already in world space (the loader flattens the node hierarchy).
#include "common/frame.glsl"
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec2 a_uv0;
layout(location = 3) in vec2 a_uv1;
layout(location = 4) in vec4 a_tangent;

out vec3 v_position;
out vec3 v_normal;
out vec2 v_uv0;
out vec2 v_uv1;
out vec4 v_tangent;

void main() {
  v_position = a_position;
  v_normal = a_normal;
  v_uv0 = a_uv0;
  v_uv1 = a_uv1;
  v_tangent = a_tangent;
  gl_Position = u_frame.viewProj * vec4(a_position, 1.0);
}
