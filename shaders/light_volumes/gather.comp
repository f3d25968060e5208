// light_volumes' gathering (Duvenhage et al. §4.3): per receiver fragment of the G-buffer, the sum of
// the beams' irradiance (light_volumes/beam.glsl) times the receiver's glTF BRDF towards the beam's
// mean direction (valid for narrow beams, notes A2.9). Two traversals:
//   u_traversal 0 (linear, the paper): beams [u_begin, u_end) of this dispatch, every one;
//   u_traversal 1 (bvh): the BVH of group u_root, only beams whose cone segment holds the fragment.
// llvmpipe ends an invocation's loops after 65535 iterations, so the CPU dispatches once per slice
// (linear) or group (bvh), accumulating in i_accum; the last dispatch adds the total to beauty.
#include "common/shared.h"
#include "common/brdf.glsl"
#include "light_volumes/beam.glsl"
#include "common/frame.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(std430, binding = 8) readonly buffer Beams { Beam beams[]; };
layout(std430, binding = 9) readonly buffer Cones { BeamCone cones[]; };
layout(std430, binding = 10) readonly buffer Nodes { BeamBvhNode nodes[]; };
layout(std430, binding = 11) readonly buffer Prims { vec4 prims[]; };

layout(binding = kUnitGbufferPosition) uniform sampler2D t_position;
layout(binding = kUnitGbufferNormal) uniform sampler2D t_normal;
layout(binding = kUnitGbufferAlbedo) uniform sampler2D t_albedo;
layout(binding = kUnitGbufferMaterial) uniform sampler2D t_material;
layout(binding = kUnitGbufferEmission) uniform sampler2D t_emission;
layout(rgba32f, binding = 0) uniform image2D i_accum;
layout(rgba32f, binding = 1) uniform image2D i_beauty;

uniform ivec2 u_size;
uniform int u_traversal;
uniform int u_begin, u_end;
uniform int u_root;
uniform int u_split;
uniform int u_accumulate;
uniform int u_addToBeauty;
// The light-path classes whose beams join beauty (LightVolumesPass::execute): 1 LS+DE (specular
// scatterers' beams, sigma 0), 2 LG+DE (glossy ones). The AOV holds every beam.
uniform int u_beautyClasses;
uniform float u_narrowLobeRoughness;  // Material::kNarrowLobeRoughness

vec3 beamRadiance(int i, vec3 F, vec3 n, vec3 wo, MaterialParams mp) {
  Beam b = beams[i];
  float k = beamIrradianceFactor(b, F, n, u_split);
  if (k == 0.0) return vec3(0.0);
  vec3 N = normalize(vec3(b.dirA) + vec3(b.dirB) + vec3(b.dirC));
  float c = max(dot(n, -N), 1e-6);
  return vec3(b.fluxSigma) * k * gltfBrdfCos(n, wo, -N, mp) / c;
}

// Whether beam i joins beauty: a shadow beam (negative flux) always, since it is its scatterer's first-order
// shadow, which the shadow maps leave out (shadowMapExclusions); a beam of light only in a class this pass
// owns (its scatterer's material's, Beam::vertexC.w), so that a class another technique owns (caustics'
// LS+DE) is not added twice.
bool toBeauty(int i) {
  vec4 fs = beams[i].fluxSigma;
  if (fs.x + fs.y + fs.z < 0.0) return true;
  return (u_beautyClasses & int(beams[i].vertexC.w)) != 0;
}

void main() {
  ivec2 px = ivec2(gl_GlobalInvocationID.xy);
  if (px.x >= u_size.x || px.y >= u_size.y) return;
  vec3 L = vec3(0.0), B = vec3(0.0);  // every beam (the AOV); those that join beauty
  vec4 P = texelFetch(t_position, px, 0);
  vec4 nUnlit = texelFetch(t_normal, px, 0);
  vec4 mat = texelFetch(t_material, px, 0);
  // Receivers: lit surfaces that are not scatterers themselves (Material::scattersNarrowLobe()).
  bool scatterer = (mat.x >= 0.5 || mat.w > 0.0) && mat.y <= u_narrowLobeRoughness;
  if (P.w > 0.0 && nUnlit.w >= 0.5 && !scatterer) {
    vec3 F = P.xyz;
    vec3 n = normalize(nUnlit.xyz);
    vec3 wo = u_frame.flags.x != 0 ? -u_frame.viewForward.xyz : normalize(u_frame.eye.xyz - F);
    MaterialParams mp = materialParams(texelFetch(t_albedo, px, 0).rgb, mat.x, mat.y, mat.w,
                                       texelFetch(t_emission, px, 0).a);
    if (u_traversal == 0) {
      for (int i = u_begin; i < u_end; ++i) {
        vec3 e = beamRadiance(i, F, n, wo, mp);
        L += e;
        if (toBeauty(i)) B += e;
      }
    } else if (u_root >= 0) {
      int stack[32];
      int sp = 0;
      int node = u_root;
      while (true) {
        BeamBvhNode nd = nodes[node];
        if (all(greaterThanEqual(F, vec3(nd.lo))) && all(lessThanEqual(F, vec3(nd.hi)))) {
          if (nd.meta.x >= 0) {
            stack[sp++] = nd.meta.x;
            node = node + 1;
            continue;
          }
          for (int j = nd.meta.y; j < nd.meta.y + nd.meta.z; ++j) {
            vec4 prim = prims[j];
            int i = int(prim.z);
            BeamCone c = cones[i];
            vec3 r = F - vec3(c.originRadius);
            float s = dot(r, vec3(c.axisSlope));
            if (s < prim.x || s >= prim.y) continue;
            float radius = c.originRadius.w + c.axisSlope.w * abs(s);
            vec3 radial = r - s * vec3(c.axisSlope);
            if (dot(radial, radial) > radius * radius) continue;
            vec3 e = beamRadiance(i, F, n, wo, mp);
            L += e;
            if (toBeauty(i)) B += e;
          }
        }
        if (sp == 0) break;
        node = stack[--sp];
      }
    }
  }
  vec4 acc = vec4(L, 1.0);
  if (u_accumulate != 0) acc.rgb += imageLoad(i_accum, px).rgb;
  imageStore(i_accum, px, acc);
  // Each dispatch adds its share of beauty (the AOV's sum is the last dispatch's acc).
  if (u_addToBeauty != 0) imageStore(i_beauty, px, imageLoad(i_beauty, px) + vec4(B, 0.0));
}
