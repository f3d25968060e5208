// The math of robust diffuse environment mapping (thesis ch. 3) against closed forms and quadrature.
// Form factors are projected solid angles (pi = the whole hemisphere), see FormFactor.h.
#include <array>
#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "renderer/shading/CubeFaces.h"
#include <glm/gtc/constants.hpp>

#include "renderer/techniques/env_diffuse/FormFactor.h"
#include "renderer/techniques/shadow_maps/ShadowMaps.h"

namespace radiant::env_diffuse {
namespace {

constexpr float kPi = glm::pi<float>();

// Differential area to a parallel rectangle with one corner on the normal through the point, sides
// A = a/h and B = b/h (Howell's catalogue, configuration B-3; the classical form factor, so x pi):
//   F = 1/(2 pi) [A/sqrt(1+A^2) atan(B/sqrt(1+A^2)) + B/sqrt(1+B^2) atan(A/sqrt(1+B^2))].
double cornerRectangle(double A, double B) {
  const double a = std::sqrt(1 + A * A), b = std::sqrt(1 + B * B);
  return (A / a * std::atan(B / a) + B / b * std::atan(A / b)) / (2 * M_PI);
}

// The square [-a, a]^2 at height h above x = 0, wound for n = +z (counter-clockwise seen from +z).
std::array<glm::vec3, 4> squareAbove(float a, float h, glm::vec3 x = glm::vec3(0.f)) {
  return {glm::vec3(-a, -a, h) - x, glm::vec3(a, -a, h) - x, glm::vec3(a, a, h) - x, glm::vec3(-a, a, h) - x};
}

float ff(const std::array<glm::vec3, 4>& q, glm::vec3 n, bool clip = true) {
  return formFactorPolygonToPoint(q.data(), 4, n, clip);
}

// Midpoint quadrature of \int cos+(theta_x) cos(theta_y) / r^2 dA over the parallelogram p0 + s u + t v.
double quadrature(glm::dvec3 x, glm::dvec3 n, glm::dvec3 p0, glm::dvec3 u, glm::dvec3 v, int N = 600) {
  const glm::dvec3 ny = glm::normalize(glm::cross(u, v));
  const double dA = glm::length(glm::cross(u, v)) / (double(N) * N);
  double sum = 0;
  for (int i = 0; i < N; ++i)
    for (int j = 0; j < N; ++j) {
      const glm::dvec3 y = p0 + u * ((i + 0.5) / N) + v * ((j + 0.5) / N);
      const glm::dvec3 d = y - x;
      const double r2 = glm::dot(d, d);
      const glm::dvec3 w = d / std::sqrt(r2);
      sum += std::max(0.0, glm::dot(n, w)) * std::abs(glm::dot(ny, w)) / r2 * dA;
    }
  return sum;
}

TEST(FormFactor, HeadOnSquareMatchesClosedForm) {
  for (float a : {0.05f, 0.3f, 1.f, 2.5f, 10.f}) {
    const double expected = kPi * 4.0 * cornerRectangle(a, a);  // four corner rectangles
    EXPECT_NEAR(ff(squareAbove(a, 1.f), {0, 0, 1}), expected, 2e-4 * expected + 1e-7) << "a/h = " << a;
    EXPECT_NEAR(ff(squareAbove(a, 1.f), {0, 0, 1}, false), expected, 2e-4 * expected + 1e-7) << "unclipped, a/h = " << a;
  }
  // Scale invariance: only directions matter.
  EXPECT_NEAR(ff(squareAbove(3.f, 3.f), {0, 0, 1}), ff(squareAbove(1.f, 1.f), {0, 0, 1}), 1e-5);
}

TEST(FormFactor, OffAxisTiltedQuadMatchesQuadratureAndFixesTheReadingOfAlgorithm1) {
  // A quad off to the side and tilted, wholly above the horizon of a tilted normal.
  const glm::dvec3 x(0.1, -0.2, 0.05), n = glm::normalize(glm::dvec3(0.3, 0.2, 1.0));
  const glm::dvec3 p0(0.4, 0.3, 0.8), u(0.6, 0.1, 0.2), v(-0.1, 0.5, 0.3);
  // Wind so that the right-hand polygon normal points away from x (the quad's front faces x).
  std::array<glm::vec3, 4> q{glm::vec3(p0 - x), glm::vec3(p0 + u - x), glm::vec3(p0 + u + v - x), glm::vec3(p0 + v - x)};
  if (glm::dot(glm::cross(q[1] - q[0], q[3] - q[0]), q[0]) < 0) std::swap(q[1], q[3]);
  const double expected = quadrature(x, n, p0, u, v);
  EXPECT_NEAR(ff(q, glm::vec3(n)), expected, 2e-3 * expected);
  // Algorithm 1 as printed clamps every edge term at 0. For this quad some edge sectors are negative
  // (they are subtracted in the thesis' own derivation of eq. 3.3), so clamping per edge overestimates:
  // we clamp the sum instead (FormFactor.h).
  double perEdge = 0;
  for (int l = 0; l < 4; ++l)
    perEdge += std::max(0.f, formFactorEdge(glm::normalize(q[l]), glm::normalize(q[(l + 1) % 4]), glm::vec3(n)));
  EXPECT_GT(perEdge, 1.2 * expected);
}

TEST(FormFactor, HorizonClippingGivesTheClampedCosineIntegral) {
  // A vertical quad standing on the tangent plane of x and reaching below it: half of it is below the
  // horizon. Clipped = quadrature of cos+; unclipped subtracts the lower half (the raw eq. 3.3 sum).
  const glm::dvec3 x(0, 0, 0), n(0, 0, 1);
  const glm::dvec3 p0(-0.5, 1.0, -0.4), u(1.0, 0, 0), v(0, 0, 1.0);  // plane y = 1, z in [-0.4, 0.6]
  std::array<glm::vec3, 4> q{glm::vec3(p0), glm::vec3(p0 + u), glm::vec3(p0 + u + v), glm::vec3(p0 + v)};
  if (glm::dot(glm::cross(q[1] - q[0], q[3] - q[0]), q[0]) < 0) std::swap(q[1], q[3]);
  const double expected = quadrature(x, n, p0, u, v, 800);
  const float clipped = ff(q, glm::vec3(n), true);
  EXPECT_NEAR(clipped, expected, 3e-3 * expected);
  EXPECT_LT(ff(q, glm::vec3(n), false), clipped - 0.02f);
}

TEST(FormFactor, HemisphereCoveringPolygonGivesPi) {
  // A huge square just above: pi (1 - O(h^2 / a^2)).
  EXPECT_NEAR(ff(squareAbove(1e4f, 1.f), {0, 0, 1}), kPi, 1e-3);
  // x on the polygon's plane, inside it: the polygon covers the whole hemisphere.
  EXPECT_NEAR(ff(squareAbove(1.f, 0.f), {0, 0, 1}), kPi, 1e-5);
  // A closed environment around x (a room of quads, as the cube map builds it) for random positions
  // and normals: with horizon clipping exactly pi; without it the quads straddling the horizon lose
  // their lower part, so the positive part sums to less.
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> U(-1.f, 1.f);
  const int M = 4;
  for (int trial = 0; trial < 8; ++trial) {
    const glm::vec3 x = 0.5f * glm::vec3(U(rng), U(rng), U(rng));
    const glm::vec3 n = glm::normalize(glm::vec3(U(rng), U(rng), U(rng)));
    double clipped = 0, raw = 0;
    for (int f = 0; f < 6; ++f)
      for (int j = 0; j < M; ++j)
        for (int i = 0; i < M; ++i) {
          const float h = 2.f / M, u0 = -1 + h * i, v0 = -1 + h * j;
          // Corners on the walls of the cube [-1, 1]^3 around the reference point o = 0, in the corner
          // order of shaders/env_diffuse/quads.comp.
          std::array<glm::vec3, 4> q{cubeFaceDirection(f, u0, v0) - x, cubeFaceDirection(f, u0, v0 + h) - x,
                                     cubeFaceDirection(f, u0 + h, v0 + h) - x, cubeFaceDirection(f, u0 + h, v0) - x};
          clipped += ff(q, n, true);
          raw += ff(q, n, false);
        }
    EXPECT_NEAR(clipped, kPi, 2e-4) << "trial " << trial;
    EXPECT_LE(raw, kPi + 1e-4);
    EXPECT_GT(raw, 0.5 * kPi);
  }
}

TEST(FormFactor, QuadCornerOrderOfTheCubeMapFacesTheReferencePoint) {
  // Every texel of every face, corners in quads.comp's order, seen from o with n along the texel
  // centre: positive. Over a sphere of quads around o the sum is pi for any normal.
  const int M = 8;
  double sum = 0;
  const glm::vec3 n = glm::normalize(glm::vec3(0.2f, -0.7f, 0.4f));
  for (int f = 0; f < 6; ++f)
    for (int j = 0; j < M; ++j)
      for (int i = 0; i < M; ++i) {
        const float h = 2.f / M, u0 = -1 + h * i, v0 = -1 + h * j;
        std::array<glm::vec3, 4> q{glm::normalize(cubeFaceDirection(f, u0, v0)), glm::normalize(cubeFaceDirection(f, u0, v0 + h)),
                                   glm::normalize(cubeFaceDirection(f, u0 + h, v0 + h)), glm::normalize(cubeFaceDirection(f, u0 + h, v0))};
        const glm::vec3 c = glm::normalize(cubeFaceDirection(f, u0 + h / 2, v0 + h / 2));
        EXPECT_GT(ff(q, c), 0.f) << "face " << f << " texel " << i << "," << j;
        sum += ff(q, n);
      }
  EXPECT_NEAR(sum, kPi, 1e-3);
}

TEST(FormFactor, ApproachingThePlaneEdgeAndCornerStaysFiniteAndContinuous) {
  // Unit square [-1/2, 1/2]^2 in the plane z = 1 facing down at x; x rises towards the plane below its
  // centre, its edge midpoint and its corner. Limits: the polygon fills the whole, half and a quarter
  // of the hemisphere: pi, pi/2, pi/4. Exactly on the plane the value equals the limit.
  struct Case { glm::vec2 xy; float limit; const char* name; };
  for (const Case& c : {Case{{0.f, 0.f}, kPi, "centre"}, Case{{0.5f, 0.f}, kPi / 2, "edge"},
                        Case{{0.5f, 0.5f}, kPi / 4, "corner"}, Case{{0.8f, 0.1f}, 0.f, "outside"}}) {
    for (bool clip : {true, false}) {
      float prev = ff(squareAbove(0.5f, 1.f, glm::vec3(c.xy, 0.5f)), {0, 0, 1}, clip);
      for (int k = 1; k <= 5000; ++k) {
        const float z = 0.5f + 0.5f * k / 5000.f;  // up to and including the plane
        const float F = ff(squareAbove(0.5f, 1.f, glm::vec3(c.xy, z)), {0, 0, 1}, clip);
        ASSERT_TRUE(std::isfinite(F)) << c.name << " z=" << z;
        ASSERT_LE(F, kPi + 1e-4f);
        ASSERT_LT(std::abs(F - prev), 0.02f) << c.name << " jumps at z=" << z << " clip " << clip;
        prev = F;
      }
      EXPECT_NEAR(prev, c.limit, 2e-3) << c.name << " on the plane, clip " << clip;
      EXPECT_NEAR(ff(squareAbove(0.5f, 1.f, glm::vec3(c.xy, 1.f - 1e-4f)), {0, 0, 1}, clip), c.limit, 2e-3) << c.name;
    }
  }
}

TEST(FormFactor, DegenerateInputStaysFinite) {
  const glm::vec3 n(0, 0, 1);
  const float inf = std::numeric_limits<float>::infinity();
  std::array<glm::vec3, 4> zero{};
  EXPECT_EQ(ff(zero, n), 0.f);  // a zero-distance texel seen from the reference point
  // A vertex at x (the shaded point on a corner of the texel quad).
  std::array<glm::vec3, 4> q = squareAbove(0.5f, 1.f);
  q[0] = glm::vec3(0.f);
  EXPECT_TRUE(std::isfinite(ff(q, n)));
  // Back-facing (wound the other way) and below the horizon: nothing.
  std::array<glm::vec3, 4> back = squareAbove(0.5f, 1.f);
  std::swap(back[1], back[3]);
  EXPECT_EQ(ff(back, n), 0.f);
  EXPECT_EQ(ff(back, n, false), 0.f);
  EXPECT_EQ(ff(squareAbove(0.5f, -1.f), n, true), 0.f);
  // Infinite vectors are not directions: the caller passes unit directions for corners at infinity
  // (shaders/env_diffuse/gather.glsl); an infinite one must still not produce NaN.
  std::array<glm::vec3, 4> huge = squareAbove(0.5f, 1.f);
  huge[2] = glm::vec3(inf, inf, inf);
  EXPECT_FALSE(std::isnan(ff(huge, n)));
  // Point-to-point: finite everywhere except it grows as 1/r^2; a light at x gives 0.
  EXPECT_EQ(formFactorPointToPoint({0, 0, 0}, n, {0, 0, 0}, {0, 0, -1}, 0.1f), 0.f);
  EXPECT_TRUE(std::isfinite(formFactorPointToPoint({0, 0, 0}, n, {0, 0, 1e-6f}, {0, 0, -1}, 0.1f)));
}

TEST(FormFactor, PointToPointAgreesFarAwayAndSpikesNearby) {
  // A small square light of area A = 0.01 at height h: the VPL form factor A / h^2 agrees with the
  // polygon form factor for h >> sqrt(A) and exceeds pi (impossible for any real surface) when h is
  // small: the instability the chapter removes.
  const float a = 0.05f, area = 4 * a * a;
  for (float h : {1.f, 2.f}) {
    const float poly = ff(squareAbove(a, h), {0, 0, 1});
    const float point = formFactorPointToPoint({0, 0, 0}, {0, 0, 1}, {0, 0, h}, {0, 0, -1}, area);
    EXPECT_NEAR(point, poly, 0.01f * poly);
  }
  const float h = 0.01f;
  EXPECT_LT(ff(squareAbove(a, h), {0, 0, 1}), kPi);
  EXPECT_GT(formFactorPointToPoint({0, 0, 0}, {0, 0, 1}, {0, 0, h}, {0, 0, -1}, area), 30.f * kPi);
}

TEST(CubeMap, FaceMappingRoundTripsAndMatchesTheFaceCameras) {
  for (int f = 0; f < 6; ++f)
    for (float s : {-0.9f, -0.3f, 0.f, 0.55f, 0.99f})
      for (float t : {-0.95f, 0.2f, 0.7f}) {
        float s2, t2;
        const glm::vec3 r = cubeFaceDirection(f, s, t);
        ASSERT_EQ(cubeFaceOf(r * 2.5f, s2, t2), f);
        EXPECT_NEAR(s2, s, 1e-6f);
        EXPECT_NEAR(t2, t, 1e-6f);
        // The face camera used to render the cube map puts direction r at NDC (s, t): framebuffer pixel
        // (x, y) is texel (x, y) of the face, as GL's sampler addresses it.
        const glm::vec3 o(0.3f, -1.f, 2.f);
        const glm::vec4 c = ShadowMapsPass::cubeFaceViewProj(o, f, 0.01f) * glm::vec4(o + r, 1.f);
        EXPECT_NEAR(c.x / c.w, s, 1e-5f) << "face " << f;
        EXPECT_NEAR(c.y / c.w, t, 1e-5f) << "face " << f;
      }
}

TEST(CubeMap, TexelSolidAnglesSumToTheSphere) {
  for (int M : {1, 2, 4, 16}) {
    double sum = 0;
    for (int j = 0; j < M; ++j)
      for (int i = 0; i < M; ++i) {
        const float h = 2.f / M;
        sum += cubeTexelSolidAngle(-1 + h * i, -1 + h * j, -1 + h * (i + 1), -1 + h * (j + 1));
      }
    EXPECT_NEAR(6 * sum, 4 * M_PI, 1e-4) << "M = " << M;
  }
  // One face is a sixth of the sphere; a centre texel of a fine face is ~ (2/M)^2.
  EXPECT_NEAR(cubeTexelSolidAngle(-1, -1, 1, 1), 4 * M_PI / 6, 1e-5);
  EXPECT_NEAR(cubeTexelSolidAngle(0, 0, 0.01f, 0.01f), 1e-4, 1e-7);
}

// sphereInCubeFace against the face cameras themselves: a sphere is in a face exactly when some point
// of it projects inside the face's NDC square in front of the camera; sampled spheres must never be
// culled from a face that sees them (the specular maps skip the meshes a face cannot see).
TEST(CubeFaces, SpheresAreCulledOnlyFromFacesThatCannotSeeThem) {
  const glm::vec3 o(0.3f, -1.f, 2.f);
  std::uint32_t state = 12345u;
  auto uniform = [&] { state = state * 1664525u + 1013904223u; return float(state >> 8) / float(1u << 24); };
  int culled = 0;
  for (int i = 0; i < 2000; ++i) {
    const glm::vec3 c = o + 4.f * glm::vec3(uniform() - 0.5f, uniform() - 0.5f, uniform() - 0.5f);
    const float r = 0.3f * uniform();
    for (int f = 0; f < 6; ++f) {
      if (sphereInCubeFace(o, f, c, r)) continue;
      ++culled;
      const glm::mat4 vp = ShadowMapsPass::cubeFaceViewProj(o, f, 0.01f);
      for (int k = 0; k < 64; ++k) {  // points of the sphere's surface and centre
        glm::vec3 d(uniform() - 0.5f, uniform() - 0.5f, uniform() - 0.5f);
        d = k == 0 ? glm::vec3(0.f) : r * glm::normalize(d + glm::vec3(1e-6f));
        const glm::vec4 p = vp * glm::vec4(c + d, 1.f);
        const bool inside = p.w > 0.f && std::abs(p.x) <= p.w && std::abs(p.y) <= p.w;
        EXPECT_FALSE(inside) << "face " << f << " culls a sphere it sees, point " << k;
      }
    }
  }
  EXPECT_GT(culled, 2000 * 3);  // most spheres are in one or two of the six faces
  // On an axis a small sphere is in that face alone; on a face diagonal in both faces.
  for (int f = 0; f < 6; ++f) {
    glm::vec3 a(0.f);
    a[f / 2] = f % 2 == 0 ? 1.f : -1.f;
    for (int g = 0; g < 6; ++g) EXPECT_EQ(sphereInCubeFace(o, g, o + 2.f * a, 0.1f), g == f) << f << " " << g;
  }
  EXPECT_TRUE(sphereInCubeFace(o, 0, o + glm::vec3(1, 1, 0), 0.01f));
  EXPECT_TRUE(sphereInCubeFace(o, 2, o + glm::vec3(1, 1, 0), 0.01f));
}

}  // namespace
}  // namespace radiant::env_diffuse
