// Indirect light on the diffuse texels of one face of one layered-distance-map cube (issue 14: the
// light path L D+ D S+ E, indirect diffuse light seen through or in a specular object): photon_gi's
// photons, gathered at the texel's surface point with photon_gi's kernel and surface test
// (photon_gi/photon.glsl: photonKernel, coverageKernel; photon_gi/grid.glsl: the 27 grid cells), times the
// texel's diffuse albedo / pi (its Lambertian term, specular_ldm_albedo), added to the texel's
// reflected radiance (specular_ldm_material rgb, which map.frag filled with emission + direct light).
// The surface point is the reference point plus the texel's centre direction times its stored
// distance; its normal faces the reference point (the map's viewer, as map.frag shades it). One gather
// per block of texels, spread over the block's texels on the same surface (u_mode below).
#include "common/shared.h"
#include "specular/shared.h"
#include "photon_gi/grid.glsl"
#include "photon_gi/photon.glsl"
#include "specular/map_texel.glsl"  // texelPoint, texelNormal; u_reference, u_face, u_size

layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, rgba32f) readonly uniform imageCubeArray i_geometry;  // oct normal, distance, object
layout(binding = 1, rgba8) readonly uniform imageCubeArray i_albedo;      // rgb albedo, a 1 = lit diffuse
layout(binding = 2, rgba16f) uniform imageCubeArray i_material;           // rgb radiance of diffuse texels
layout(binding = 3, rgba32f) uniform image2D i_accum;                     // this face's sums over slices
// mode 1: the block samples' E, a = 1 + the sample texel's index in its block (a -1: none)
layout(binding = 4, rgba32f) uniform image2D i_blocks;
layout(binding = 5, r32f) uniform image2D i_fixup;  // mode 2 writes 1 where no block sample fits

// The gathers made, per kind: [0] first-level block samples, [1] second-level, [2] single texels.
layout(std430, binding = kBindingMapGatherCounts) buffer GatherCounts { uint gatherCounts[3]; };
uniform int u_layerFace;  // cube * 6 + face
uniform int u_first;        // first slice: start the sums at 0
uniform int u_last;         // last slice: add the estimate to the material texel
uniform int u_renormalize;
uniform float u_minKernelMass;
uniform float u_hMin;  // the smallest splat radius of the photon set (PhotonGrid::minRadius)
// u_mode 0: every texel gathers (u_fixupOnly 1: only the texels mode 2 marked); 1: one gather per
// u_block x u_block block, at its centre texel, into i_blocks; 2: every diffuse texel takes the block
// samples of its own and the 8 neighbouring blocks that lie on its surface (same object code, normal
// within 25 degrees, within 0.1 of the distance between them off its plane: the gather's estimate is
// smooth over a kernel radius, the block is 1/64 of a face), weighted by a tent over their texel
// distance; where none fits it is marked for mode 0. With u_fixupOnly 1, modes 1 and 2 are a second,
// finer level over what the first left marked: a block's sample is its first marked texel (none: no
// gather), and only marked texels take samples (unmarked where one fits). On small curved objects
// (a sphere a few texels across in the environment layers) the first level's samples rarely fit, and
// the texels the second level leaves gather themselves.
uniform int u_mode;
uniform int u_block;
uniform int u_fixupOnly;

// The photon sums at texel px (rgb sum phi k / h^2 of this slice, a the coverage points' kernel mass).
vec4 gatherAt(ivec2 px, vec4 acc) {
  vec4 g = imageLoad(i_geometry, ivec3(px, u_layerFace));
  vec3 x = texelPoint(px, g);
  vec3 n = texelNormal(g, x);
  // The coverage points' side (photon_gi/photon.glsl coverageKernel): the stored vertex normal, unflipped.
  vec3 nw = normalize(octDecode(g.xy));
  ivec3 c = photonCellOf(x);
  for (int k = 0; k < 27; ++k) {
    uint begin, end;
    if (!photonCellSlice(x, c, k, begin, end)) continue;
    for (uint i = begin; i < end; ++i) {
      GpuPhoton p = photons[i];
      if (p.power.a > 0.0) {
        acc.a += coverageKernel(p, x, nw);
      } else {
        float k = photonKernel(p, x, n);
        if (k > 0.0 && dot(n, photonWi(p)) > 0.0) acc.rgb += p.power.rgb * k;
      }
    }
  }
  return acc;
}

// A sample within the smallest kernel radius of the texel and within the kernel's plane tolerance of its
// plane sees the photons the texel would (photon_gi/upsample.comp's sameSurface, its neighbour fill): on
// objects smaller than the kernel (MetalRoughSpheres' spheres, a few texels across in the environment
// layers) the plane test above fails between neighbouring texels while the estimate cannot differ.
bool withinKernel(vec3 d, vec3 n) {
  return dot(d, d) <= u_hMin * u_hMin && abs(dot(d, n)) <= u_planeTolerance * u_hMin;
}

bool lit(vec4 albedo) { return albedo.a > 0.0 && any(greaterThan(albedo.rgb, vec3(0.0))); }

vec3 irradiance(vec4 acc) {
  vec3 E = acc.rgb;  // sum phi k / h^2: the irradiance estimate
  if (u_renormalize != 0 && acc.a > 0.0) E /= max(acc.a, u_minKernelMass);
  return E;
}

void addToTexel(ivec3 t, vec4 albedo, vec3 E) {
  vec4 m = imageLoad(i_material, t);
  imageStore(i_material, t, vec4(m.rgb + albedo.rgb * INV_PI * E, m.a));
}

void main() {
  ivec2 id = ivec2(gl_GlobalInvocationID.xy);
  if (u_mode == 1) {
    int blocks = (u_size + u_block - 1) / u_block;
    if (id.x >= blocks || id.y >= blocks) return;
    ivec2 px = min(id * u_block + u_block / 2, ivec2(u_size - 1));
    bool found = true;
    if (u_fixupOnly != 0) {
      found = false;
      for (int i = 0; i < u_block * u_block && !found; ++i) {
        ivec2 q = id * u_block + ivec2(i % u_block, i / u_block);
        if (q.x < u_size && q.y < u_size && imageLoad(i_fixup, q).r == 1.0) {
          px = q;
          found = true;
        }
      }
    }
    vec4 albedo = imageLoad(i_albedo, ivec3(px, u_layerFace));
    bool sampled = found && lit(albedo);
    vec4 acc = u_first != 0 ? vec4(0.0) : imageLoad(i_accum, id);
    if (sampled) {
      acc = gatherAt(px, acc);
      if (u_first != 0) atomicAdd(gatherCounts[u_fixupOnly], 1u);
    }
    ivec2 at = px - id * u_block;
    if (u_last == 0) imageStore(i_accum, id, acc);
    else imageStore(i_blocks, id, sampled ? vec4(irradiance(acc), float(1 + at.y * u_block + at.x)) : vec4(0.0, 0.0, 0.0, -1.0));
    return;
  }
  ivec2 px = id;
  if (px.x >= u_size || px.y >= u_size) return;
  ivec3 t = ivec3(px, u_layerFace);
  vec4 albedo = imageLoad(i_albedo, t);
  if (u_mode == 2) {
    if (u_fixupOnly != 0 && imageLoad(i_fixup, px).r != 1.0) return;
    if (!lit(albedo)) { imageStore(i_fixup, px, vec4(0.0)); return; }
    vec4 g = imageLoad(i_geometry, t);
    vec3 x = texelPoint(px, g);
    vec3 n = texelNormal(g, x);
    ivec2 b0 = px / u_block;
    int blocks = (u_size + u_block - 1) / u_block;
    vec3 sum = vec3(0.0);
    float wsum = 0.0;
    for (int by = -1; by <= 1; ++by)
      for (int bx = -1; bx <= 1; ++bx) {
        ivec2 b = b0 + ivec2(bx, by);
        if (any(lessThan(b, ivec2(0))) || any(greaterThanEqual(b, ivec2(blocks)))) continue;
        vec4 e = imageLoad(i_blocks, b);
        if (e.a < 0.0) continue;
        int at = int(e.a) - 1;
        ivec2 sp = b * u_block + ivec2(at % u_block, at / u_block);
        vec4 gs = imageLoad(i_geometry, ivec3(sp, u_layerFace));
        if (gs.w != g.w) continue;
        vec3 xs = texelPoint(sp, gs);
        vec3 ns = texelNormal(gs, xs);
        if (dot(ns, n) < 0.9) continue;
        vec3 d = xs - x;
        if (abs(dot(d, n)) > 0.1 * length(d) + 1e-4 * g.z && !withinKernel(d, n)) continue;
        vec2 o = abs(vec2(sp - px)) / float(u_block);
        float w = max(1.0 - o.x, 0.0) * max(1.0 - o.y, 0.0);
        if (sp == px) w = 1.0;
        if (w <= 0.0) continue;
        sum += w * e.rgb;
        wsum += w;
      }
    if (wsum > 0.0) {
      addToTexel(t, albedo, sum / wsum);
      imageStore(i_fixup, px, vec4(0.0));
    } else {
      imageStore(i_fixup, px, vec4(1.0));
    }
    return;
  }
  if (u_fixupOnly != 0 && imageLoad(i_fixup, px).r != 1.0) return;
  vec4 acc = u_first != 0 ? vec4(0.0) : imageLoad(i_accum, px);
  if (lit(albedo)) {
    acc = gatherAt(px, acc);
    if (u_first != 0) atomicAdd(gatherCounts[2], 1u);
  }
  if (u_last == 0) {
    imageStore(i_accum, px, acc);
    return;
  }
  if (lit(albedo)) addToTexel(t, albedo, irradiance(acc));
}
