// The reference light tracer against closed forms (a mirror's image of a light, a glass slab's
// Fresnel transmission and shadow shift), against the path tracer where both can see the light, and
// the caustics partition: path tracer without caustics + light-traced caustics = the whole image.
#include <gtest/gtest.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <vector>

#include "renderer/raytracing/CameraRays.h"
#include "renderer/raytracing/RayScene.h"
#include "renderer/reference/LightTracer.h"
#include "renderer/reference/PathTracer.h"
#include "tests/unit/reference/TestScenes.h"

namespace radiant::reference {
namespace {

using namespace radiant::rt;
using testing::addMaterial;
using testing::lambert;

Material mirrorMaterial() {
  Material m;
  m.baseColorFactor = glm::vec4(1.f);  // Schlick with f0 = 1: F = 1 at every angle
  m.metallicFactor = 1.f;
  m.roughnessFactor = 0.f;
  return m;
}

double mean(const Image& img, int x0, int y0, int x1, int y1) {
  double s = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) s += img.at(x, y)[0];
  return s / ((x1 - x0) * (y1 - y0));
}

// Point and area light on diffuse surfaces, no deltas: both estimators of the same image (every
// path with k >= 1) must agree in every 8x8 block, for a perspective camera.
TEST(LightTracer, AgreesWithThePathTracerWithoutDeltas) {
  Scene s;
  s.meshes.push_back(testing::square({0, 0, 0}, {0, 1, 0}, 1.f, addMaterial(s, lambert(glm::vec3(0.5f)))));
  s.meshes.push_back(testing::square({0, 1, -1}, {0, 0, 1}, 1.f, addMaterial(s, lambert(glm::vec3(0.7f)))));
  s.meshes.push_back(testing::square({-0.6f, 1.2f, 0.f}, {1, -1, 0}, 0.15f, addMaterial(s, testing::emitter(glm::vec3(4.f)))));
  Light l;
  l.type = LightType::Point;
  l.intensity = 1.f;
  l.position = {0.3f, 0.8f, 0.2f};
  s.lights.push_back(l);
  const Camera cam = testing::lookAtCamera({0, 0.9f, 2.6f}, {0, 0.4f, 0}, {0, 1, 0}, false, 0.8f);
  const RayScene rays(s);
  ReferenceOptions po;
  po.spp = 256;
  po.minPathBounce = 1;
  const Image pt = PathTracer(rays).render(cam, 32, 32, po);
  LightTracerOptions lo;
  lo.paths = LightTracerOptions::Paths::All;
  lo.pathsPerPixel = 256;
  const Image lt = LightTracer(rays).render(cam, 32, 32, lo);
  for (int by = 0; by < 4; ++by)
    for (int bx = 0; bx < 4; ++bx) {
      const double a = mean(pt, bx * 8, by * 8, bx * 8 + 8, by * 8 + 8);
      const double b = mean(lt, bx * 8, by * 8, bx * 8 + 8, by * 8 + 8);
      // Both are ~1% noisy per block here; a wrong pixel measure or importance is off by tens of %.
      EXPECT_NEAR(b, a, 0.04 * a + 1e-3) << "block " << bx << "," << by;
    }
  EXPECT_NEAR(mean(lt, 0, 0, 32, 32), mean(pt, 0, 0, 32, 32), 0.015 * mean(pt, 0, 0, 32, 32));
}

// A spot light at height 1 over a flat mirror (F = 1) lights a ceiling at height 2 as its mirror image
// L' = (0, -1, 0) would: E = F I cos(theta) / |x - L'|^2 inside the reflected footprint of the mirror
// (|x|, |z| <= 1.5) and 0 outside. Seen by an orthographic camera from below, the Lambertian ceiling's
// radiance is albedo / pi E.
TEST(LightTracer, MirrorCausticIsTheImageOfTheLight) {
  Scene s;
  s.meshes.push_back(testing::square({0, 0, 0}, {0, 1, 0}, 0.5f, addMaterial(s, mirrorMaterial())));
  const float albedo = 0.5f;
  s.meshes.push_back(testing::square({0, 2, 0}, {0, -1, 0}, 2.f, addMaterial(s, lambert(glm::vec3(albedo)))));
  Light l;
  l.type = LightType::Spot;
  l.intensity = 2.f;
  l.position = {0, 1, 0};
  l.direction = {0, -1, 0};
  l.outerConeAngle = 0.70f;  // 40 degrees: the mirror's corners are at 35.3 degrees, inside the flat part
  l.innerConeAngle = 0.69f;
  s.lights.push_back(l);
  const Camera cam = testing::lookAtCamera({0, 1.5f, 0}, {0, 2, 0}, {0, 0, -1}, true, 2.f);
  const RayScene rays(s);
  LightTracerOptions o;
  o.pathsPerPixel = 192;
  const int n = 32;  // 0.125 units per pixel: the footprint's edges at +-1.5 lie on pixel edges
  const Image img = LightTracer(rays).render(cam, n, n, o);
  const CameraRays camRays(cam, n, n);
  double inner = 0, innerExpected = 0, outer = 0, outerExpected = 0;
  int innerCount = 0, outerCount = 0, outside = 0;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const Ray r = camRays.ray(x + 0.5f, y + 0.5f);
      const glm::vec3 p = r.org + r.dir * ((2.f - r.org.y) / r.dir.y);  // on the ceiling
      const float m = std::max(std::abs(p.x), std::abs(p.z));
      const double v = img.at(x, y)[0];
      if (m > 1.5f) {
        EXPECT_EQ(v, 0.0) << "outside the footprint at " << p.x << "," << p.z;
        ++outside;
        continue;
      }
      if (m > 1.45f) continue;  // no edge pixels here anyway; keep the classification honest
      const double d2 = p.x * p.x + p.z * p.z + 9.0, cosTheta = 3.0 / std::sqrt(d2);
      const double L = albedo / M_PI * l.intensity * cosTheta / d2;
      if (m < 0.5f) inner += v, innerExpected += L, ++innerCount;
      if (m > 1.0f) outer += v, outerExpected += L, ++outerCount;
    }
  EXPECT_EQ(outside, n * n - 24 * 24);
  ASSERT_GT(innerCount, 0);
  ASSERT_GT(outerCount, 0);
  // ~60 particles per pixel: 1% on 64 pixels, 0.5% on 320. The falloff between them is 31%.
  EXPECT_NEAR(inner / innerExpected, 1.0, 0.03);
  EXPECT_NEAR(outer / outerExpected, 1.0, 0.02);
}

// A glass slab (n = 1.5, thickness t) at height h over a white floor under a directional light of
// illuminance E: through its two faces, the floor receives E cos(theta) (1 - F(theta))^2 (the same F at
// both faces by Stokes reciprocity; maxBounces 3 keeps exactly the two refractions), 0.9216 E at
// normal incidence. The caustic's edge on the side the light comes from sits where the ray through the
// top corner lands, -a + t tan(theta_t) + h tan(theta): shifted by t (tan theta - tan theta_t) from the
// unrefracted shadow edge.
TEST(LightTracer, GlassSlabTransmitsFresnelSquaredAndShiftsItsShadowEdge) {
  const float a = 0.5f, t = 0.6f, h = 2.f, albedo = 0.8f;
  Scene s;
  s.meshes.push_back(testing::square({0.5f, 0, 0}, {0, 1, 0}, 2.f, addMaterial(s, lambert(glm::vec3(albedo)))));
  s.meshes.push_back(testing::box({-a, h, -1.2f}, {a, h + t, 1.2f}, addMaterial(s, testing::smoothGlass(1.5f))));
  // Seen from up-left at 45 degrees, so lines of sight to the floor at x < 1.4 pass left of the slab.
  const Camera cam = testing::lookAtCamera(glm::vec3(0.5f, 0, 0) + 4.f * glm::normalize(glm::vec3(-1, 1, 0)),
                                           {0.5f, 0, 0}, {0, 0, 1}, true, 1.f);
  const int w = 64, hgt = 32;
  const CameraRays camRays(cam, w, hgt);
  for (double theta : {0.0, M_PI / 6}) {
    SCOPED_TRACE(theta);
    Light l;
    l.type = LightType::Directional;
    l.intensity = 1.f;
    l.direction = glm::vec3(float(std::sin(theta)), float(-std::cos(theta)), 0.f);
    Scene lit = s;
    lit.lights.push_back(l);
    const RayScene rays(lit);
    LightTracerOptions o;
    o.pathsPerPixel = 512;
    o.maxBounces = 3;
    const Image img = LightTracer(rays).render(cam, w, hgt, o);
    const double F = testing::fresnelUnpolarised(std::cos(theta), 1.0, 1.5);
    const double sinT = std::sin(theta) / 1.5, tanT = sinT / std::sqrt(1 - sinT * sinT);
    const double edge = -a + t * tanT + h * std::tan(theta);
    const double expected = albedo / M_PI * std::cos(theta) * (1 - F) * (1 - F);
    // Column profile along x on the floor: mean over the rows with |z| < 0.6.
    std::vector<double> value(w, 0.0), xs(w, 0.0);
    std::vector<int> count(w, 0);
    for (int y = 0; y < hgt; ++y)
      for (int x = 0; x < w; ++x) {
        const Ray r = camRays.ray(x + 0.5f, y + 0.5f);
        const glm::vec3 p = r.org + r.dir * (-r.org.y / r.dir.y);
        if (std::abs(p.z) >= 0.6f) continue;
        value[x] += img.at(x, y)[0];
        xs[x] += p.x;
        ++count[x];
      }
    double interior = 0;
    int interiorColumns = 0, zeroColumns = 0;
    double crossing = 0;
    bool found = false;
    for (int x = 0; x < w; ++x) {
      if (!count[x]) continue;
      value[x] /= count[x];
      xs[x] /= count[x];
    }
    const double lo = theta == 0 ? -0.4 : edge + 0.08, hi = theta == 0 ? 0.4 : 1.3;
    for (int x = 0; x < w; ++x) {
      if (!count[x]) continue;
      if (xs[x] > lo && xs[x] < hi) interior += value[x], ++interiorColumns;
      if (theta > 0 && xs[x] > -a + 0.1 && xs[x] < edge - 0.08) {
        EXPECT_EQ(value[x], 0.0) << "left of the caustic at x = " << xs[x];
        ++zeroColumns;
      }
    }
    ASSERT_GT(interiorColumns, 3);
    interior /= interiorColumns;
    EXPECT_NEAR(interior / expected, 1.0, 0.02) << "expected " << expected;
    if (theta == 0) {
      EXPECT_NEAR(std::cos(theta) * (1 - F) * (1 - F), 0.9216, 1e-4);
      continue;
    }
    EXPECT_GT(zeroColumns, 5);
    // Where the profile crosses half the interior value, by linear interpolation between columns
    // taken in order of increasing x (the image's columns run towards -x).
    std::vector<std::pair<double, double>> profile;
    for (int x = 0; x < w; ++x)
      if (count[x] && xs[x] > -a) profile.push_back({xs[x], value[x]});
    std::sort(profile.begin(), profile.end());
    for (std::size_t i = 1; i < profile.size() && !found; ++i) {
      const auto [x0, v0] = profile[i - 1];
      const auto [x1, v1] = profile[i];
      if (v0 < 0.5 * interior && v1 >= 0.5 * interior) {
        crossing = x0 + (0.5 * interior - v0) / (v1 - v0) * (x1 - x0);
        found = true;
      }
    }
    ASSERT_TRUE(found);
    const double unrefracted = -a + (t + h) * std::tan(theta);
    EXPECT_NEAR(crossing, edge, 0.035) << "unrefracted edge at " << unrefracted;
    EXPECT_GT(unrefracted - edge, 0.13);  // the shift t (tan theta - tan theta_t) is 2 columns wide
  }
}

// An area light over a floor with a tilted mirror: the path tracer finds the caustic by hitting the
// emitter after the mirror. Its caustic part (all paths minus excludeCaustics, with the same random
// numbers, so it is exactly its caustic estimate) must equal the light tracer's caustics, and both
// images together hold every path once.
TEST(LightTracer, CausticsPartitionThePathTracersImage) {
  Scene s;
  s.meshes.push_back(testing::square({0, 0, 0}, {0, 1, 0}, 1.5f, addMaterial(s, lambert(glm::vec3(0.6f)))));
  s.meshes.push_back(testing::square({0.8f, 0.6f, 0.f}, {-1, 0.3f, 0}, 0.4f, addMaterial(s, mirrorMaterial())));
  s.meshes.push_back(testing::square({-0.2f, 1.6f, 0.f}, {0.2f, -1, 0}, 0.3f, addMaterial(s, testing::emitter(glm::vec3(5.f)))));
  const Camera cam = testing::lookAtCamera({-0.5f, 2.2f, 2.2f}, {0.2f, 0.2f, 0}, {0, 1, 0}, false, 0.9f);
  const RayScene rays(s);
  ReferenceOptions po;
  po.spp = 512;
  const PathTracer pt(rays);
  const Image all = pt.render(cam, 16, 16, po);
  po.excludeCaustics = true;
  const Image rest = pt.render(cam, 16, 16, po);
  LightTracerOptions lo;
  lo.pathsPerPixel = 2048;
  const Image caustics = LightTracer(rays).render(cam, 16, 16, lo);
  double ptCaustics = 0, lt = 0, total = 0;
  for (std::size_t i = 0; i < all.pixels.size(); i += 3) {
    EXPECT_GE(all.pixels[i], rest.pixels[i] - 1e-6f);  // the same paths, some of them dropped
    ptCaustics += all.pixels[i] - rest.pixels[i];
    lt += caustics.pixels[i];
    total += all.pixels[i];
  }
  ASSERT_GT(ptCaustics, 0.02 * total);  // the caustic is a visible part of the image
  EXPECT_NEAR(lt / ptCaustics, 1.0, 0.05);
}

TEST(LightTracer, BitwiseIdenticalForOneAndTwoThreads) {
  Scene s;
  s.meshes.push_back(testing::square({0, 0, 0}, {0, 1, 0}, 1.f, addMaterial(s, lambert(glm::vec3(0.5f)))));
  s.meshes.push_back(testing::square({0, 0.5f, 0}, {0, 1, 0}, 0.3f, addMaterial(s, testing::smoothGlass(1.5f))));
  Light l;
  l.position = {0, 1.5f, 0};
  s.lights.push_back(l);
  const Camera cam = testing::lookAtCamera({0, 2, 2}, {0, 0, 0}, {0, 1, 0}, false, 0.9f);
  const RayScene rays(s);
  LightTracerOptions o;
  o.pathsPerPixel = 8;
  o.threads = 1;
  const Image a = LightTracer(rays).render(cam, 24, 16, o);
  o.threads = 2;
  const Image b = LightTracer(rays).render(cam, 24, 16, o);
  ASSERT_EQ(a.pixels.size(), b.pixels.size());
  EXPECT_EQ(a.pixels, b.pixels);
  double sum = 0;
  for (float v : a.pixels) {
    ASSERT_TRUE(std::isfinite(v));
    sum += v;
  }
  EXPECT_GT(sum, 0.0);  // the glass square focuses some light: the caustic exists
  EXPECT_TRUE(sceneHasDeltaLobes(s));
}

TEST(LightTracer, RejectsBadArguments) {
  Scene s;
  s.meshes.push_back(testing::square({0, 0, 0}, {0, 1, 0}, 1.f, addMaterial(s, lambert(glm::vec3(0.5f)))));
  const RayScene rays(s);
  const LightTracer lt(rays);
  const Camera cam = testing::lookAtCamera({0, 1, 1}, {0, 0, 0}, {0, 1, 0}, false, 0.9f);
  LightTracerOptions o;
  EXPECT_THROW(lt.render(cam, 0, 4, o), std::invalid_argument);
  o.pathsPerPixel = 0;
  EXPECT_THROW(lt.render(cam, 4, 4, o), std::invalid_argument);
  o.pathsPerPixel = 1;
  // No emitter: a black image, not an error.
  const Image img = lt.render(cam, 4, 4, o);
  for (float v : img.pixels) EXPECT_EQ(v, 0.f);
  EXPECT_FALSE(sceneHasDeltaLobes(s));
}

}  // namespace
}  // namespace radiant::reference
