// Stores the light's distance measure: Euclidean distance to the light (point, spot) or the distance
// along the light direction from its origin plane (directional, orthographic).
in vec3 v_position;
uniform vec3 u_lightPosition;
uniform vec3 u_lightDirection;
uniform int u_orthographic;
layout(location = 0) out float o_distance;
void main() {
  o_distance = u_orthographic != 0 ? dot(v_position - u_lightPosition, u_lightDirection)
                                   : length(v_position - u_lightPosition);
}
