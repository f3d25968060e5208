// The reference path tracer against numbers fixed by physics: furnaces, light calibration, Fresnel,
// convergence rate, determinism, ambient occlusion closed forms. Every scene is built in code.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "renderer/reference/PathTracer.h"
#include "tests/unit/reference/TestScenes.h"

namespace radiant::reference {
namespace {

using namespace radiant::rt;  // the BSDF and its constants

using testing::addMaterial;
using testing::lambert;
using testing::meanPixel;
using testing::pinpointCamera;

Image render(const Scene& s, const Camera& c, int w, int h, const ReferenceOptions& o) {
  PathTracer pt(s);
  return pt.render(c, w, h, o);
}

float renderPoint(const Scene& s, glm::vec3 target, glm::vec3 towardsEye, const ReferenceOptions& o,
                  float distance = 0.5f) {
  return render(s, pinpointCamera(target, towardsEye, distance), 1, 1, o).pixels[0];
}

using testing::fresnelUnpolarised;
using testing::bsdfOf;

// E(mu) tabulated by quadrature on [mu0, 1] and interpolated.
struct AlbedoTable {
  double mu0;
  std::vector<double> e;
  AlbedoTable(const GltfBsdf& b, double mu0_, int n = 17) : mu0(mu0_) {
    for (int i = 0; i < n; ++i) e.push_back(testing::directionalAlbedo(b, float(mu0 + (1 - mu0) * i / (n - 1))).x);
  }
  double operator()(double mu) const {
    const double t = std::clamp((mu - mu0) / (1 - mu0), 0.0, 1.0) * (e.size() - 1);
    const size_t i = std::min<size_t>(size_t(t), e.size() - 2);
    return e[i] + (t - i) * (e[i + 1] - e[i]);
  }
};

// A unit sphere in a uniform white sky seen by an orthographic camera: each facet sees only sky, so
// the radiance at a pixel is the directional albedo E(n.v) -- 0.5 x (Lambert) for albedo 0.5.
struct SphereFurnace {
  double rendered = 0, expected = 0, maxPixel = 0;
  double rmsDeviation = 0;  // per-pixel rms of (rendered - expected): the pixel noise
};
SphereFurnace sphereFurnace(const Material& m, int spp, float scale = 1.f) {
  Scene s;
  s.meshes.push_back(testing::sphere(glm::vec3(0.f), scale, 48, 96, addMaterial(s, m)));
  const int n = 32;
  const float half = 1.05f;
  Camera cam = testing::lookAtCamera({0, 0, 3 * scale}, {0, 0, 0}, {0, 1, 0}, true, half * scale);
  ReferenceOptions o;
  o.spp = spp;
  o.skyRadiance = glm::vec3(1.f);
  const Image img = render(s, cam, n, n, o);
  const AlbedoTable table(bsdfOf(m), 0.45);
  SphereFurnace r;
  int count = 0;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const double px = (2.0 * (x + 0.5) / n - 1) * half, py = (2.0 * (y + 0.5) / n - 1) * half;
      const double rho = std::sqrt(px * px + py * py);
      if (rho > 0.85) continue;  // keep away from the silhouette (partly sky-covered pixels)
      r.rendered += img.at(x, y)[0];
      r.expected += table(std::sqrt(1 - rho * rho));
      r.maxPixel = std::max<double>(r.maxPixel, img.at(x, y)[0]);
      r.rmsDeviation += std::pow(img.at(x, y)[0] - table(std::sqrt(1 - rho * rho)), 2);
      ++count;
    }
  r.rmsDeviation = std::sqrt(r.rmsDeviation / count);
  r.rendered /= count;
  r.expected /= count;
  return r;
}

TEST(PathTracer, FurnaceLambertSphere) {
  const SphereFurnace f = sphereFurnace(lambert(glm::vec3(0.5f)), 64);
  // The glTF dielectric with ior 1 is Lambert up to Schlick's (1 - v.h)^5 layer; the quadrature of the
  // full BRDF gives the exact expectation, and it is within 2% of the Lambertian 0.5.
  EXPECT_NEAR(f.expected, 0.5, 0.01);
  EXPECT_NEAR(f.rendered, f.expected, 0.01 * f.expected);
  EXPECT_NEAR(f.rendered, 0.5, 0.02 * 0.5);
}

TEST(PathTracer, FurnaceGgxMetalSphereMatchesDirectionalAlbedo) {
  for (float roughness : {0.3f, 0.6f, 1.f}) {
    Material m;
    m.baseColorFactor = glm::vec4(1.f);
    m.metallicFactor = 1.f;
    m.roughnessFactor = roughness;
    const SphereFurnace f = sphereFurnace(m, 64);
    EXPECT_NEAR(f.rendered, f.expected, 0.02 * f.expected) << roughness;
    EXPECT_LE(f.expected, 1.0);
    // A white single-scattering metal loses energy: no pixel above 1 beyond its noise (the max of
    // ~560 pixels is ~3 sigma; allow 5 sigma, sigma measured as the rms deviation from quadrature).
    EXPECT_LE(f.maxPixel, 1.0 + 5.0 * f.rmsDeviation) << roughness << " sigma " << f.rmsDeviation;
    EXPECT_LT(f.rmsDeviation, 0.05) << roughness;
  }
}

TEST(PathTracer, FurnaceGlassSphereConservesEnergy) {
  // A closed sphere of clear glass in a white furnace: smooth glass neither absorbs nor emits, so
  // every path leaves with weight exactly 1 (the n^2 radiance gain on entering is undone on leaving):
  // the image is 1 everywhere up to Russian roulette noise. Rough glass (single-scattering microfacets)
  // can only lose energy, and little of it.
  for (float roughness : {0.f, 0.3f}) {
    Material glass;
    glass.baseColorFactor = glm::vec4(1.f);
    glass.metallicFactor = 0.f;
    glass.roughnessFactor = roughness;
    glass.transmissionFactor = 1.f;
    glass.ior = 1.5f;
    Scene s;
    s.meshes.push_back(testing::sphere(glm::vec3(0.f), 1.f, 24, 48, addMaterial(s, glass)));
    ReferenceOptions o;
    o.spp = 64;
    o.maxBounces = 64;
    o.skyRadiance = glm::vec3(1.f);
    const Image img = render(s, testing::lookAtCamera({0, 0, 3}, {0, 0, 0}, {0, 1, 0}, true, 0.7f), 16, 16, o);
    const double mean = meanPixel(img).x;
    if (roughness == 0.f) {
      EXPECT_NEAR(mean, 1.0, 0.01);
    } else {
      EXPECT_LT(mean, 1.01);
      EXPECT_GT(mean, 0.9);
    }
  }
}

// A huge plane under uniform sky, seen at one angle: exactly the directional albedo.
TEST(PathTracer, FurnacePlaneAtFixedAnglesMatchesQuadrature) {
  for (float roughness : {0.3f, 0.6f, 1.f})
    for (float metallic : {0.f, 1.f})
      for (float cosV : {1.f, 0.5f}) {
        Material m;
        m.baseColorFactor = glm::vec4(metallic == 1.f ? 1.f : 0.5f);
        m.metallicFactor = metallic;
        m.roughnessFactor = roughness;
        Scene s;
        s.meshes.push_back(testing::square({0, 0, 0}, {0, 1, 0}, 100.f, addMaterial(s, m)));
        ReferenceOptions o;
        o.spp = 4096;
        o.skyRadiance = glm::vec3(1.f);
        const glm::vec3 eye(std::sqrt(1 - cosV * cosV), cosV, 0.f);
        const float L = renderPoint(s, {0, 0, 0}, eye, o);
        const double e = testing::directionalAlbedo(bsdfOf(m), cosV).x;
        EXPECT_NEAR(L, e, 0.02 * e) << "roughness " << roughness << " metallic " << metallic << " cos " << cosV;
      }
}

Scene lightOverPlane(const Light& light) {
  Scene s;
  s.meshes.push_back(testing::square({0, 0, 0}, {0, 1, 0}, 100.f, addMaterial(s, lambert(glm::vec3(1.f)))));
  s.lights.push_back(light);
  return s;
}

TEST(PathTracer, PointLightCalibrationAndInverseSquareCosineFalloff) {
  Light l;
  l.type = LightType::Point;
  l.intensity = kPi;  // I = pi W/sr at height 1: E = pi, L = E / pi = 1 at the foot
  l.position = {0, 1, 0};
  const Scene s = lightOverPlane(l);
  ReferenceOptions o;
  o.spp = 4;
  o.maxPathBounce = 1;  // direct only
  EXPECT_NEAR(renderPoint(s, {0, 0, 0}, {0, 1, 0}, o), 1.0, 0.01);
  // L(x) = I cos(theta) / (pi d^2) = cos^3(theta) / h^2 with cos = h / d: (1 + x^2)^-3/2.
  for (float x : {0.5f, 1.f, 2.f}) {
    const double expected = std::pow(1.0 + x * x, -1.5);
    EXPECT_NEAR(renderPoint(s, {x, 0, 0}, {0, 1, 0}, o), expected, 0.02 * expected) << x;
  }
  // A lone plane has no indirect light.
  o.minPathBounce = 2;
  o.maxPathBounce = INT_MAX;
  EXPECT_EQ(renderPoint(s, {0, 0, 0}, {0, 1, 0}, o), 0.f);
}

TEST(PathTracer, SpotRangeAndDirectionalLightsFollowKhrLightsPunctual) {
  ReferenceOptions o;
  o.spp = 4;
  {
    Light l;
    l.type = LightType::Spot;
    l.intensity = kPi;
    l.position = {0, 1, 0};
    l.direction = {0, -1, 0};
    l.innerConeAngle = 0.2f;
    l.outerConeAngle = 0.4f;
    const Scene s = lightOverPlane(l);
    EXPECT_NEAR(renderPoint(s, {0, 0, 0}, {0, 1, 0}, o), 1.0, 0.01);
    // Between the cones: t = (cos 0.3 - cos 0.4) / (cos 0.2 - cos 0.4), attenuation t^2.
    const double t = (std::cos(0.3) - std::cos(0.4)) / (std::cos(0.2) - std::cos(0.4));
    const double expected = std::pow(std::cos(0.3), 3) * t * t;
    EXPECT_NEAR(renderPoint(s, {std::tan(0.3f), 0, 0}, {0, 1, 0}, o), expected, 0.02 * expected);
    EXPECT_EQ(renderPoint(s, {std::tan(0.5f), 0, 0}, {0, 1, 0}, o), 0.f);  // outside the outer cone
  }
  {
    Light l;
    l.type = LightType::Point;
    l.intensity = kPi;
    l.position = {0, 1, 0};
    l.range = 2.f;  // window clamp(1 - (d / range)^4, 0, 1) = 1 - 1/16 at d = 1
    const Scene s = lightOverPlane(l);
    EXPECT_NEAR(renderPoint(s, {0, 0, 0}, {0, 1, 0}, o), 0.9375, 0.01 * 0.9375);
    EXPECT_EQ(renderPoint(s, {2, 0, 0}, {0, 1, 0}, o), 0.f);  // d = sqrt(5) > range
  }
  {
    Light l;
    l.type = LightType::Directional;
    l.intensity = 2.f;  // lux: irradiance on a plane facing the light
    l.direction = glm::vec3(std::sin(kPi / 6), -std::cos(kPi / 6), 0.f);
    const Scene s = lightOverPlane(l);
    const double expected = 2.0 * std::cos(kPi / 6) / kPi;
    EXPECT_NEAR(renderPoint(s, {0, 0, 0}, {0, 1, 0}, o), expected, 0.01 * expected);
  }
}

TEST(PathTracer, EmissiveAreaLightWithMisMatchesFurnace) {
  // A plane under a huge single-sided emitter of radiance 1 sees radiance 1 over (almost) its whole
  // hemisphere: the same as the sky furnace, E(mu) -- here through triangle-light NEE + BSDF MIS.
  const Material white = lambert(glm::vec3(0.8f));
  Scene s;
  s.meshes.push_back(testing::square({0, 0, 0}, {0, 1, 0}, 1000.f, addMaterial(s, white)));
  s.meshes.push_back(testing::square({0, 1, 0}, {0, -1, 0}, 1000.f, addMaterial(s, testing::emitter(glm::vec3(1.f)))));
  ReferenceOptions o;
  o.spp = 8192;
  o.maxPathBounce = 1;
  const double e = testing::directionalAlbedo(bsdfOf(white), 1.f).x;
  EXPECT_NEAR(renderPoint(s, {0, 0, 0}, {0, 1, 0}, o), e, 0.015 * e);
  // The emitter seen directly (k = 0) is its emission; its back face is dark.
  o.maxPathBounce = 0;
  EXPECT_EQ(renderPoint(s, {0, 1, 0}, {0, -1, 0}, o), 1.f);
  EXPECT_EQ(renderPoint(s, {0, 1, 0}, {0, 1, 0}, o), 0.f);
}

TEST(PathTracer, EnvironmentMapImportanceSamplingMatchesFurnace) {
  const Material grey = lambert(glm::vec3(0.5f));
  Scene s;
  s.meshes.push_back(testing::square({0, 0, 0}, {0, 1, 0}, 100.f, addMaterial(s, grey)));
  const double e = testing::directionalAlbedo(bsdfOf(grey), 1.f).x;
  // Upper half of the equirect map (v < 1/2 <=> dir.y > 0) is 1, with a bright band; lower half 0.
  Image env = Image::make("env", 16, 8, 3);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 16; ++x)
      for (int c = 0; c < 3; ++c) env.at(x, y)[c] = 1.f;
  ReferenceOptions o;
  o.spp = 4096;
  o.environment = &env;
  EXPECT_NEAR(renderPoint(s, {0, 0, 0}, {0, 1, 0}, o), e, 0.015 * e);
  // A texel 20x brighter than the rest: the plane sees L = (E weighted) -- check against quadrature of
  // the Lambertian part, which is exact for ior = 1 at normal view up to (1 - v.h)^5 terms.
  for (int c = 0; c < 3; ++c) env.at(5, 1)[c] = 21.f;
  const double thetaLo = kPi * 1 / 8.0, thetaHi = kPi * 2 / 8.0;
  // Extra irradiance from that texel: 20 * \int cos dw over it = 20 * (2 pi / 16) * (sin^2 hi - sin^2 lo) / 2.
  const double extraE = 20.0 * (2 * kPi / 16) * 0.5 * (std::pow(std::sin(thetaHi), 2) - std::pow(std::sin(thetaLo), 2));
  const double expected = e + 0.5 / kPi * extraE;  // albedo 0.5 Lambert for the extra (small angles)
  EXPECT_NEAR(renderPoint(s, {0, 0, 0}, {0, 1, 0}, o), expected, 0.02 * expected);
}

TEST(PathTracer, SmoothMirrorReflectsEmitterAtSchlickReflectance) {
  Material mirror;
  mirror.baseColorFactor = glm::vec4(0.5f, 0.5f, 0.5f, 1.f);
  mirror.metallicFactor = 1.f;
  mirror.roughnessFactor = 0.f;
  Scene s;
  s.meshes.push_back(testing::square({0, 0, 0}, {0, 1, 0}, 100.f, addMaterial(s, mirror)));
  s.meshes.push_back(testing::square({0, 2, 0}, {0, -1, 0}, 1000.f, addMaterial(s, testing::emitter(glm::vec3(1.f)))));
  ReferenceOptions o;
  o.spp = 16;
  for (float theta : {0.f, 1.f, 1.3f}) {
    const double F = 0.5 + 0.5 * std::pow(1 - std::cos(theta), 5);  // Schlick with f0 = baseColor
    EXPECT_NEAR(renderPoint(s, {0, 0, 0}, {std::sin(theta), std::cos(theta), 0}, o), F, 0.005 * F) << theta;
  }
}

TEST(PathTracer, DielectricSlabTransmittanceMatchesFresnelSeries) {
  // A glass slab (n = 1.5) between the camera and an emitter of radiance 1. Each interface reflects R
  // (the same R inside and out, by Stokes reciprocity), so light reaching the emitter after 2j internal
  // reflections carries (1 - R)^2 R^(2j):  T = (1 - R)^2 / (1 - R^2) = (1 - R) / (1 + R).
  // The renderer is unpolarised, so R is the unpolarised (Rs + Rp) / 2 of each interface.
  // The n^2 radiance change on entering cancels on leaving.
  const Material glass = testing::smoothGlass(1.5f);
  Scene s;
  s.meshes.push_back(testing::box({-50, 0, -50}, {50, 0.2f, 50}, addMaterial(s, glass)));
  s.meshes.push_back(testing::square({0, -1, 0}, {0, 1, 0}, 1000.f, addMaterial(s, testing::emitter(glm::vec3(1.f)))));
  ReferenceOptions o;
  o.spp = 20000;
  o.maxBounces = 64;
  for (double theta : {0.0, M_PI / 4}) {
    const double R = fresnelUnpolarised(std::cos(theta), 1.0, 1.5);
    const double T = (1 - R) / (1 + R);  // 0.923 at normal incidence
    const float L = renderPoint(s, {0, 0.2f, 0}, {float(std::sin(theta)), float(std::cos(theta)), 0}, o);
    EXPECT_NEAR(L, T, 0.01 * T) << theta;
  }
}

// KHR_materials_volume: the same slab bounding an absorbing medium. One crossing at angle theta_t
// inside travels d / cos(theta_t), so it transmits a = c^(d / (d0 cos theta_t)) (Beer-Lambert with
// sigma_t = -ln(c) / d0); the series becomes T = (1 - R)^2 a / (1 - R^2 a^2). Against the clear slab
// the ratio is a (1 - R^2) / (1 - R^2 a^2): c^(d/d0) within R^2 = 0.16% at normal incidence.
TEST(PathTracer, AbsorbingSlabTransmitsBeerLambertInsideTheFresnelSeries) {
  const float d = 0.2f, d0 = 0.1f;
  const glm::vec3 c(0.5f, 0.8f, 1.f);
  Scene s;
  s.meshes.push_back(testing::box({-50, 0, -50}, {50, d, 50}, addMaterial(s, testing::absorbingGlass(1.5f, c, d0))));
  s.meshes.push_back(testing::square({0, -1, 0}, {0, 1, 0}, 1000.f, addMaterial(s, testing::emitter(glm::vec3(1.f)))));
  Scene clear = s;
  clear.materials[0].thicknessFactor = 0.f;  // the spec's thin-wall default: no medium
  ReferenceOptions o;
  o.spp = 20000;
  o.maxBounces = 64;
  for (double theta : {0.0, M_PI / 4}) {
    const double R = fresnelUnpolarised(std::cos(theta), 1.0, 1.5);
    const double cosT = std::sqrt(1 - std::pow(std::sin(theta) / 1.5, 2));
    const Camera cam = pinpointCamera({0, d, 0}, {float(std::sin(theta)), float(std::cos(theta)), 0}, 0.5f);
    const Image vol = render(s, cam, 1, 1, o), ref = render(clear, cam, 1, 1, o);
    for (int k = 0; k < 3; ++k) {
      const double a = std::pow(double(c[k]), d / (d0 * cosT));
      const double T = (1 - R) * (1 - R) * a / (1 - R * R * a * a);
      // 1%: the Fresnel branching's noise at 20000 samples, as the clear slab's test.
      EXPECT_NEAR(vol.pixels[k], T, 0.01 * T) << "theta " << theta << " channel " << k;
      const double ratio = double(vol.pixels[k]) / ref.pixels[k];
      EXPECT_NEAR(ratio, a * (1 - R * R) / (1 - R * R * a * a), 0.015 * a) << "theta " << theta << " channel " << k;
      if (theta == 0.0) {
        EXPECT_NEAR(ratio, std::pow(double(c[k]), d / d0), 0.02 * std::pow(double(c[k]), d / d0));
      }
    }
  }
}

// Extremes stay finite: an infinite or huge distance or a white colour is the clear slab, a black colour
// or a vanishing distance is opaque (exactly 0, never NaN).
TEST(PathTracer, VolumeExtremesAreClearOrOpaqueAndFinite) {
  Scene s;
  s.meshes.push_back(testing::box({-50, 0, -50}, {50, 0.2f, 50}, addMaterial(s, testing::smoothGlass(1.5f))));
  s.meshes.push_back(testing::square({0, -1, 0}, {0, 1, 0}, 1000.f, addMaterial(s, testing::emitter(glm::vec3(1.f)))));
  ReferenceOptions o;
  o.spp = 4000;
  o.maxBounces = 64;
  const Camera cam = pinpointCamera({0, 0.2f, 0}, {0, 1, 0}, 0.5f);
  const Image clear = render(s, cam, 1, 1, o);
  struct Case { glm::vec3 color; float distance; bool opaque; };
  for (const Case& k : {Case{glm::vec3(0.5f), 1e30f, false}, Case{glm::vec3(0.5f), std::numeric_limits<float>::infinity(), false},
                        Case{glm::vec3(1.f), 1e-30f, false}, Case{glm::vec3(0.f), 1.f, true},
                        Case{glm::vec3(0.5f), 1e-30f, true}, Case{glm::vec3(0.f), std::numeric_limits<float>::min(), true}}) {
    Scene v = s;
    v.materials[0] = testing::absorbingGlass(1.5f, k.color, k.distance);
    const Image img = render(v, cam, 1, 1, o);
    for (int c = 0; c < 3; ++c) {
      ASSERT_TRUE(std::isfinite(img.pixels[c]));
      if (k.opaque) EXPECT_EQ(img.pixels[c], 0.f) << k.distance;
      else EXPECT_NEAR(img.pixels[c], clear.pixels[c], 1e-5f) << k.distance;  // same seeds, same paths
    }
  }
}

TEST(PathTracer, TotalInternalReflectionAtTheCriticalAngle) {
  // Camera inside glass (n = 1.5) looking up at the flat top face, an emitter of radiance 1 just above.
  // With one scattering event only, the camera sees the emitter through the interface:
  // L = n^2 (1 - R(theta)) below the critical angle asin(1/1.5) = 41.81 deg, and 0 above it (TIR).
  const Material glass = testing::smoothGlass(1.5f);
  Scene s;
  s.meshes.push_back(testing::box({-50, -50, -50}, {50, 0, 50}, addMaterial(s, glass)));
  s.meshes.push_back(testing::square({0, 0.001f, 0}, {0, -1, 0}, 1000.f, addMaterial(s, testing::emitter(glm::vec3(1.f)))));
  ReferenceOptions o;
  o.spp = 16384;
  o.maxBounces = 1;
  const double critical = std::asin(1 / 1.5);
  for (double deg : {30.0, 41.0, 42.5, 60.0}) {
    const double theta = deg * kPi / 180;
    const float L = renderPoint(s, {0, 0, 0}, {float(std::sin(theta)), float(-std::cos(theta)), 0}, o);
    if (theta < critical) {
      const double expected = 2.25 * (1 - fresnelUnpolarised(std::cos(theta), 1.5, 1.0));
      EXPECT_NEAR(L, expected, (deg > 40 ? 0.03 : 0.01) * expected) << deg;
    } else {
      EXPECT_EQ(L, 0.f) << deg;
    }
  }
}

// A small closed-ish scene with every light type for convergence, determinism and bounce ranges.
Scene cornerScene() {
  Scene s;
  const int floorM = addMaterial(s, lambert({0.7f, 0.7f, 0.7f}));
  Material red = lambert({0.7f, 0.2f, 0.2f});
  red.ior = 1.5f;
  red.roughnessFactor = 0.5f;
  const int redM = addMaterial(s, red);
  Material metal;
  metal.baseColorFactor = glm::vec4(0.9f, 0.8f, 0.6f, 1.f);
  metal.roughnessFactor = 0.4f;
  const int metalM = addMaterial(s, metal);
  s.meshes.push_back(testing::square({0, 0, 0}, {0, 1, 0}, 3.f, floorM));
  s.meshes.push_back(testing::square({0, 1.5f, -1.5f}, {0, 0, 1}, 1.5f, redM));
  s.meshes.push_back(testing::box({-0.6f, 0, -0.5f}, {0.1f, 0.8f, 0.2f}, metalM));
  s.meshes.push_back(testing::square({0.4f, 2.5f, 0}, {0, -1, 0}, 0.4f, addMaterial(s, testing::emitter(glm::vec3(6.f)))));
  Light l;
  l.type = LightType::Point;
  l.intensity = 2.f;
  l.position = {1.f, 1.5f, 1.f};
  s.lights.push_back(l);
  return s;
}
Camera cornerCamera() { return testing::lookAtCamera({0.5f, 1.5f, 3.5f}, {0, 0.5f, 0}, {0, 1, 0}, false, 0.9f); }

double rmse(const Image& a, const Image& b) {
  double s = 0;
  for (size_t i = 0; i < a.pixels.size(); ++i) s += double(a.pixels[i] - b.pixels[i]) * (a.pixels[i] - b.pixels[i]);
  return std::sqrt(s / a.pixels.size());
}

TEST(PathTracer, ErrorFallsAsOneOverSqrtSpp) {
  const Scene s = cornerScene();
  PathTracer pt(s);
  ReferenceOptions o;
  o.skyRadiance = glm::vec3(0.3f);
  o.maxBounces = 4;
  o.seed = 1000;
  o.spp = 2048;
  const Image reference = pt.render(cornerCamera(), 12, 12, o);
  std::vector<double> lx, ly;
  for (int spp : {4, 16, 64}) {
    double e = 0;
    // Average the squared error over a few seeds so the slope is not at the mercy of one draw.
    for (std::uint64_t seed = 0; seed < 3; ++seed) {
      o.spp = spp;
      o.seed = seed;
      e += std::pow(rmse(pt.render(cornerCamera(), 12, 12, o), reference), 2);
    }
    lx.push_back(std::log(double(spp)));
    ly.push_back(0.5 * std::log(e / 3));
  }
  const double mx = (lx[0] + lx[1] + lx[2]) / 3, my = (ly[0] + ly[1] + ly[2]) / 3;
  double sxy = 0, sxx = 0;
  for (int i = 0; i < 3; ++i) { sxy += (lx[i] - mx) * (ly[i] - my); sxx += (lx[i] - mx) * (lx[i] - mx); }
  const double slope = sxy / sxx;
  EXPECT_NEAR(slope, -0.5, 0.1);
}

TEST(PathTracer, BitwiseIdenticalForOneAndTwoThreads) {
  const Scene s = cornerScene();
  PathTracer pt(s);
  ReferenceOptions o;
  o.spp = 8;
  o.skyRadiance = glm::vec3(0.3f);
  o.threads = 1;
  const Image a = pt.render(cornerCamera(), 24, 20, o);
  const std::uint64_t raysA = pt.raysTraced();
  o.threads = 2;
  const Image b = pt.render(cornerCamera(), 24, 20, o);
  ASSERT_EQ(a.pixels.size(), b.pixels.size());
  EXPECT_EQ(0, std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(float)));
  EXPECT_EQ(raysA, pt.raysTraced());
  EXPECT_GT(raysA, std::uint64_t(24 * 20 * 8));
  for (float v : a.pixels) ASSERT_TRUE(std::isfinite(v) && v >= 0.f);
  o.seed = 1;
  const Image c = pt.render(cornerCamera(), 24, 20, o);
  EXPECT_NE(0, std::memcmp(a.pixels.data(), c.pixels.data(), a.pixels.size() * sizeof(float)));
}

TEST(PathTracer, BounceRangesPartitionTheImage) {
  const Scene s = cornerScene();
  PathTracer pt(s);
  ReferenceOptions o;
  o.spp = 256;
  o.skyRadiance = glm::vec3(0.3f);
  o.maxBounces = 6;
  const glm::dvec3 all = meanPixel(pt.render(cornerCamera(), 12, 12, o));
  o.maxPathBounce = 1;
  const glm::dvec3 direct = meanPixel(pt.render(cornerCamera(), 12, 12, o));
  o.minPathBounce = 2;
  o.maxPathBounce = INT_MAX;
  const glm::dvec3 indirect = meanPixel(pt.render(cornerCamera(), 12, 12, o));
  EXPECT_GT(indirect.x, 0.02 * all.x);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(direct[c] + indirect[c], all[c], 0.02 * all[c]) << c;
}

TEST(PathTracer, ScaleInvariantFrom1e3To1e4) {
  const double unit = sphereFurnace(lambert(glm::vec3(0.5f)), 16, 1.f).rendered;
  for (float scale : {1e-3f, 1e4f}) {
    EXPECT_NEAR(sphereFurnace(lambert(glm::vec3(0.5f)), 16, scale).rendered, unit, 0.005 * unit) << scale;
    Light l;
    l.intensity = kPi * scale * scale;  // keeps E = I / h^2 = pi at height `scale`
    l.position = {0, scale, 0};
    Scene s;
    s.meshes.push_back(testing::square({0, 0, 0}, {0, 1, 0}, 100.f * scale, addMaterial(s, lambert(glm::vec3(1.f)))));
    s.lights.push_back(l);
    ReferenceOptions o;
    o.spp = 4;
    const float L = render(s, pinpointCamera({0.3f * scale, 0, 0}, {0, 1, 0}, 0.5f * scale, 1e-4f * scale), 1, 1, o).pixels[0];
    EXPECT_NEAR(L, std::pow(1.0 + 0.09, -1.5), 0.01) << scale;
  }
}

// ---------------------------------------------------------------------------------------------------
// Ambient occlusion.
//
// Geometry: a floor (normal +y) meeting a wall (normal +x) at a 90 degree concave edge; the shaded
// point is on the floor at distance h from the wall, AO radius R, k = h / R. A direction w hits the
// wall iff its component towards the wall s = -w.x > 0, at distance d = h / s. Projecting the
// cosine-weighted hemisphere onto the unit disk (Nusselt), (1/pi) cos dw = dA / pi with the chord at
// s of length 2 sqrt(1 - s^2):
//  step (classic AO):    O = 1 - (1/pi) \int_k^1 2 sqrt(1 - s^2) ds = 1 - (acos k - k sqrt(1 - k^2)) / pi
//  cubic mu = (d/R)^3:   O = 1 - (2/pi) \int_k^1 sqrt(1 - s^2) (1 - k^3 / s^3) ds
//                          = 1 - (2/pi) [ (acos k - k w) / 2 - k^3 J ],  w = sqrt(1 - k^2),
//                          J = \int_k^1 sqrt(1 - s^2) / s^3 ds = w / (2 k^2) - ln((1 + w) / k) / 2
//  volumetric (eq. 4.6): the visible part of the tangent sphere (radius a = R/2, centre h from the wall)
//                        is the sphere minus the cap beyond the wall, of height c = a - h:
//                        V = 1 - c^2 (3a - c) / (4 a^3) = 1 - (1 - t)^2 (2 + t) / 4, t = 2h / R < 1.
// All three tend to 1/2 at the foot of the edge (k -> 0) and to 1 far from it.
double aoStepClosedForm(double k) { return k >= 1 ? 1 : 1 - (std::acos(k) - k * std::sqrt(1 - k * k)) / M_PI; }
double aoCubicClosedForm(double k) {
  if (k >= 1) return 1;
  const double w = std::sqrt(1 - k * k);
  const double J = w / (2 * k * k) - 0.5 * std::log((1 + w) / k);
  return 1 - (2 / M_PI) * (0.5 * (std::acos(k) - k * w) - k * k * k * J);
}
double aoVolumetricClosedForm(double t) { return t >= 1 ? 1 : 1 - (1 - t) * (1 - t) * (2 + t) / 4; }

// The same integrals by brute-force quadrature over the hemisphere (checks the derivations above).
double aoQuadrature(double k, int mode) {
  const int n = 1500;
  double sum = 0;
  for (int i = 0; i < n; ++i) {
    const double theta = (i + 0.5) / n * M_PI / 2, ct = std::cos(theta), st = std::sin(theta);
    for (int j = 0; j < 2 * n; ++j) {
      const double phi = (j + 0.5) / (2 * n) * 2 * M_PI;
      const double s = -st * std::cos(phi);  // component towards the wall
      const double d = s > 0 ? k / s : 1e30;  // hit distance in units of R
      const double dw = st * (M_PI / 2 / n) * (M_PI / n);
      if (mode == 0) sum += ct / M_PI * (d >= 1 ? 1 : 0) * dw;
      if (mode == 1) sum += ct / M_PI * std::min(1.0, d * d * d) * dw;
      if (mode == 2) sum += 2 / M_PI * std::pow(std::min(d, ct), 3) * dw;  // (2/pi) \int min(d/R, cos)^3 dw
    }
  }
  return sum;
}

TEST(AmbientOcclusion, ClosedFormsMatchQuadrature) {
  for (double k : {0.02, 0.25, 0.4}) {
    EXPECT_NEAR(aoStepClosedForm(k), aoQuadrature(k, 0), 2e-3) << k;
    EXPECT_NEAR(aoCubicClosedForm(k), aoQuadrature(k, 1), 2e-3) << k;
    EXPECT_NEAR(aoVolumetricClosedForm(2 * k), aoQuadrature(k, 2), 2e-3) << k;
  }
  EXPECT_NEAR(aoStepClosedForm(1e-9), 0.5, 1e-6);
  EXPECT_NEAR(aoCubicClosedForm(1e-6), 0.5, 1e-5);
  EXPECT_NEAR(aoVolumetricClosedForm(0), 0.5, 1e-12);
}

TEST(AmbientOcclusion, OpenPlaneIsOneInEveryMode) {
  Scene s;
  s.meshes.push_back(testing::square({0, 0, 0}, {0, 1, 0}, 100.f, addMaterial(s, lambert(glm::vec3(0.5f)))));
  for (auto mode : {ReferenceOptions::Mode::AoCosineStep, ReferenceOptions::Mode::AoVolumetric,
                    ReferenceOptions::Mode::AoCubicFalloff})
    for (float scale : {1e-3f, 1.f, 1e4f}) {
      ReferenceOptions o;
      o.mode = mode;
      o.aoRadius = 2.f * scale;
      o.spp = 64;
      const Camera cam = testing::lookAtCamera({0, 3 * scale, 2 * scale}, {0, 0, 0}, {0, 1, 0}, false, 0.5f);
      const Image img = render(s, cam, 16, 16, o);
      for (float v : img.pixels) ASSERT_EQ(v, 1.f) << int(mode) << " scale " << scale;
    }
}

TEST(AmbientOcclusion, ConcaveEdgeMatchesClosedForms) {
  Scene s;
  const int m = addMaterial(s, lambert(glm::vec3(0.5f)));
  s.meshes.push_back(testing::quad({0, 0, 10}, {20, 0, 0}, {0, 0, -20}, m));  // floor x in [0,20], normal +y
  s.meshes.push_back(testing::quad({0, 0, 10}, {0, 0, -20}, {0, 10, 0}, m));  // wall x = 0, normal +x
  ASSERT_GT(s.meshes[0].normals[0].y, 0.9f);
  ASSERT_GT(s.meshes[1].normals[0].x, 0.9f);
  const float R = 1.f;
  for (double k : {0.02, 0.25, 0.4}) {
    const glm::vec3 p(float(k * R), 0.f, 0.f);
    ReferenceOptions o;
    o.aoRadius = R;
    o.spp = 40000;  // binomial sigma <= 0.0025 for the step
    o.mode = ReferenceOptions::Mode::AoCosineStep;
    EXPECT_NEAR(renderPoint(s, p, {0, 1, 0}, o), aoStepClosedForm(k), 0.01) << k;
    o.mode = ReferenceOptions::Mode::AoCubicFalloff;
    EXPECT_NEAR(renderPoint(s, p, {0, 1, 0}, o), aoCubicClosedForm(k), 0.01) << k;
    o.mode = ReferenceOptions::Mode::AoVolumetric;
    EXPECT_NEAR(renderPoint(s, p, {0, 1, 0}, o), aoVolumetricClosedForm(2 * k), 0.01) << k;
  }
}

TEST(PathTracer, BaseColorTextureAndAlphaMask) {
  // A 1x1 sRGB base-colour texel of 188 (linear 0.5029) on a plane in the white furnace.
  Scene s;
  Texture t;
  t.width = t.height = 1;
  t.rgba8 = {188, 188, 188, 255};
  s.textures.push_back(t);
  Material textured = lambert(glm::vec3(1.f));
  textured.baseColorTexture.texture = 0;
  MeshInstance plane = testing::square({0, 0, 0}, {0, 1, 0}, 100.f, addMaterial(s, textured));
  plane.uv0 = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  s.meshes.push_back(plane);
  ReferenceOptions o;
  o.spp = 4096;
  o.skyRadiance = glm::vec3(1.f);
  const double linear = std::pow((188 / 255.0 + 0.055) / 1.055, 2.4);
  const double e = testing::directionalAlbedo(bsdfOf(lambert(glm::vec3(float(linear)))), 1.f).x;
  const float open = renderPoint(s, {0, 0, 0}, {0, 1, 0}, o);
  EXPECT_NEAR(open, e, 0.015 * e);

  // An emitter (radiance 3, facing the camera) above the plane whose alpha comes from a texture:
  // alpha 0 under MASK passes through (the camera and the shadow rays see the plane as if it were
  // absent); alpha 1 shows the emitter.
  Texture a;
  a.width = a.height = 1;
  a.rgba8 = {255, 255, 255, 0};
  s.textures.push_back(a);
  Material cutout = testing::emitter(glm::vec3(3.f));
  cutout.baseColorTexture.texture = 1;
  cutout.alphaMode = AlphaMode::Mask;
  MeshInstance card = testing::square({0, 0.5f, 0}, {0, 1, 0}, 100.f, addMaterial(s, cutout));
  card.uv0 = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  s.meshes.push_back(card);
  EXPECT_NEAR(renderPoint(s, {0, 0, 0}, {0, 1, 0}, o, 1.f), open, 0.015 * open);
  s.textures[1].rgba8[3] = 255;
  EXPECT_GE(renderPoint(s, {0, 0, 0}, {0, 1, 0}, o, 1.f), 3.f);
}

TEST(PathTracer, RejectsBadArguments) {
  Scene s;
  s.meshes.push_back(testing::square({0, 0, 0}, {0, 1, 0}, 1.f, addMaterial(s, lambert(glm::vec3(0.5f)))));
  PathTracer pt(s);
  ReferenceOptions o;
  EXPECT_THROW(pt.render(cornerCamera(), 0, 4, o), std::invalid_argument);
  o.spp = 0;
  EXPECT_THROW(pt.render(cornerCamera(), 4, 4, o), std::invalid_argument);
  o.spp = 1;
  o.mode = ReferenceOptions::Mode::AoVolumetric;
  o.aoRadius = 0.f;
  EXPECT_THROW(pt.render(cornerCamera(), 4, 4, o), std::invalid_argument);
  Scene bad = s;
  bad.meshes[0].indices[0] = 99;
  EXPECT_THROW(PathTracer{bad}, std::invalid_argument);
}

}  // namespace
}  // namespace radiant::reference
