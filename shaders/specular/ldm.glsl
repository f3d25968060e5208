// Layered distance maps (thesis ch. 5): layout of the maps and ray tracing in them (5.1.2, Algorithm 3).
// C++ side: renderer/techniques/specular/Specular.cpp. Included by specular.frag (tracing) and map.frag
// (texel classification).
//
// Every specular object k has u_layers cube maps (index k * u_layers + l of the cube arrays):
//   l = 0 its own front faces as seen from its reference point, l = 1 its back faces, l = 2 the
//   environment (every other mesh, closest surface), l >= 3 depth-peeled environment layers.
// Two cube maps per layer as thesis 5.2 describes, plus a filtered copy of the distance:
//   t_ldmMaterial: rgb = reflected radiance (diffuse), the radiance of a mirror's diffuse lobe (its
//                  emission and the lights' direct light on the dielectric part of a metallic 0.5-1
//                  mirror) or transmission tint (refractor);
//                  a = signed index of refraction: < 0 mirror, 0 diffuse, > 0 refractor.
//   t_ldmGeometry: xy = octahedral-encoded surface normal (as modelled: outward), z = distance from
//                  the reference point (0 = empty texel, no surface), w = specular object index + 1
//                  of the surface (0 for diffuse): a ray leaving a mirror or refractor continues in the
//                  maps of the object it hit.
//   t_ldmAlbedo:   rgb = diffuse albedo (1 - metallic)(1 - transmission) baseColor of a lit non-specular
//                  surface (a = 1), a mirror's F0 (a = 0), 0 elsewhere (RGBA8; the caustics pass reads
//                  the albedo at its secondary hits; mapSpecularTexel the F0).
//   t_ldmDistance:   the distance again (R32F), sampled with linear filtering for the search: the
//                  secant steps then converge on a piecewise-linear surface instead of the staircase
//                  of nearest texels. Empty texels hold kEmptyDistance, so a blend with an empty
//                  neighbour stays huge and reads as "no surface" (the material and geometry maps are
//                  read with nearest texels: filtering normals or object indices is meaningless).
#ifndef RADIANT_SPECULAR_LDM
#define RADIANT_SPECULAR_LDM
#include "common/cube_texels.glsl"  // cubeTexelCentre
#include "common/octahedral.glsl"
#include "common/shared.h"
#include "specular/shared.h"

// Reflection/refraction data of a specular surface in the thesis' representation (5.2). Mixtures are
// reduced to one of the two ideal cases: a refractor (any transmission) keeps its ior and its
// transmission tint; a metal-like mirror keeps F0 = mix(F0(ior), baseColor, metallic) (glTF's
// metal/dielectric mix at normal incidence).
vec4 specularTexel(vec3 baseColor, float metallic, float transmission, float ior) {
  if (transmission > 0.0) return vec4(baseColor * transmission, max(ior, 1.0));
  float r = (ior - 1.0) / (ior + 1.0);
  return vec4(mix(vec3(r * r), baseColor, metallic), -1.0);
}

// Whether a texel of a specular object is stored in its layered distance maps as specular (a
// refractor or a mirror, specularTexel) or as a lit diffuse surface. A specular object is one by its
// material's factors (Material::isSpecular); its textures can make parts of it diffuse: the stripes of
// a transmissionTexture, a metallicRoughnessTexture's dielectric regions. Such a texel is stored as
// what most of its light does: transmission or metalness of at least one half makes it specular.
// Below that it is a dielectric whose diffuse lobe carries the most, stored lit (emission + direct +
// photon_gi's gather) and its 4% Fresnel reflection dropped; before, it was a 4% mirror, black where
// a ray through the object's transmissive parts met it (issue 29, item 5: TransmissionTest's
// striped spheres rendered solid).
bool specularInMaps(float metallic, float transmission) { return transmission >= 0.5 || metallic >= 0.5; }

const float kEmptyDistance = 3.0e38;

#ifdef LDM_TRACING
layout(binding = kUnitLdmMaterial) uniform samplerCubeArray t_ldmMaterial;
layout(binding = kUnitLdmGeometry) uniform samplerCubeArray t_ldmGeometry;
layout(binding = kUnitLdmDistance) uniform samplerCubeArray t_ldmDistance;  // linear filtering, see below
layout(binding = kUnitLdmAlbedo) uniform samplerCubeArray t_ldmAlbedo;

// The scattering data (specularTexel's form) of a specular texel found in the maps, from its material
// texel: a mirror's F0 is stored in t_ldmAlbedo, since its material texel holds its diffuse lobe's
// radiance; a refractor's material texel is its specularTexel.
vec4 mapSpecularTexel(vec4 materialTexel, vec3 dir, float cube) {
  return materialTexel.a < 0.0 ? vec4(texture(t_ldmAlbedo, vec4(dir, cube)).rgb, -1.0) : materialTexel;
}

struct SpecularObject {
  vec4 referenceRadius;  // xyz reference point (world), w bounding radius of the object
  vec4 extent;           // x distance from the reference point to the farthest scene-bounds corner,
                         // yzw sigma_t of the object's KHR_materials_volume medium (0: none)
};

layout(std430, binding = 3) readonly buffer SpecularObjects { SpecularObject objects[]; };

// Beer-Lambert transmittance exp(-sigma_t d) of a segment of length d inside `object`'s medium
// (KHR_materials_volume; Material::attenuationCoefficient). The exponent is capped so that an opaque
// medium (sigma_t up to FLT_MAX) or an escaping ray (d huge) gives 0, never a NaN from inf x 0.
vec3 volumeTransmittance(int object, float d) {
  vec3 sigma = objects[object].extent.yzw;
  return exp(-min(sigma * max(d, 0.0), vec3(88.0)));
}
// Per cube (object * layers + layer): floatBitsToUint of the minimum and maximum stored distance
// (min = FLT_MAX, max = 0 for an empty layer). Written by minmax.comp when the maps are built.
layout(std430, binding = 4) readonly buffer LayerMinMax { uint layerMinMax[]; };

uniform int u_layers;
uniform int u_linearSteps;
uniform int u_secantSteps;
uniform int u_minmax;
uniform float u_cubeResolution;

// One probe of a layer: signed mismatch f = |l| - |l'| (> 0 overshooting: the ray point lies behind
// the stored surface) and whether the texel holds a surface at all.
struct Probe { float d; float len; float stored; bool valid; };

Probe probe(float cube, vec3 x, vec3 R, float d) {
  vec3 l = x + R * d;
  float len = length(l);
  // On the reference point itself the direction is undefined: look along the ray instead.
  vec3 dir = len > 1e-30 ? l : R;
  float stored = texture(t_ldmDistance, vec4(dir, cube)).r;
  // Within half a texel of a surface's edge against empty texels the filtered value blends with the
  // empty marker: fall back to the nearest texel there, so edges keep nearest-texel accuracy instead
  // of eroding by half a texel.
  // (Any non-zero bilinear weight on an empty texel lifts the blend above 1e30.)
  if (stored >= 1e30) stored = texture(t_ldmGeometry, vec4(dir, cube)).z;
  Probe p;
  p.d = d;
  p.len = len;
  p.valid = stored > 0.0 && stored < 1e30;
  p.stored = p.valid ? stored : 0.0;
  return p;
}
// Empty texels count as a surface infinitely far away: the ray is always in front of them.
bool overshoots(Probe p) { return p.valid && p.len >= p.stored; }

// Ray parameter at which |x + R d| = r (far root when far, else near root); false when the line misses
// the sphere of radius r around the reference point.
bool sphereRoots(vec3 x, vec3 R, float r, out float dNear, out float dFar) {
  float b = dot(x, R);
  float c = dot(x, x) - r * r;
  float disc = b * b - c;
  if (disc < 0.0) return false;
  float s = sqrt(disc);
  dNear = -b - s;
  dFar = -b + s;
  return true;
}

// Whether the point p (relative to the reference point, |p| = len > 0) lies on a surface the layer
// stores: within three texels of the tangent plane of one of the four texels around its direction (the
// ones linear filtering blends; their normals and distances), |len - stored| |cos| <= 3 texels + slack
// |cos|, cos between the direction and the texel's normal. A point on a rubber sheet (the filtered
// ramp across a depth discontinuity, see traceLayer) is in front of the far surface's plane and behind
// the near one's by a good part of the jump, so it fails both; a radial test alone cannot tell a
// sheet from a surface seen at a slant (a surface at inclination t from the direction steps by
// 2/res tan(t) of the distance per texel), so it had to admit 16 texels and let sheets through: a
// mirror sphere's rays passing just behind the tall box as seen from the sphere's centre "hit" the
// sheet between the box and the ceiling (cornell_mirror's worst pixels, 40% too dark). slack: what the
// refined bracket still spans.
bool onStoredSurface(vec3 p, float len, float cube, float slack) {
  vec3 dir = p / len;
  vec4 gx = textureGather(t_ldmGeometry, vec4(dir, cube), 0);
  vec4 gy = textureGather(t_ldmGeometry, vec4(dir, cube), 1);
  vec4 gz = textureGather(t_ldmGeometry, vec4(dir, cube), 2);
  for (int i = 0; i < 4; ++i) {
    if (!(gz[i] > 0.0 && gz[i] < 1e30)) continue;
    float c = abs(dot(dir, octDecode(vec2(gx[i], gy[i]))));
    if (abs(len - gz[i]) * c <= 6.0 * gz[i] / u_cubeResolution + slack * c) return true;
  }
  return false;
}

// Linear search + secant refinement in one layer (thesis 5.1.2). x is the ray origin relative to the
// reference point, R the unit direction. Returns the ray parameter of the first crossing in this layer.
// dHidden: where no crossing is found, the ray parameter at which the ray first passed behind a nearer
// surface's silhouette (as seen from the reference point; the refined bracket's end on the far
// surface), or -1: the layer does not store what the ray would hit there (it is hidden from the
// reference point), and the far surface next to the silhouette is the best stand-in the layer has.
bool traceLayer(int object, int layer, vec3 x, vec3 R, out float dHit, out float dHidden) {
  dHidden = -1.0;
  float cube = float(object * u_layers + layer);
  float rMin = 0.0;
  float rMax = objects[object].extent.x;
  if (u_minmax != 0) {
    int i = 2 * (object * u_layers + layer);
    rMin = uintBitsToFloat(layerMinMax[i]);
    rMax = uintBitsToFloat(layerMinMax[i + 1]);
    if (rMax <= 0.0) return false;  // empty layer: no texel holds a surface
    rMin *= 0.999;
    rMax *= 1.001;
  }
  // Min-max acceleration (thesis Fig. 5.3): crossings can only happen inside the shell
  // rMin <= |l| <= rMax, so the ray is clipped to it. Beyond the far intersection with the max sphere
  // every probe overshoots; inside the min sphere every probe undershoots.
  float n0, f0;
  if (!sphereRoots(x, R, rMax, n0, f0) || f0 <= 0.0) return false;
  float dStart = max(n0, 0.0);
  float dEnd = f0;
  float n1, f1;
  if (rMin > 0.0 && dot(x, x) < rMin * rMin && sphereRoots(x, R, rMin, n1, f1)) dStart = max(dStart, f1);
  if (dStart >= dEnd) return false;

  // Uniform steps in t along the segment s -> e between the projections of the clipped ray ends A and
  // B onto the unit sphere (thesis Fig. 5.2). The ray point in the direction of r'(t) = s (1 - t) + e t
  // is A + (B - A) u with u = |A| t / (|A| t + |B| (1 - t)) (project r' back onto the ray). For
  // B -> infinity along R this is the thesis formula d(t) = |x|/|R| * t / (1 - t); the clipped form is
  // finite at t = 1. |A|, |B| are floored so a ray starting on the reference point (|x| = 0, where the
  // thesis formula gives d = 0 for every t) still marches.
  vec3 A = x + R * dStart;
  vec3 B = x + R * dEnd;
  float floorLen = 1e-7 * max(rMax, 1e-30);
  float a = max(length(A), floorLen);
  float b = max(length(B), floorLen);
  vec3 s = length(A) > floorLen ? normalize(A) : R;
  vec3 e = length(B) > floorLen ? normalize(B) : R;
  // Step count proportional to the texels the segment s-e spans (one texel ~ 2/res at a face centre),
  // capped by linear_steps. A ray parallel to its reference direction (s = e) needs a single step.
  int steps = clamp(int(ceil(length(e - s) * 0.5 * u_cubeResolution)), 1, u_linearSteps);

  Probe prev = probe(cube, x, R, dStart);

  for (int i = 1; i <= steps; ++i) {
    float t = float(i) / float(steps);
    float u = a * t / (a * t + b * (1.0 - t));
    Probe cur = probe(cube, x, R, mix(dStart, dEnd, u));
    bool crossIn = !overshoots(prev) && overshoots(cur);               // undershoot -> overshoot
    bool crossOut = prev.valid && cur.valid && overshoots(prev) && !overshoots(cur);  // hit from behind
    if (crossIn || crossOut) {
      // Refine the bracket [lo, hi] (lo on prev's side). Secant / false position on the ratio
      // g(d) = |l| / |l'| (thesis eq. 2.3, read as: d_new = d_l + (d_p - d_l) (1 - g_l) / (g_p - g_l),
      // where the PDF's "|l'|/|l'|" is the ratio of the ray point's distance to the stored one). While
      // an end lies in an empty texel there is no surface to interpolate: bisect instead.
      Probe lo = prev, hi = cur;
      Probe m = cur;
      bool fromEmpty = !prev.valid;
      for (int k = 0; k < u_secantSteps; ++k) {
        float dn;
        if (lo.valid && hi.valid) {
          float gl = lo.len / lo.stored, gp = hi.len / hi.stored;
          float den = gp - gl;
          float w = abs(den) > 1e-12 ? (1.0 - gl) / den : 0.5;
          dn = mix(lo.d, hi.d, clamp(w, 0.0, 1.0));
        } else {
          dn = 0.5 * (lo.d + hi.d);
        }
        m = probe(cube, x, R, dn);
        if (overshoots(m) == overshoots(lo)) lo = m; else hi = m;
      }
      // Accept only a crossing of one continuous surface (thesis 5.1.2: the safe search must bracket
      // "a continuous surface"). Where the bracket straddles a depth discontinuity of the layer (the
      // silhouette of a nearer surface) the ray passes behind that surface as seen from the reference
      // point. Linear filtering bridges the discontinuity with a one-texel ramp (a "rubber sheet") on
      // which the secant converges like on any surface, so the test uses the nearest texel at the
      // converged point: on a real surface the ray is within a texel's step of it; at a discontinuity
      // it is in front of the far side or behind the near side by the jump. A texel spans 2/res of the
      // distance at a face centre and its step grows as the surface turns edge-on to the reference
      // point (2/res tan(inclination)). Tolerance between two surface texels: 16 texels (inclinations up
      // to atan 8 ~ 83 deg) plus what the bracket itself still spans (few secant steps leave it wide).
      // A bracket that began in an empty texel is the edge of a surface against nothing (no sheet to
      // fear): the ray must come within one texel of the filtered surface there.
      // The radial test is the coarse one; onStoredSurface's plane test tells a slanted surface from a
      // sheet.
      Probe at = m.valid ? m : hi;
      float nearestStored = texture(t_ldmGeometry, vec4(at.len > 1e-30 ? x + R * at.d : R, cube)).z;
      float check = nearestStored > 0.0 && !fromEmpty ? nearestStored : at.stored;
      float span = abs(hi.len - lo.len);
      float tol = fromEmpty ? 2.0 * at.stored / u_cubeResolution : 32.0 * at.stored / u_cubeResolution + span;
      if (at.valid && abs(at.len - check) <= tol &&
          (fromEmpty || at.len <= 1e-30 || onStoredSurface(x + R * at.d, at.len, cube, span))) {
        dHit = at.d;
        return true;
      }
      // Passed behind a nearer surface (undershooting the far one, then overshooting the near one):
      // remember the far side, the last point known to be in front of it.
      if (crossIn && !fromEmpty && lo.valid && dHidden < 0.0) dHidden = lo.d;
    }
    prev = cur;
  }
  return false;
}

// The curvature (1 / radius) of a convex surface at a texel found in the maps, or 0 where it is flat,
// concave or unknown: the turn of the stored normal towards each of two neighbouring texels (a texel
// along two tangents of the cube direction, the same surface by object code) per unit of distance
// between the texels' surface points, (n' - n).(S' - S) / |S' - S|^2, positive where the normals
// diverge; the larger of the two. The points are the texels' centre directions times their stored
// distances, the points their normals were stored for (a sphere of radius r gives 1 / r whatever the
// resolution). spacing: the distance between those points, the texel's size on the surface (the
// normal at a hit is known to that: the nearest texel's).
float mapConvexCurvature(vec3 dir, float cube, vec4 geo, out float spacing) {
  vec3 d = normalize(cubeTexelCentre(dir, u_cubeResolution));
  vec3 t1 = normalize(cross(abs(d.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0), d));
  vec3 t2 = cross(d, t1);
  vec3 n = normalize(octDecode(geo.xy));
  vec3 S = d * geo.z;
  float k = 0.0;
  spacing = 0.0;
  for (int a = 0; a < 2; ++a) {
    // One texel's width at a face centre, 2 / res, is at least one texel anywhere on the face.
    vec3 dq = normalize(cubeTexelCentre(d + (a == 0 ? t1 : t2) * (2.0 / u_cubeResolution), u_cubeResolution));
    vec4 gq = texture(t_ldmGeometry, vec4(dq, cube));
    if (!(gq.z > 0.0 && gq.z < 1e30) || abs(gq.w - geo.w) > 0.5) continue;
    vec3 dS = dq * gq.z - S;
    float len2 = dot(dS, dS);
    if (!(len2 > 0.0)) continue;
    k = max(k, dot(normalize(octDecode(gq.xy)) - n, dS) / len2);
    spacing = max(spacing, sqrt(len2));
  }
  return k;
}

// Algorithm 3's "for each layer ... find the closest intersection". Where no layer has one but the
// ray passed behind a silhouette in some layer (what it meets is hidden from the reference point in
// every layer: depth peeling, `layers` > 3, stores more of it), the nearest such far side stands in
// for it: the surface next to the silhouette, not the sheet across it, nor a miss (the environment,
// black inside a closed room).
bool traceLayers(int object, vec3 originWorld, vec3 R, out float dHit, out int hitLayer) {
  vec3 x = originWorld - objects[object].referenceRadius.xyz;
  dHit = 3.4e38;
  hitLayer = -1;
  float dStandIn = 3.4e38;
  int standInLayer = -1;
  for (int l = 0; l < u_layers; ++l) {
    float d, hidden;
    if (traceLayer(object, l, x, R, d, hidden)) {
      if (d < dHit) {
        dHit = d;
        hitLayer = l;
      }
    } else if (hidden >= 0.0 && hidden < dStandIn) {
      dStandIn = hidden;
      standInLayer = l;
    }
  }
  if (hitLayer < 0 && standInLayer >= 0) {
    dHit = dStandIn;
    hitLayer = standInLayer;
  }
  return hitLayer >= 0;
}
#endif  // LDM_TRACING

#endif
