// Indirect light on the diffuse texels of one face of one layered-distance-map cube (issue 14: the
// light path L D+ D S+ E, indirect diffuse light seen through or in a specular object): photon_gi's
// photons, gathered at the texel's surface point with photon_gi's kernel and surface test
// (photon_gi/photon.glsl: photonKernel, coverageKernel, the 27 grid cells of gather.comp), times the
// texel's diffuse albedo / pi (its Lambertian term, specular_ldm_albedo), added to the texel's
// reflected radiance (specular_ldm_material rgb, which map.frag filled with emission + direct light).
// The surface point is the reference point plus the texel's centre direction times its stored
// distance; its normal faces the reference point (the map's viewer, as map.frag shades it).
#include "common/octahedral.glsl"
#include "photon_gi/photon.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(std430, binding = 6) readonly buffer Cells { uint cellStart[]; };
layout(binding = 0, rgba32f) readonly uniform imageCubeArray i_geometry;  // oct normal, distance, object
layout(binding = 1, rgba8) readonly uniform imageCubeArray i_albedo;      // rgb albedo, a 1 = lit diffuse
layout(binding = 2, rgba16f) uniform imageCubeArray i_material;           // rgb radiance of diffuse texels
layout(binding = 3, rgba32f) uniform image2D i_accum;                     // this face's sums over slices

uniform vec3 u_reference;
uniform int u_layerFace;  // cube * 6 + face
uniform int u_face;
uniform int u_size;
uniform vec3 u_gridOrigin;
uniform float u_cellSize;
uniform ivec3 u_gridDims;
uniform uint u_sliceBegin;  // as gather.comp: llvmpipe's loop limit, one dispatch per slice
uniform uint u_sliceLength;
uniform int u_first;        // first slice: start the sums at 0
uniform int u_last;         // last slice: add the estimate to the material texel
uniform int u_renormalize;
uniform float u_minKernelMass;

// Direction of the point (s, t) in [-1, 1]^2 of cube face `face` (GL 4.5 table 8.19, inverted).
vec3 faceDirection(int face, vec2 st) {
  if (face == 0) return vec3(1.0, -st.y, -st.x);
  if (face == 1) return vec3(-1.0, -st.y, st.x);
  if (face == 2) return vec3(st.x, 1.0, st.y);
  if (face == 3) return vec3(st.x, -1.0, -st.y);
  if (face == 4) return vec3(st.x, -st.y, 1.0);
  return vec3(-st.x, -st.y, -1.0);
}

void main() {
  ivec2 px = ivec2(gl_GlobalInvocationID.xy);
  if (px.x >= u_size || px.y >= u_size) return;
  ivec3 t = ivec3(px, u_layerFace);
  vec4 albedo = imageLoad(i_albedo, t);
  vec4 acc = u_first != 0 ? vec4(0.0) : imageLoad(i_accum, px);
  if (albedo.a > 0.0 && any(greaterThan(albedo.rgb, vec3(0.0)))) {
    vec4 g = imageLoad(i_geometry, t);
    vec3 dir = normalize(faceDirection(u_face, (vec2(px) + 0.5) / float(u_size) * 2.0 - 1.0));
    vec3 x = u_reference + dir * g.z;
    vec3 n = normalize(octDecode(g.xy));
    if (dot(n, dir) > 0.0) n = -n;  // facing the reference point, the map's viewer
    ivec3 c = ivec3(floor((x - u_gridOrigin) / u_cellSize));
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          ivec3 q = c + ivec3(dx, dy, dz);
          if (any(lessThan(q, ivec3(0))) || any(greaterThanEqual(q, u_gridDims))) continue;
          int cell = (q.z * u_gridDims.y + q.y) * u_gridDims.x + q.x;
          uint begin = cellStart[cell] + u_sliceBegin, end = min(cellStart[cell + 1], begin + u_sliceLength);
          for (uint i = begin; i < end; ++i) {
            GpuPhoton p = photons[i];
            if (p.power.a > 0.0) {
              acc.a += coverageKernel(p, x, n);
            } else if (dot(n, p.wi.xyz) > 0.0) {
              acc.rgb += p.power.rgb * photonKernel(p, x, n);
            }
          }
        }
  }
  if (u_last == 0) {
    imageStore(i_accum, px, acc);
    return;
  }
  if (!(albedo.a > 0.0)) return;
  vec3 E = acc.rgb;  // sum phi k / h^2: the irradiance estimate
  if (u_renormalize != 0 && acc.a > 0.0) E /= max(acc.a, u_minKernelMass);
  vec4 m = imageLoad(i_material, t);
  imageStore(i_material, t, vec4(m.rgb + albedo.rgb * INV_PI * E, m.a));
}
