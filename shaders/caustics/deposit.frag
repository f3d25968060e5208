// Additive deposit into the caustic cube map: rgb = irradiance per receiver area E (triangles,
// splats), a = (E.r + E.g + E.b) |h - c_G|, so that a / (r + g + b) is the mean distance from c_G of
// the receivers that got the deposits in a texel: the camera pass's visibility test (camera.frag).
in vec3 g_irradiance;
in vec2 g_disk;      // splats: position in the disk, radius 1 (triangles: 0)
in vec3 g_position;  // the receiver point h - c_G (interpolated perspective-correctly: on the triangle)
layout(location = 0) out vec4 o_irradiance;
void main() {
  if (dot(g_disk, g_disk) > 1.0) discard;
  o_irradiance = vec4(g_irradiance, (g_irradiance.r + g_irradiance.g + g_irradiance.b) * length(g_position));
}
