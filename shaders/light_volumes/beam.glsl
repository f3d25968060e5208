// Light volumes (Duvenhage, Bouatouch, Kourie, "Exploring the Use of Glossy Light Volumes for
// Interactive Global Illumination"): the per-beam gathering maths, the one definition for GLSL and C++.
//   GLSL: #include "light_volumes/beam.glsl" (the shader library prepends #version 450 core);
//   C++:  renderer/techniques/light_volumes/BeamMath.h includes this file inside a namespace with
//         glm's vec2/vec3/vec4 and functions, and static_asserts the layout.
// Rules that keep the two readings identical: float literals carry the f suffix, no in/out/inout
// parameters, no struct constructors, functions marked LV_FN (inline in C++), no swizzles (vec3(v) takes xyz), every struct member a vec4
// (std430 without padding).
#ifndef RADIANT_LIGHT_VOLUMES_BEAM_GLSL
#define RADIANT_LIGHT_VOLUMES_BEAM_GLSL

#ifdef __cplusplus
#define LV_CONST inline constexpr
#define LV_FN inline
#else
#define LV_CONST const
#define LV_FN
#endif

LV_CONST float kLvPi = 3.14159265358979f;
LV_CONST int kLvSplitPaper = 0;  // the printed Fig. 12 split (D from the world-space edge point)
LV_CONST int kLvSplit2d = 1;     // D = AB intersected with the ray O->C in the angular domain (continuous)
// A scattered beam's light-path class (Beam::vertexC.w; gather.comp's u_beautyClasses bits): the
// scatterer's material decides, not the beam's sigma, so a glossy scatterer's specular fallback beams
// (tessellation_fallback, sigma 0) stay LG+DE.
LV_CONST int kLvClassSpecular = 1;  // LS+DE: a mirror or smooth glass (roughness 0)
LV_CONST int kLvClassGlossy = 2;    // LG+DE: glossy metal or glass (roughness > 0)

// One beam: 8 x vec4 = 128 bytes, as the paper's 8 RGBA texels (§4.3).
struct Beam {
  vec4 vertexA;    // xyz V_a (scatterer vertex), w: 1 / A_min, the irradiance clamp (Phi / A_perp <= Phi * w)
  vec4 vertexB;    // xyz V_b, w: 0 scattered beam, 1 shadow beam
  vec4 vertexC;    // xyz V_c, w: the light-path class of a scattered beam, by its scatterer's material
                   // (kLvClassSpecular, kLvClassGlossy; 0 for a shadow beam)
  vec4 dirA;       // xyz unit scattered (or, for a shadow beam, unscattered) direction at V_a
  vec4 dirB;
  vec4 dirC;
  vec4 fluxSigma;  // rgb beam flux Phi (W; negative for shadow beams), w: sigma (rad; 0 = specular)
  vec4 plane;      // generator plane: xyz unit normal pointing into the beam's half-space, w = -dot(n, V_a)
};

// A bound of the beam for culling: the points that can receive from it lie within distance
// radius0 + slope * s of the axis, s = dot(F - origin, axis) >= 0 (a truncated cone, padded for
// glossy beams by cull_sigmas * sigma; renderer/techniques/light_volumes/Beams.cpp).
struct BeamCone {
  vec4 originRadius;  // xyz centroid of the scatterer triangle, w radius at s = 0
  vec4 axisSlope;     // xyz unit mean direction N, w radius slope per unit s
};

// The culled traversal (renderer/techniques/light_volumes/BeamBvh.h): a BVH over segments of the
// beams' cones, one BVH per group of beams. A node's box holds its subtree; meta.x is the index of
// its second child (the first is the next node) or -1 for a leaf, whose primitives are
// [meta.y, meta.y + meta.z). A primitive is the part s0 <= s < s1 of one beam's cone: x s0, y s1,
// z the beam index (exact in float below 2^24), w unused; a fragment is gathered from the beam by the
// one segment whose s-range holds it, so no beam counts twice.
struct BeamBvhNode {
  vec4 lo;
  vec4 hi;
  ivec4 meta;
};

// The normalised 2-D Gaussian over the angular deviation x (rad): exp(-|x|^2 / 2 sigma^2) / (2 pi sigma^2).
LV_FN float lvGaussian(vec2 x, float sigma) {
  float s2 = sigma * sigma;
  return exp(-dot(x, x) / (2.0f * s2)) / (2.0f * kLvPi * s2);
}

LV_FN float lvCross(vec2 a, vec2 b) { return a.x * b.y - a.y * b.x; }

// The angle between u and the unit direction d (atan2 form: accurate near 0, where acos is not).
LV_FN float lvAngle(vec3 u, vec3 d) { return atan(length(cross(u, d)), dot(u, d)); }

LV_FN vec2 lvSafeNormalize(vec2 v) {
  float l = length(v);
  return l > 1e-30f ? v / l : vec2(0.0f);
}

// Twice the unsigned area of the triangle (a, b, c).
LV_FN float lvArea2(vec2 a, vec2 b, vec2 c) { return abs(lvCross(b - a, c - a)); }

// The volume under the Gaussian over the angular triangles CAD and CDB: the edge region of Fig. 12,
// with AB split at D. Fig. 12's second P_CAD is read as P_CDB (notes A7); the areas are the
// triangles' own (the printed "Area ABD" lacks its d x a term, notes A7).
LV_FN float lvVolumeEdge(vec2 A, vec2 B, vec2 C, vec2 D, float sigma) {
  float pA = lvGaussian(A, sigma), pB = lvGaussian(B, sigma), pC = lvGaussian(C, sigma), pD = lvGaussian(D, sigma);
  return 0.5f * lvArea2(C, A, D) * (pC + pA + pD) / 3.0f + 0.5f * lvArea2(C, D, B) * (pC + pD + pB) / 3.0f;
}

// The parameter s of the point D = A + s (B - A) on edge AB where the line through the origin and C
// crosses it (cross(D, C) = 0), clamped to the edge. Used in the angular domain (the 2-D split) and
// in the flux plane (the printed split's D_F).
LV_FN float lvSplitParameter(vec2 A, vec2 B, vec2 C) {
  float den = lvCross(A - B, C);
  return abs(den) > 1e-30f ? clamp(lvCross(A, C) / den, 0.0f, 1.0f) : 0.5f;
}
LV_FN vec2 lvSplitPoint(vec2 A, vec2 B, vec2 C) { return A + lvSplitParameter(A, B, C) * (B - A); }

// P_E with the 2-D split: the volume under the Gaussian (centred at the origin O) over the angular
// triangle ABC, by the facets of Figs. 11 and 12: through the peak P_O when O is inside, split at
// D = AB intersected with line OC when O is beyond edge AB only, one facet over ABC in a vertex region.
LV_FN float lvVolume2d(vec2 A, vec2 B, vec2 C, float sigma) {
  float orient = lvCross(B - A, C - A) >= 0.0f ? 1.0f : -1.0f;
  float eab = orient * lvCross(A, B), ebc = orient * lvCross(B, C), eca = orient * lvCross(C, A);
  float pA = lvGaussian(A, sigma), pB = lvGaussian(B, sigma), pC = lvGaussian(C, sigma);
  if (eab >= 0.0f && ebc >= 0.0f && eca >= 0.0f) {
    float pO = 1.0f / (2.0f * kLvPi * sigma * sigma);
    return 0.5f * (abs(eab) * (pA + pO + pB) + abs(ebc) * (pB + pO + pC) + abs(eca) * (pC + pO + pA)) / 3.0f;
  }
  int outsideEdges = (eab < 0.0f ? 1 : 0) + (ebc < 0.0f ? 1 : 0) + (eca < 0.0f ? 1 : 0);
  if (outsideEdges >= 2) return 0.5f * lvArea2(A, B, C) * (pA + pB + pC) / 3.0f;
  if (eab < 0.0f) return lvVolumeEdge(A, B, C, lvSplitPoint(A, B, C), sigma);
  if (ebc < 0.0f) return lvVolumeEdge(B, C, A, lvSplitPoint(B, C, A), sigma);
  return lvVolumeEdge(C, A, B, lvSplitPoint(C, A, B), sigma);
}

// The irradiance per unit beam flux that beam `b` delivers to a receiver at F with unit normal n:
// E = Phi * beamIrradianceFactor(b, F, n, split).
//   specular (sigma = 0): Phi / A_perp * cos(theta) inside the flux triangle, 0 outside (eqs. 1, 2);
//   glossy: Phi / A_perp * cos(theta) * min(P_E, 1) (eqs. 3 to 5, Figs. 9 to 12).
// The flux plane passes through F perpendicular to N = normalise(d_a + d_b + d_c) (Fig. 5); X_k =
// V_k + t_k d_k with t_k = ((F - V_k).N) / (d_k.N). t_k < 0 (grazing) is allowed; a triangle whose
// orientation flips past a focus is handled by the sign of its area; A_perp -> 0 at caustic curves is
// clamped by 1 / A_min (vertexA.w); d_k.N <= 1e-4 (a beam fanning out by 90 degrees) gives 0.
LV_FN float beamIrradianceFactor(Beam b, vec3 F, vec3 n, int split) {
  if (dot(vec3(b.plane), F) + b.plane.w <= 0.0f) return 0.0f;  // behind the generator plane (notes A7)
  vec3 da = vec3(b.dirA), db = vec3(b.dirB), dc = vec3(b.dirC);
  vec3 sum = da + db + dc;
  float sumLength = length(sum);
  if (!(sumLength > 1e-6f)) return 0.0f;
  vec3 N = sum / sumLength;
  float cosTheta = -dot(n, N);
  if (!(cosTheta > 0.0f)) return 0.0f;
  float ka = dot(da, N), kb = dot(db, N), kc = dot(dc, N);
  if (!(min(ka, min(kb, kc)) > 1e-4f)) return 0.0f;
  vec3 Va = vec3(b.vertexA), Vb = vec3(b.vertexB), Vc = vec3(b.vertexC);
  vec3 Xa = Va + (dot(F - Va, N) / ka) * da;
  vec3 Xb = Vb + (dot(F - Vb, N) / kb) * db;
  vec3 Xc = Vc + (dot(F - Vc, N) / kc) * dc;
  // An orthonormal basis (T, S) of the flux plane (Duff et al. 2017), F at the origin.
  float sgn = N.z >= 0.0f ? 1.0f : -1.0f;
  float q = -1.0f / (sgn + N.z);
  float nxy = N.x * N.y * q;
  vec3 T = vec3(1.0f + sgn * N.x * N.x * q, sgn * nxy, -sgn * N.x);
  vec3 S = vec3(nxy, sgn + N.y * N.y * q, -N.y);
  vec2 a = vec2(dot(Xa - F, T), dot(Xa - F, S));
  vec2 bb = vec2(dot(Xb - F, T), dot(Xb - F, S));
  vec2 c = vec2(dot(Xc - F, T), dot(Xc - F, S));
  float area2 = lvCross(bb - a, c - a);
  float orient = area2 >= 0.0f ? 1.0f : -1.0f;
  float aPerp = 0.5f * abs(area2);
  // Phi / A_perp, clamped at caustic curves (A_perp -> 0).
  float density = aPerp * b.vertexA.w > 1.0f ? 1.0f / aPerp : b.vertexA.w;
  // Signed edge functions of F (the origin) against the flux triangle (Fig. 12, step 1).
  float eab = orient * lvCross(a, bb), ebc = orient * lvCross(bb, c), eca = orient * lvCross(c, a);
  bool inside = eab >= 0.0f && ebc >= 0.0f && eca >= 0.0f;
  float sigma = b.fluxSigma.w;
  if (!(sigma > 0.0f)) return inside ? density * cosTheta : 0.0f;

  // Angular domain (§4.2.1): A = phi_a l_a, ..., O = F at the origin.
  float phiA = lvAngle(F - Va, da), phiB = lvAngle(F - Vb, db), phiC = lvAngle(F - Vc, dc);
  vec2 A = phiA * lvSafeNormalize(a), B = phiB * lvSafeNormalize(bb), C = phiC * lvSafeNormalize(c);
  float pE;
  int outsideEdges = (eab < 0.0f ? 1 : 0) + (ebc < 0.0f ? 1 : 0) + (eca < 0.0f ? 1 : 0);
  if (split == kLvSplitPaper && outsideEdges == 1) {
    // Fig. 12, step 3 as printed: D_F -> s -> D_W and S_D -> phi_d; D = phi_d l_d, l_d the direction
    // of D_F. Relabel so that the crossed edge is (E0, E1) and the opposite vertex E2.
    vec2 E0 = A, E1 = B, E2 = C, e0 = a, e1 = bb, e2 = c;
    vec3 W0 = Va, W1 = Vb, w0 = da, w1 = db;
    if (ebc < 0.0f) { E0 = B; E1 = C; E2 = A; e0 = bb; e1 = c; e2 = a; W0 = Vb; W1 = Vc; w0 = db; w1 = dc; }
    if (eca < 0.0f) { E0 = C; E1 = A; E2 = B; e0 = c; e1 = a; e2 = bb; W0 = Vc; W1 = Va; w0 = dc; w1 = da; }
    float s = lvSplitParameter(e0, e1, e2);
    vec3 DW = W0 + s * (W1 - W0);
    vec3 SD = normalize(w0 + s * (w1 - w0));
    vec2 D = lvAngle(F - DW, SD) * lvSafeNormalize(e0 + s * (e1 - e0));
    pE = lvVolumeEdge(E0, E1, E2, D, sigma);
  } else {
    pE = lvVolume2d(A, B, C, sigma);
  }
  return density * cosTheta * min(pE, 1.0f);
}

#endif
