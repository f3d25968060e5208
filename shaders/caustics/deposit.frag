// Additive deposit into the caustic cube map: irradiance per receiver area (triangles, splats).
in vec3 g_irradiance;
in vec2 g_disk;  // splats: position in the disk, radius 1 (triangles: 0)
layout(location = 0) out vec4 o_irradiance;
void main() {
  if (dot(g_disk, g_disk) > 1.0) discard;
  o_irradiance = vec4(g_irradiance, 0.0);
}
