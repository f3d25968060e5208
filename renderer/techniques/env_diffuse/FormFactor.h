#pragma once
// The math of robust diffuse environment mapping (thesis ch. 3), header-only and GL-free so that
// tests/unit/env_diffuse checks it against closed forms. shaders/env_diffuse/form_factor.glsl is a
// line-by-line mirror: keep the two in step.
//
// Normalisation: every "form factor" here is the PROJECTED SOLID ANGLE
//     F = \int_{polygon} cos+(theta_x) dw     (0 <= F <= pi),
// i.e. the area of the polygon's double projection (hemisphere, then tangent plane) that thesis eq. 3.3
// computes. A polygon covering the whole hemisphere gives pi. The irradiance of a Lambertian polygon of
// radiance L is E = L F, and a Lambertian receiver of albedo a reflects L_o = a E / pi. (The classical
// radiosity form factor is F / pi.)
#include <algorithm>
#include <array>
#include <cmath>

#include <glm/glm.hpp>

namespace radiant::env_diffuse {

// ---- Cube map faces (GL 4.5 spec table 8.19) ------------------------------------------------------
// Face order +X, -X, +Y, -Y, +Z, -Z. A direction r maps to face coordinates (sc, tc) in [-1, 1], and the
// texel (i, j) of an M x M face covers s = (sc + 1) / 2 in [i/M, (i+1)/M), t likewise with j.
inline glm::vec3 cubeFaceDirection(int face, float sc, float tc) {
  switch (face) {
    case 0: return {1.f, -tc, -sc};
    case 1: return {-1.f, -tc, sc};
    case 2: return {sc, 1.f, tc};
    case 3: return {sc, -1.f, -tc};
    case 4: return {sc, -tc, 1.f};
    default: return {-sc, -tc, -1.f};
  }
}

// Inverse of cubeFaceDirection for unnormalised r: returns the face, writes (sc, tc).
inline int cubeFaceOf(const glm::vec3& r, float& sc, float& tc) {
  const glm::vec3 a = glm::abs(r);
  if (a.x >= a.y && a.x >= a.z) {
    if (r.x > 0) { sc = -r.z / a.x; tc = -r.y / a.x; return 0; }
    sc = r.z / a.x; tc = -r.y / a.x; return 1;
  }
  if (a.y >= a.z) {
    if (r.y > 0) { sc = r.x / a.y; tc = r.z / a.y; return 2; }
    sc = r.x / a.y; tc = -r.z / a.y; return 3;
  }
  if (r.z > 0) { sc = r.x / a.z; tc = -r.y / a.z; return 4; }
  sc = -r.x / a.z; tc = -r.y / a.z; return 5;
}

// Solid angle of the face region [x0, x1] x [y0, y1] (face coordinates): the integral of the area
// element dw = dx dy / (1 + x^2 + y^2)^(3/2), whose antiderivative is atan2(x y, sqrt(1 + x^2 + y^2)).
inline float cubeTexelSolidAngle(float x0, float y0, float x1, float y1) {
  auto A = [](float x, float y) { return std::atan2(x * y, std::sqrt(1.f + x * x + y * y)); };
  return A(x1, y1) - A(x0, y1) - A(x1, y0) + A(x0, y0);
}

// ---- Polygon-to-point form factor (thesis eq. 3.3) -------------------------------------------------
// One edge's signed ellipse-sector area: 1/2 angle(a, b) (a x b / |a x b|) . n, for unit a, b.
// Written as 1/2 (theta / sin theta) (a x b) . n so that it is smooth as theta -> 0 (theta / sin -> 1).
// theta -> pi means the shaded point lies on the edge: the edge's great circle is undefined there and
// the term is taken as 0, the limit when the point is approached from in front of the polygon.
inline float formFactorEdge(const glm::vec3& a, const glm::vec3& b, const glm::vec3& n) {
  const glm::vec3 c = glm::cross(a, b);
  const float s = glm::length(c);
  if (s < 1e-7f) return 0.f;
  const float theta = std::atan2(s, glm::dot(a, b));
  return 0.5f * theta / s * glm::dot(c, n);
}

// Polygon-to-point form factor of a planar convex polygon with vertices R[0..count) given RELATIVE to
// the shaded point x (only their directions matter: a vertex at infinity is its unit direction), as
// seen by a surface at x with unit normal n. Vertices wind so that (R_l x R_l+1) . n > 0 for a polygon
// that faces x (counter-clockwise around n seen from the tip of n, i.e. clockwise as x sees it).
//
// thesis eq. 3.3 sums the signed sectors of all edges. Its derivation assumes the polygon lies in the
// hemisphere above x; the raw sum is \int cos(theta_x) dw with the cosine NOT clamped, so parts below
// the horizon subtract. `horizonClip` first clips the polygon to the half-space n . R >= 0
// (Sutherland-Hodgman), which makes the sum the exact projected solid angle for any position.
// Algorithm 1 then keeps the positive part: a polygon seen from behind (or wholly below the horizon)
// has a negative sum and contributes nothing. The printed pseudo code puts max(0, .) inside the edge
// loop, which is not a form factor (an off-axis polygon's near edges are negative sectors); we read it
// as max(0, sum over edges), and tests/unit/env_diffuse shows why.
//
// Degenerate vertices: a vertex at x (|R| ~ 0, e.g. a zero-distance texel or the shaded point on a
// polygon corner) takes the direction n, the limit as x approaches it from in front along the normal.
inline float formFactorPolygonToPoint(const glm::vec3* R, int count, const glm::vec3& n, bool horizonClip) {
  std::array<glm::vec3, 8> v{};
  float scale = 0.f;
  for (int i = 0; i < count; ++i) scale = std::max(scale, glm::dot(R[i], R[i]));
  if (!(scale > 0.f) || !std::isfinite(scale)) return 0.f;
  for (int i = 0; i < count; ++i) v[i] = glm::dot(R[i], R[i]) <= 1e-10f * scale ? n : R[i] / std::sqrt(scale);
  int m = count;
  if (horizonClip) {
    std::array<glm::vec3, 8> c{};
    int k = 0;
    for (int i = 0; i < m; ++i) {
      const glm::vec3& a = v[i];
      const glm::vec3& b = v[(i + 1) % m];
      const float da = glm::dot(a, n), db = glm::dot(b, n);
      if (da >= 0.f) c[k++] = a;
      if ((da >= 0.f) != (db >= 0.f)) c[k++] = a + (b - a) * (da / (da - db));
    }
    v = c;
    m = k;
    if (m < 3) return 0.f;
  }
  float sum = 0.f;
  for (int i = 0; i < m; ++i) {
    const glm::vec3 a = v[i], b = v[(i + 1) % m];
    const float la = glm::length(a), lb = glm::length(b);
    if (la <= 0.f || lb <= 0.f) continue;
    sum += formFactorEdge(a / la, b / lb, n);
  }
  return std::max(0.f, sum);
}

// ---- Point-to-point form factor (virtual point lights: the chapter's unstable baseline) ------------
// A cube-map texel as a point light at y with normal ny and area A: F = cos+ theta_x cos+ theta_y A / r^2.
// It diverges as x approaches y (r -> 0): the "bright spikes" of thesis Fig. 3.3/3.4. Only a light AT x
// (r = 0, where both cosines are undefined) is taken as 0, so results stay finite.
inline float formFactorPointToPoint(const glm::vec3& x, const glm::vec3& n, const glm::vec3& y, const glm::vec3& ny,
                                    float area) {
  const glm::vec3 d = y - x;
  const float r2 = glm::dot(d, d);
  if (!(r2 > 1e-20f)) return 0.f;
  const glm::vec3 w = d / std::sqrt(r2);
  return std::max(0.f, glm::dot(n, w)) * std::max(0.f, -glm::dot(ny, w)) * area / r2;
}

// Area of the surface seen through a cube texel of solid angle dw at distance d from the reference
// point, with unit normal ny at angle theta_o to the direction back to the reference point:
// A = dw d^2 / cos(theta_o). cos is clamped at 0.1 so a grazing patch does not become an unbounded light.
inline float vplArea(float solidAngle, float distance, float cosToReference) {
  return solidAngle * distance * distance / std::max(cosToReference, 0.1f);
}

}  // namespace radiant::env_diffuse
