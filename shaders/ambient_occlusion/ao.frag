// Screen-space ambient occlusion estimate at the working resolution (full or half). One method is
// compiled in (METHOD_VOLUMETRIC | METHOD_CONTAINMENT | METHOD_CRYTEK | METHOD_GTAO) with SAMPLES taps;
// the kernel comes from renderer/techniques/ambient_occlusion/AmbientOcclusion.cpp (buildSampleBlock).
//
// The z-buffer is the thesis' characteristic function I(p) (thesis 4.1.1, case 3): a point is outer
// (I = 1) when it is in front of the visible surface along its eye ray. The depth there is not the
// texel centre's: the texel's surface is extended by its tangent plane (world position + geometric
// normal), i.e. the depth is reconstructed at the exact sub-texel position. This removes the
// quantisation error that otherwise makes tilted open planes self-occlude; on planes it is exact.
#include "common/shared.h"
#include "common/constants.glsl"
#include "common/frame.glsl"

in vec2 v_uv;

layout(binding = kUnitGbufferPosition) uniform sampler2D t_position;  // xyz world, w = linear view depth (0: no surface)
layout(binding = kUnitGbufferNormal) uniform sampler2D t_normal;      // shading normal
layout(binding = kUnitGbufferGeometricNormal) uniform sampler2D t_geoNormal;  // geometric normal facing the viewer

layout(std140, binding = 0) uniform AoSamples {
  vec4 u_samples[64];    // method-specific kernel (see AmbientOcclusion.h)
  vec4 u_rotations[16];  // 4x4 pattern: (cos a, sin a, gtao slice offset, gtao step jitter)
};

uniform float u_radius;  // R, world units
uniform vec3 u_forward;  // camera axes, world space
uniform vec3 u_right;
uniform vec3 u_up;
uniform int u_interleave;
uniform int u_scale;     // full-resolution pixels per working pixel (1 or 2)
uniform vec2 u_fullSize;
uniform float u_proj11;  // proj[1][1]: pixels per world unit = proj11 * height / 2 (/ view depth)
uniform int u_slices;    // gtao
uniform int u_steps;     // gtao, per side

layout(location = 0) out float o_ao;

const float OPEN = 3.0e38;  // no surface along the ray (background or outside the image)

vec3 rayDir(vec3 p) { return u_frame.flags.x != 0 ? u_forward : normalize(p - u_frame.eye.xyz); }

// Full-resolution texel that p projects to; false outside the image or behind the eye.
bool projectToTexel(vec3 p, out ivec2 texel) {
  vec4 c = u_frame.viewProj * vec4(p, 1.0);
  texel = ivec2(0);
  if (!(c.w > 0.0)) return false;
  vec2 px = (c.xy / c.w * 0.5 + 0.5) * u_fullSize;
  if (!(px.x >= 0.0 && px.y >= 0.0 && px.x < u_fullSize.x && px.y < u_fullSize.y)) return false;
  texel = ivec2(px);
  return true;
}

// Signed distance from s to the depth-buffer surface along the eye ray through s (direction dir):
// positive when the surface is behind s, i.e. s is an outer point. The surface is the tangent plane of
// the texel s projects to (sub-texel depth, see the header).
float surfaceDistance(vec3 s, vec3 dir) {
  ivec2 t;
  if (!projectToTexel(s, t)) return OPEN;
  vec4 P = texelFetch(t_position, t, 0);
  if (P.w <= 0.0) return OPEN;
  vec3 ng = texelFetch(t_geoNormal, t, 0).xyz;
  vec3 d = P.xyz - s;
  float denom = dot(dir, ng);
  // A plane seen (nearly) edge-on: fall back to the texel centre's depth.
  if (denom < -1e-3) return dot(d, ng) / denom;
  return dot(d, dir);
}

// I(p) of thesis 4.1.1 from the z-buffer. The tolerance (1e-5 R) only absorbs float rounding.
float outer(vec3 p) { return surfaceDistance(p, rayDir(p)) >= -1e-5 * u_radius ? 1.0 : 0.0; }

vec2 rotate(vec2 v, vec2 cs) { return vec2(cs.x * v.x - cs.y * v.y, cs.y * v.x + cs.x * v.y); }

vec4 patternCell(ivec2 q) { return u_rotations[(q.x & 3) + 4 * (q.y & 3)]; }

// An orthonormal basis (t, b) of the plane perpendicular to unit vector a, tied to the camera axes so
// that it is the same for every pixel with the same a (no per-pixel noise when interleave is off).
void basisAround(vec3 a, out vec3 t, out vec3 b) {
  vec3 h = abs(dot(a, u_right)) < 0.9 ? u_right : u_up;
  t = normalize(h - a * dot(h, a));
  b = cross(a, t);
}

#if defined(METHOD_VOLUMETRIC)
// G(u) = \int_0^u (1 + v/m)^2 dv: volume per unit cross-section of a perspective pipe (a thin cone from
// the eye, "parallel to axis z in clipping space", thesis 4.1.1) between the chord midpoint at distance
// m and u beyond it. invM = 1/m; orthographic pipes (invM = 0) give the thesis' length Delta z exactly.
float pipeVolume(float u, float invM) { return u * (1.0 + u * invM * (1.0 + u * invM / 3.0)); }

// Thesis eq. 4.8 / Algorithm 2: V = sum Delta z_i / F with F = sum of the full chords (weighted
// importance sampling; for parallel pipes F = R sum sqrt(1 - x_i^2 - y_i^2)).
float volumetricAO(vec3 x, vec3 n, vec2 rot) {
  float rho = 0.5 * u_radius;          // tangent sphere S: radius R/2 ...
  vec3 c = x + n * rho;                // ... centre R/2 above x along the normal (Fig. 4.4)
  vec3 axis = rayDir(c);               // axis z: the view direction through the centre
  vec3 t, b;
  basisAround(axis, t, b);
  float unoccluded = 0.0, sphere = 0.0;
  for (int i = 0; i < SAMPLES; ++i) {
    vec2 xy = rotate(u_samples[i].xy, rot);
    vec3 o = rho * (xy.x * t + xy.y * b);  // (x_i R/2, y_i R/2) on the disk through the centre
    vec3 s = c + o;                        // the "sample" of Fig. 4.7
    vec3 dir = rayDir(s);                  // the pipe: the eye ray through the sample
    float mid = -dot(o, dir);              // chord midpoint, measured from s along the pipe
    float halfChord = sqrt(max(rho * rho - max(dot(o, o) - mid * mid, 0.0), 0.0));
    float invM = u_frame.flags.x != 0 ? 0.0 : 1.0 / max(dot(s - u_frame.eye.xyz, dir) + mid, 1e-30);
    float zEntry = -halfChord, zExit = halfChord;      // relative to the midpoint
    float zStar = surfaceDistance(s, dir) - mid;       // z*: where the pipe meets the surface
    // Algorithm 2: Delta z = min(z_exit, z*) - min(z_entry, z*) = clamp(z*, z_entry, z_exit) - z_entry
    // (cases A, B, C of Fig. 4.7); the clamp form cannot overflow when z* is far away.
    float zFree = clamp(zStar, zEntry, zExit);
    unoccluded += pipeVolume(zFree, invM) - pipeVolume(zEntry, invM);
    sphere += pipeVolume(zExit, invM) - pipeVolume(zEntry, invM);
  }
  return sphere > 0.0 ? unoccluded / sphere : 1.0;
}
#endif

#if defined(METHOD_CONTAINMENT) || defined(METHOD_CRYTEK)
// Containment: thesis eq. 4.5, O = 1/n sum I(x + X_i T + Y_i B + Z_i N) with (X,Y,Z)_i = omega_i r_i
// (cosine-distributed omega, r_i = mu^-1(xi_i)). Crytek: the same test with points filling the whole
// ball of radius R around x, so an open plane gives 1/2 (thesis 4.2).
float containmentAO(vec3 x, vec3 n, vec2 rot) {
  vec3 t, b;
  basisAround(n, t, b);
  float open = 0.0;
  for (int i = 0; i < SAMPLES; ++i) {
    vec3 k = u_samples[i].xyz;
    vec2 xy = rotate(k.xy, rot);       // rotation around the surface normal (thesis 4.1.3)
    open += outer(x + u_radius * (xy.x * t + xy.y * b + k.z * n));
  }
  return open / float(SAMPLES);
}
#endif

#if defined(METHOD_GTAO)
// The depth-buffer surface on the exact eye ray through screen position sp (full-resolution pixels):
// the tangent plane of the texel under sp intersected with that ray. The texel centre itself would lie
// off the slice by up to half a pixel, which near the centre tilts the horizon by up to ~27 degrees.
bool surfaceAtScreen(vec2 sp, out vec3 P) {
  ivec2 t = ivec2(sp);
  vec4 Pt = texelFetch(t_position, t, 0);
  P = Pt.xyz;
  if (Pt.w <= 0.0) return false;
  vec4 o4 = u_frame.invViewProj * vec4(sp / u_fullSize * 2.0 - 1.0, 1.0, 1.0);  // on the near plane (depth 1)
  vec3 o = o4.xyz / o4.w;
  vec3 dir = u_frame.flags.x != 0 ? u_forward : normalize(o - u_frame.eye.xyz);
  vec3 ng = texelFetch(t_geoNormal, t, 0).xyz;
  float denom = dot(dir, ng);
  vec3 d = Pt.xyz - o;
  P = o + dir * (denom < -1e-3 ? dot(d, ng) / denom : dot(d, dir));
  return true;
}

// Jimenez, Wu, Pesce, Jarabo 2016, "Practical Realtime Strategies for Accurate Indirect Occlusion":
// per slice (a plane containing the view vector), the two horizon angles h1 <= 0 <= h2 (from the view
// vector, clamped to the hemisphere around the projected normal n) are searched in screen space within
// R, and the cosine-weighted visible arc is integrated analytically (their eq. 10):
//   a(h1, h2) = 1/4 (-cos(2 h1 - n) + cos n + 2 h1 sin n) + 1/4 (-cos(2 h2 - n) + cos n + 2 h2 sin n),
// weighted by the length of the normal projected onto the slice; slices average over phi in [0, pi)
// (self-normalised, see the end of gtaoAO).
// Falloff: a step at distance R (the classic AO definition), with the horizon of the segment that
// crosses the radius taken at the crossing point (exact for planar occluders instead of one step short).
float gtaoAO(vec3 x, vec3 n, ivec2 px, float viewDepth, vec4 cell) {
  vec3 V = u_frame.flags.x != 0 ? -u_forward : normalize(u_frame.eye.xyz - x);
  float R = u_radius;
  float radiusPx = R * u_proj11 * 0.5 * u_fullSize.y / (u_frame.flags.x != 0 ? 1.0 : max(viewDepth, 1e-30));
  radiusPx = min(radiusPx, 2.0 * max(u_fullSize.x, u_fullSize.y));
  float sliceOffset = u_interleave != 0 ? cell.z : 0.5;
  float jitter = u_interleave != 0 ? cell.w : 0.5;
  vec2 centre = vec2(px) + 0.5;
  float visibility = 0.0, unoccluded = 0.0;
  for (int k = 0; k < u_slices; ++k) {
    float phi = PI * (float(k) + sliceOffset) / float(u_slices);
    vec2 omega = vec2(cos(phi), sin(phi));
    vec3 dirW = u_right * omega.x + u_up * omega.y;  // the slice's screen direction, in world space
    vec3 orthoDir = dirW - V * dot(dirW, V);
    vec3 axis = normalize(cross(orthoDir, V));
    vec3 projN = n - axis * dot(n, axis);
    float projLen = length(projN);
    if (projLen < 1e-6) continue;  // the normal is perpendicular to the slice: zero weight
    float cosN = clamp(dot(projN, V) / projLen, -1.0, 1.0);
    float nAng = (dot(orthoDir, projN) >= 0.0 ? 1.0 : -1.0) * acos(cosN);
    float horizonCos[2];
    for (int side = 0; side < 2; ++side) {
      float sgn = side == 0 ? 1.0 : -1.0;
      float hc = cos(nAng + sgn * 0.5 * PI);  // the tangent plane: nothing found yet
      vec3 last = vec3(0.0);                  // last sample inside R, relative to x (x itself first)
      bool crossed = false;
      for (int j = 0; j < u_steps; ++j) {
        float s = max(radiusPx * (float(j) + jitter) / float(u_steps), 1.0);
        vec2 sp = centre + sgn * omega * s;
        if (!(sp.x >= 0.0 && sp.y >= 0.0 && sp.x < u_fullSize.x && sp.y < u_fullSize.y)) break;
        vec3 P;
        if (!surfaceAtScreen(sp, P)) continue;  // background: no occluder
        vec3 delta = P - x;
        float d2 = dot(delta, delta);
        if (d2 <= 1e-12 * R * R) continue;
        if (d2 <= R * R) {
          hc = max(hc, dot(delta, V) * inversesqrt(d2));
          last = delta;
        } else if (!crossed) {
          crossed = true;
          // First sample beyond R: the point at distance R on the segment last -> delta. Only across a
          // continuous surface (a jump to a far surface is a silhouette, not an occluder).
          if (d2 <= 4.0 * R * R) {
            vec3 e = delta - last;
            float A = dot(e, e), B = 2.0 * dot(last, e), C = dot(last, last) - R * R;
            float t = A > 0.0 ? (-B + sqrt(max(B * B - 4.0 * A * C, 0.0))) / (2.0 * A) : 0.0;
            vec3 q = last + clamp(t, 0.0, 1.0) * e;
            hc = max(hc, dot(q, V) / max(length(q), 1e-30));
          }
        }
      }
      horizonCos[side] = clamp(hc, -1.0, 1.0);
    }
    float h0 = -acos(horizonCos[1]);
    float h1 = acos(horizonCos[0]);
    h0 = nAng + max(h0 - nAng, -0.5 * PI);
    h1 = nAng + min(h1 - nAng, 0.5 * PI);
    float sinN = sin(nAng);
    float arc0 = 0.25 * (cosN + 2.0 * h0 * sinN - cos(2.0 * h0 - nAng));
    float arc1 = 0.25 * (cosN + 2.0 * h1 * sinN - cos(2.0 * h1 - nAng));
    visibility += projLen * (arc0 + arc1);
    // The same slice with both horizons on the tangent plane (h = n -+ pi/2): arc0 + arc1 = cos n + n sin n.
    unoccluded += projLen * (cosN + nAng * sinN);
  }
  // Jimenez et al. divide by the slice count: a slice is unbiased only on average over slice angles, so
  // with 1-2 slices per pixel an open plane seen obliquely is off by up to 30% per pixel (and stays off
  // wherever the 4x4 filter window is incomplete: image borders, depth discontinuities). We normalise by
  // the same slices' unoccluded value instead (weighted importance sampling, the device of thesis eq. 4.8's
  // F): consistent (both sums converge to their integrals, whose ratio is the AO) and exactly 1 on open
  // planes with any number of slices.
  return unoccluded > 0.0 ? visibility / unoccluded : 1.0;
}
#endif

void main() {
  ivec2 q = ivec2(gl_FragCoord.xy);
  ivec2 px = min(q * u_scale, ivec2(u_fullSize) - 1);
  vec4 P = texelFetch(t_position, px, 0);
  if (P.w <= 0.0) {
    o_ao = 1.0;  // no surface: nothing to occlude (background)
    return;
  }
  vec3 x = P.xyz;
  vec3 ng = texelFetch(t_geoNormal, px, 0).xyz;
  vec3 n = texelFetch(t_normal, px, 0).xyz;
  // The shading normal on the viewer's side of the surface (as the reference renderer does).
  n = dot(n, n) > 1e-12 ? normalize(n) : ng;
  if (dot(n, ng) < 0.0) n = -n;
  vec4 cell = u_interleave != 0 ? patternCell(q) : vec4(1.0, 0.0, 0.5, 0.5);
  float a;
#if defined(METHOD_VOLUMETRIC)
  a = volumetricAO(x, n, cell.xy);
#elif defined(METHOD_CONTAINMENT) || defined(METHOD_CRYTEK)
  a = containmentAO(x, n, cell.xy);
#else
  a = gtaoAO(x, n, px, P.w, cell);
#endif
  // Stored unclamped: a single GTAO slice is an unbiased but noisy estimate that may exceed 1 (its average
  // over slice angles is the AO), so the 4x4 filter must average raw values; the resolve clamps.
  o_ao = isnan(a) ? 1.0 : clamp(a, 0.0, 2.0);
}
