// gather_step > 1: the gather ran on one pixel per step x step block (its centre pixel); this pass gives
// every pixel the photon estimate of the nearby block samples that lie on its own surface, bilinear
// weights times a surface test (the estimator's own: within planeTolerance h_min of the pixel's plane,
// normals within acos(0.9), and closer than h_min: every estimate is a kernel mean over a disc of radius
// h >= h_min, so it is smooth over h_min, and the bilinear mix of samples within it adds a blur below the
// smallest kernel's). The diffuse albedo is re-modulated per pixel, (albedo + 0.02) / (albedo_sample + 0.02), so
// texture detail survives. Pixels without a matching sample are marked for a full-resolution gather
// (i_fixup = 1), which a later dispatch of gather.comp does for them alone (the fix-up list,
// fixup_list.comp): no pixel is left dark.
// u_refine = 1 (the fix-up cascade of a supersampled frame): only the marked pixels, from block samples
// of a finer step taken at marked block centres (alpha -1: no sample there); a pixel that finds one is
// unmarked, the others stay marked for the full gather.
// u_refine = 2 (the neighbour fill, before the cascade): a marked pixel takes the mean of the pixels
// within u_fillRadius that the block samples filled (i_fixup 0) and that pass the same surface test
// (a block sample's estimate may thus reach a pixel up to 2 h_min from where it was gathered, h_min to
// the neighbour and h_min more, though the neighbour is a pixel or two away); it is then marked 2, which no pass
// reads from or gathers for. Edge pixels usually have such a neighbour on their own surface one or two
// pixels inwards, so only thin features and isolated triangles are left for the full gather. Race-free:
// it reads only pixels marked 0, which it never writes, and writes only pixels marked 1 (as 2).
#include "photon_gi/photon.glsl"
#include "photon_gi/surface.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(rgba32f, binding = 0) uniform image2D i_accum;
layout(r32f, binding = 1) uniform image2D i_fixup;
layout(rgba32f, binding = 2) readonly uniform image2D i_low;  // the block samples

uniform ivec2 u_size;     // full resolution
uniform ivec2 u_lowSize;  // the block samples
uniform int u_step;
uniform float u_hMin;
uniform int u_renormalize;
uniform float u_minKernelMass;
uniform int u_refine;
uniform int u_fillRadius;

// The surface test of a borrowed estimate: o's value may stand for s's (module comment). The distance
// bound was h_min / 2 until 2026-12-02: on the Cornell boxes' walls seen at a grazing angle, block samples
// two pixels apart are farther than that, so every other pixel there was gathered again (21% of the
// 128 px cornell_glass frame at k = 1); at h_min the frame's error is unchanged (docs/PERFORMANCE.md).
// A glossy lobe that the estimate evaluates (photon.glsl: roughness from u_minGlossyRoughness) makes it
// depend on the view through the lobe: it stands for another point only where the two mirror
// directions of the view agree within twice the lobe's width (2 alpha radians, alpha = roughness^2:
// alpha gave the same error for 2.6x the gather's time, 4 alpha kept the error; the normal test above
// allows 25 degrees, 50 between mirror directions). On a metal sphere a few pixels wide, a block
// sample at the silhouette (grazing view, Fresnel and masking near 1, the neighbours seen in the grazing
// reflection) lent its estimate to the samples of two pixels whose views were 20 degrees steeper:
// indirect 1.9 and 2.1 where the reference's whole pixel is 0.08 (MetalRoughSpheres under qwantani).
bool sameLobe(SplatSurface s, SplatSurface o) {
  float alpha = s.p.surface.y * s.p.surface.y;
  if (s.p.surface.y < u_minGlossyRoughness || alpha >= 0.45) return true;  // diffuse only, or wider than the test
  return dot(reflect(-s.wo, s.n), reflect(-o.wo, o.n)) >= cos(2.0 * alpha);
}
bool sameSurface(SplatSurface s, SplatSurface o) {
  vec3 d = s.x - o.x;
  return abs(dot(d, o.ng)) <= u_planeTolerance * u_hMin && dot(s.ng, o.ng) >= 0.9 && dot(d, d) <= u_hMin * u_hMin &&
         sameLobe(s, o);
}

// The diffuse albedo re-modulation of a borrowed estimate (module comment).
vec3 remodulate(SplatSurface s, SplatSurface o) { return (s.p.baseColor.rgb + 0.02) / (o.p.baseColor.rgb + 0.02); }

void neighbourFill(ivec2 px, SplatSurface s) {
  vec3 sum = vec3(0.0);
  float n = 0.0;
  for (int dy = -u_fillRadius; dy <= u_fillRadius; ++dy)
    for (int dx = -u_fillRadius; dx <= u_fillRadius; ++dx) {
      ivec2 q = px + ivec2(dx, dy);
      if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, u_size))) continue;
      if (imageLoad(i_fixup, q).r != 0.0) continue;  // marked: not filled yet (or filled by this pass)
      SplatSurface o;
      if (!loadSurface(q, o) || !sameSurface(s, o)) continue;
      sum += imageLoad(i_accum, q).rgb * remodulate(s, o);
      n += 1.0;
    }
  if (n > 0.0) {
    imageStore(i_accum, px, vec4(sum / n, 1.0));
    imageStore(i_fixup, px, vec4(2.0));
  }
}

ivec2 samplePixel(ivec2 q) { return min(q * u_step + u_step / 2, u_size - 1); }

void main() {
  ivec2 px = ivec2(gl_GlobalInvocationID.xy);
  if (px.x >= u_size.x || px.y >= u_size.y) return;
  if (u_refine != 0 && imageLoad(i_fixup, px).r != 1.0) return;
  SplatSurface s;
  if (u_refine == 2) {
    if (loadSurface(px, s)) neighbourFill(px, s);
    return;
  }
  if (!loadSurface(px, s)) {
    imageStore(i_accum, px, vec4(0.0));
    imageStore(i_fixup, px, vec4(0.0));
    return;
  }
  vec2 f = (vec2(px) + 0.5) / float(u_step) - 0.5;
  ivec2 q0 = ivec2(floor(f));
  vec2 t = f - vec2(q0);
  vec3 sum = vec3(0.0);
  float wsum = 0.0;
  for (int j = 0; j <= 1; ++j)
    for (int i = 0; i <= 1; ++i) {
      ivec2 q = clamp(q0 + ivec2(i, j), ivec2(0), u_lowSize - 1);
      float wb = (i == 0 ? 1.0 - t.x : t.x) * (j == 0 ? 1.0 - t.y : t.y);
      if (wb <= 0.0) continue;
      SplatSurface o;
      if (!loadSurface(samplePixel(q), o) || !sameSurface(s, o)) continue;
      vec4 a = imageLoad(i_low, q);
      if (a.a < 0.0) continue;  // u_refine: no block sample was taken there
      vec3 L = a.rgb;
      if (u_renormalize != 0 && a.a > 0.0) L /= max(a.a, u_minKernelMass);
      sum += wb * L * remodulate(s, o);
      wsum += wb;
    }
  if (wsum > 0.0) {
    // a = 1: the resolve's renormalisation divides by max(1, minKernelMass) = 1.
    imageStore(i_accum, px, vec4(sum / wsum, 1.0));
    imageStore(i_fixup, px, vec4(0.0));
  } else if (u_refine == 0) {
    imageStore(i_accum, px, vec4(0.0));
    imageStore(i_fixup, px, vec4(1.0));
  }
}
