// The caustics technique (thesis ch. 6, caustic triangles; issue 14): closed-form energy, flux,
// slab, mirror and sphere cases, light-path ownership, and degenerate input.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "renderer/frame/FrameView.h"
#include "renderer/raytracing/Bsdf.h"
#include "renderer/raytracing/RayScene.h"
#include "renderer/reference/LightTracer.h"
#include "renderer/scene/BuiltinScenes.h"
#include "renderer/techniques/caustics/Caustics.h"
#include "tests/gl/specular/SpecularTestSupport.h"
#include "tests/support/Expect.h"

namespace radiant {
namespace {

using testing::findAov;

Renderer& renderer() {
  static std::unique_ptr<Renderer> r = std::make_unique<Renderer>();
  return *r;
}

constexpr double kPi = 3.14159265358979323846;

api::RenderRequest request(int n, nlohmann::json caustics = nlohmann::json::object()) {
  api::RenderRequest req;
  req.width = n;
  req.height = n;
  req.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"beauty", "direct", "caustics"}, false}};
  req.passes["caustics"] = std::move(caustics);
  req.disabledPasses.insert("photon_gi");  // indirect light is not what these tests measure
  return req;
}

const api::PassStats& passStats(const RenderOutput& out, const std::string& name) {
  for (const auto& p : out.stats.passes)
    if (p.name == name) return p;
  static const api::PassStats none{};
  ADD_FAILURE() << "no pass " << name;
  return none;
}
double counter(const RenderOutput& out, const std::string& pass, const std::string& key) {
  const auto& c = passStats(out, pass).counters;
  auto it = c.find(key);
  if (it == c.end()) {
    ADD_FAILURE() << pass << " has no counter " << key;
    return 0.0;
  }
  return it->second;
}

void expectFinite(const Image& img) {
  int bad = 0;
  for (float v : img.pixels)
    if (!std::isfinite(v) || v < 0.f) ++bad;
  EXPECT_EQ(bad, 0) << img.aov << ": " << bad << " non-finite or negative values";
}

// A white Lambertian floor (y = 0, 6 x 6) under a glass slab (ior, thickness t, top at y = top, side
// `side`), lit by a directional light of irradiance E travelling along `dir`. The camera looks
// straight down from below the slab (orthographic, half extent `half`), so it sees the floor only.
// `primitives`: the slab is one mesh primitive (1), its top face and the other five faces (2), or six
// quads (6), each primitive a generator of its own with its own reference point.
Scene slabScene(float ior, float t, float top, float side, glm::vec3 dir, float E, const std::string& digest,
                bool withSlab = true, int primitives = 1) {
  testing::SceneBuilder b;
  const int white = b.material(testing::lambertian());
  b.quad({0, 0, 0}, {0, 0, 3}, {3, 0, 0}, white, "floor");
  const glm::vec3 lo(-0.5f * side, top - t, -0.5f * side), hi(0.5f * side, top, 0.5f * side);
  if (withSlab && primitives == 1) b.solidBox(lo, hi, b.material(testing::glass(ior)), "slab");
  if (withSlab && primitives > 1) {
    const std::size_t first = b.scene().meshes.size();
    b.box(lo, hi, b.material(testing::glass(ior)), "slab");  // +x -x +y -y +z -z
    if (primitives == 2) {
      auto& meshes = b.scene().meshes;
      std::rotate(meshes.begin() + first + 2, meshes.begin() + first + 3, meshes.end());  // +y last
      b.merge(first, 5, "slab-sides-and-bottom");
    }
  }
  b.directionalLight(dir, E);
  b.topDownOrtho(0.5f * (top - t), 1.5f);
  return b.build(digest);
}

// World (x, z) of pixel (px, py) for SceneBuilder::topDownOrtho(h, half): image x = world x, image up
// = world -z.
glm::vec2 floorPoint(int px, int py, int n, float half) {
  return {-half + 2.f * half * (px + 0.5f) / n, -(half - 2.f * half * (py + 0.5f) / n)};
}

// Energy identity of Gouraud-interpolated triangles (thesis 6.1.2; notes, oracle 1): with
// dA_v = k sum A_t, the cube map holds sum_t A_t (I_a + I_b + I_c) / 3 = sum_v dPhi_v / (3 k), i.e.
// all of the photon power for k = 1/3 and 2/3 of it for the thesis's k = 1/2. The deposit is
// integrated over the receiver seen in the distance map (sum E Omega d^2 / cos), within 2%. The
// rasterised footprint differs from the true one by at most about half a texel along its edge: at
// C = 512 the slab's caustic spans 230 texels, so the edge error is below 1% (at C = 256, 3.1% was
// measured).
TEST(Caustics, EnergyIsAllPhotonPowerWithWeightOneThirdAndTwoThirdsWithOneHalf) {
  Scene scene = slabScene(1.5f, 0.2f, 1.2f, 1.f, {0, -1, 0}, 2.f, "caustics-energy");
  for (double k : {1.0 / 3.0, 0.5}) {
    RenderOutput out = renderer().render(scene, request(32, {{"area_weight", k}, {"energy_check", true}, {"cube_resolution", 512}}));
    const double photons = counter(out, "caustics", "photon_power");
    const double deposited = counter(out, "caustics", "deposited_power");
    const double lost = counter(out, "caustics", "lost_power");
    const double expected = (photons - lost) / (3.0 * k);
    std::printf("k = %.4f: photon power %.5f, lost %.6f, deposited %.5f, expected %.5f (ratio %.4f)\n", k, photons,
                lost, deposited, expected, deposited / expected);
    EXPECT_GT(photons, 1.0);
    EXPECT_LT(lost, 1e-3 * photons);  // a square's hit image loses no vertex: every one has a triangle
    EXPECT_NEAR(deposited / photons, 1.0 / (3.0 * k), 0.02 / (3.0 * k));
  }
}

// Flux (oracle 2): the photons carry the light's power through the generator times the Fresnel
// products: a directional light E through the slab's top face, into and out of the glass at normal
// incidence, (1 - F)^2 with F = ((n - 1) / (n + 1))^2 = 0.04. The light camera's pixels are squares
// of side 2 R / P (R = the slab's bounding radius); those whose centres fall on the top face carry
// the photons, so the discrete flux is E (count x side)^2 (1 - F)^2 exactly (float rounding), and it
// is within 2% of the continuous E A (1 - F)^2. The distance maps are 512^2 here: at the default 256^2
// the outer ring of photons (4% of the flux at P = 128) is lost, because seen from the slab's centre
// its bottom face is at 11 degrees from grazing and its last texels hold the side faces (measured:
// 7748 of 8100 photons reach the floor at 256, all 8100 at 512 and 1024).
TEST(Caustics, PhotonFluxIsLightPowerThroughGeneratorTimesFresnelProducts) {
  const float E = 2.f, side = 1.f, t = 0.2f;
  Scene scene = slabScene(1.5f, t, 1.2f, side, {0, -1, 0}, E, "caustics-flux");
  const int P = 128;
  api::RenderRequest req = request(32, {{"photon_resolution", P}, {"energy_check", true}});
  req.passes["specular"] = {{"cube_resolution", 512}};
  RenderOutput out = renderer().render(scene, req);
  const double R = 0.5 * std::sqrt(side * side * 2.0 + t * t);
  const double pixel = 2.0 * R / P;
  int inside = 0;
  for (int i = 0; i < P; ++i)
    if (std::abs((-1.0 + (2.0 * i + 1.0) / P) * R) < 0.5 * side) ++inside;
  const double fresnel = std::pow(1.0 - 0.04, 2.0);
  const double discrete = E * std::pow(inside * pixel, 2.0) * fresnel;
  const double continuous = E * side * side * fresnel;
  const double photons = counter(out, "caustics", "photon_power");
  std::printf("photon power %.5f, discrete %.5f, continuous %.5f, valid photons %.0f of %d\n", photons, discrete,
              continuous, counter(out, "caustics", "valid_photons"), inside * inside);
  EXPECT_NEAR(photons, discrete, 1e-4 * discrete);
  EXPECT_NEAR(photons, continuous, 0.02 * continuous);
  EXPECT_EQ(counter(out, "caustics", "valid_photons"), double(inside * inside));
}

// Glass slab at normal incidence (oracle 3): under the slab the direct light is shadowed (generators
// stay opaque in the shadow maps) and the caustic brings back E (1 - F)^2 = 0.9216 E, so beauty is
// 0.9216 E / pi on a white Lambertian floor; outside it is E / pi from direct alone and the caustic
// is 0: nothing is counted twice.
void expectSlabTransmitsFresnelSquaredAtNormalIncidence(int primitives) {
  SCOPED_TRACE(std::to_string(primitives) + " primitives");
  const float E = 2.f;
  Scene scene = slabScene(1.5f, 0.2f, 1.2f, 1.f, {0, -1, 0}, E, "caustics-slab-" + std::to_string(primitives), true,
                          primitives);
  const int n = 64;
  const float half = 1.5f;
  RenderOutput out = renderer().render(scene, request(n));
  const Image& caustics = findAov(out, "caustics");
  const Image& direct = findAov(out, "direct");
  const Image& beauty = findAov(out, "beauty");
  expectFinite(caustics);
  expectFinite(beauty);
  const double under = 0.9216 * E / kPi, open = E / kPi;
  int in = 0, outside = 0;
  for (int py = 0; py < n; ++py)
    for (int px = 0; px < n; ++px) {
      const glm::vec2 p = floorPoint(px, py, n, half);
      const float m = std::max(std::abs(p.x), std::abs(p.y));
      if (m < 0.5f - 0.1f) {
        ++in;
        EXPECT_NEAR(caustics.at(px, py)[1], under, 0.01 * under) << px << "," << py;
        EXPECT_NEAR(direct.at(px, py)[1], 0.0, 1e-6) << px << "," << py;
        EXPECT_NEAR(beauty.at(px, py)[1], under, 0.01 * under) << px << "," << py;
      } else if (m > 0.5f + 0.1f) {
        ++outside;
        EXPECT_EQ(caustics.at(px, py)[1], 0.f) << px << "," << py;
        EXPECT_NEAR(beauty.at(px, py)[1], open, 0.01 * open) << px << "," << py;
      }
    }
  EXPECT_GT(in, 200);
  EXPECT_GT(outside, 1000);
}
TEST(Caustics, GlassSlabTransmitsFresnelSquaredAtNormalIncidence) { expectSlabTransmitsFresnelSquaredAtNormalIncidence(1); }

// KHR_materials_volume: the same slab absorbing, white light turning into c = (0.5, 0.8, 1) over d0 =
// 0.1. Each photon crosses the thickness t = 0.2 once at normal incidence, so the caustic under it is
// E (1 - F)^2 a / pi with a = c^(t / d0) = (0.25, 0.64, 1) per channel (Beer-Lambert over the traced
// length in the distance maps, shaders/caustics/photon.frag), within the clear slab's 1%.
TEST(Caustics, AbsorbingSlabTransmitsBeerLambertTimesFresnelSquared) {
  const float E = 2.f, t = 0.2f, d0 = 0.1f;
  const glm::vec3 c(0.5f, 0.8f, 1.f);
  Scene scene = slabScene(1.5f, t, 1.2f, 1.f, {0, -1, 0}, E, "caustics-slab-volume");
  for (Material& m : scene.materials)
    if (m.isTransmissive()) {
      m.thicknessFactor = 1.f;
      m.attenuationColor = c;
      m.attenuationDistance = d0;
    }
  const int n = 64;
  const float half = 1.5f;
  RenderOutput out = renderer().render(scene, request(n));
  const Image& caustics = findAov(out, "caustics");
  expectFinite(caustics);
  int in = 0;
  for (int py = 0; py < n; ++py)
    for (int px = 0; px < n; ++px) {
      const glm::vec2 p = floorPoint(px, py, n, half);
      if (std::max(std::abs(p.x), std::abs(p.y)) >= 0.5f - 0.1f) continue;
      ++in;
      for (int k = 0; k < 3; ++k) {
        const double under = 0.9216 * E * std::pow(double(c[k]), t / d0) / kPi;
        EXPECT_NEAR(caustics.at(px, py)[k], under, 0.01 * under) << px << "," << py << " channel " << k;
      }
    }
  EXPECT_GT(in, 200);
}

// A generator made of several primitives (each its own specular object with its own reference point
// and maps): the photons entering the top face are traced on through the other primitive's maps, and
// the receivers under the slab lie behind that other primitive as seen from the top face's reference
// point. The caustic must still be there, with the same closed form: the slab as its top face plus
// the other five faces, and as six quads.
TEST(Caustics, GlassSlabOfSeveralPrimitivesKeepsItsCaustic) {
  expectSlabTransmitsFresnelSquaredAtNormalIncidence(2);
  expectSlabTransmitsFresnelSquaredAtNormalIncidence(6);
}

// The slab at 30 degrees (oracle 3): the transmitted light keeps its direction (parallel faces), so
// the floor under it gets E cos(theta) (1 - F(theta))^2 with the exact Fresnel factor of both
// interfaces; and its edge is shifted, against the straight projection of the slab's top edge, by
// t (tan theta - tan theta_t) towards the light (refraction inside the glass bends the rays steeper).
// The leading edge is found as the half-plateau crossing of the caustic along the row z = 0; it must
// lie within 0.012 (a pixel, a quarter of the 0.045 shift) of the closed form.
TEST(Caustics, GlassSlabAtAnAngleTransmitsFresnelProductAndShiftsItsEdge) {
  const float E = 2.f, t = 0.2f, top = 1.2f, side = 1.f;
  const float theta = glm::radians(30.f);
  Scene scene = slabScene(1.5f, t, top, side, {std::sin(theta), -std::cos(theta), 0.f}, E, "caustics-slab-30");
  const int n = 256;
  const float half = 1.5f;
  RenderOutput out = renderer().render(scene, request(n, {{"cube_resolution", 512}}));
  const Image& caustics = findAov(out, "caustics");
  expectFinite(caustics);
  const float F = rt::fresnelDielectric(std::cos(theta), 1.5f);
  const double plateau = E * std::cos(theta) * std::pow(1.0 - F, 2.0) / kPi;
  const double thetaT = std::asin(std::sin(theta) / 1.5);
  const double straight = -0.5 * side + top * std::tan(theta);
  const double expectedEdge = straight - t * (std::tan(theta) - std::tan(thetaT));
  // The row through z = 0 and the plateau beyond the edge (x in [edge + 0.2, edge + 0.6]).
  const int row = n / 2;
  double sum = 0.0;
  int count = 0;
  std::vector<double> xs, vs;
  for (int px = 0; px < n; ++px) {
    const glm::vec2 p = floorPoint(px, row, n, half);
    const double v = 0.5 * (caustics.at(px, row)[1] + caustics.at(px, row - 1)[1]);
    xs.push_back(p.x);
    vs.push_back(v);
    if (p.x > expectedEdge + 0.2 && p.x < expectedEdge + 0.6) sum += v, ++count;
  }
  ASSERT_GT(count, 10);
  const double measuredPlateau = sum / count;
  // Walk left from the plateau to the first value below half of it. (Left of the edge, at
  // x = -0.13, lies a one-pixel line of spurious light: photons that enter the slab's side face,
  // are totally reflected at its bottom and then "exit" where the distance map confuses the bottom
  // face with the side face at its grazing edge; thesis 6.4's search misses. It is not the edge.)
  double edge = 0.0;
  std::size_t i = 0;
  while (i < xs.size() && xs[i] < expectedEdge + 0.4) ++i;
  for (; i > 0; --i)
    if (vs[i - 1] < 0.5 * measuredPlateau && vs[i] >= 0.5 * measuredPlateau) {
      edge = xs[i - 1] + (xs[i] - xs[i - 1]) * (0.5 * measuredPlateau - vs[i - 1]) / (vs[i] - vs[i - 1]);
      break;
    }
  std::printf("plateau %.5f (expected %.5f, F = %.5f), edge %.4f (expected %.4f, unrefracted %.4f)\n", measuredPlateau,
              plateau, F, edge, expectedEdge, straight);
  EXPECT_NEAR(measuredPlateau, plateau, 0.01 * plateau);
  EXPECT_NEAR(edge, expectedEdge, 0.012);
}

// ior 1 (oracle 3): no Fresnel reflection, no bending; the caustic returns exactly the light the
// slab's shadow removed, so direct + caustics equals the image without the slab (1% per pixel away
// from the shadow's edges, where PCF and the caustic's texel edge differ, and 0.5% over the image).
TEST(Caustics, Ior1SlabLeavesDirectPlusCausticsEqualToTheImageWithoutIt) {
  const float E = 2.f;
  const glm::vec3 dir = glm::normalize(glm::vec3(0.3f, -1.f, 0.2f));
  Scene with = slabScene(1.f, 0.2f, 1.2f, 1.f, dir, E, "caustics-ior1");
  Scene without = slabScene(1.f, 0.2f, 1.2f, 1.f, dir, E, "caustics-ior1-none", false);
  const int n = 64;
  RenderOutput a = renderer().render(with, request(n, {{"cube_resolution", 512}}));
  api::RenderRequest plain = request(n);
  plain.passes.erase("caustics");
  plain.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"beauty"}, false}};
  RenderOutput b = renderer().render(without, plain);
  const Image& beautyA = findAov(a, "beauty");
  const Image& beautyB = findAov(b, "beauty");
  const Image& direct = findAov(a, "direct");
  const Image& caustics = findAov(a, "caustics");
  expectFinite(beautyA);
  double sumA = 0, sumB = 0;
  int compared = 0, shadowed = 0;
  for (int py = 2; py < n - 2; ++py)
    for (int px = 2; px < n - 2; ++px) {
      sumA += beautyA.at(px, py)[1];
      sumB += beautyB.at(px, py)[1];
      // Away from the shadow's edge: all nine neighbours agree on lit or shadowed.
      bool edge = false;
      for (int j = -2; j <= 2; ++j)
        for (int i = -2; i <= 2; ++i)
          edge = edge || ((direct.at(px + i, py + j)[1] > 0.1f) != (direct.at(px, py)[1] > 0.1f));
      if (edge) continue;
      ++compared;
      if (direct.at(px, py)[1] < 0.1f) ++shadowed;
      EXPECT_NEAR(beautyA.at(px, py)[1], beautyB.at(px, py)[1], 0.01 * beautyB.at(px, py)[1]) << px << "," << py;
      EXPECT_NEAR(direct.at(px, py)[1] + caustics.at(px, py)[1], beautyA.at(px, py)[1], 1e-5);
    }
  std::printf("ior 1: sum with slab %.4f, without %.4f, %d pixels compared, %d in the shadow\n", sumA, sumB, compared,
              shadowed);
  EXPECT_GT(shadowed, 150);
  EXPECT_NEAR(sumA, sumB, 0.005 * sumB);
}

// A flat mirror (oracle 5): a point light I at (0, 2, 0) above a mirror of F0 = 0.8 in the plane
// y = 1 (side 1) lights the ceiling y = 3 from its image at the origin: E = I F(cos_i) cos(theta_r) / d^2
// with d the distance from the image, cos(theta_r) = 3 / d, F Schlick's (glTF conductor), inside the
// reflected footprint |x|, |z| < 1.5, and 0 outside. The camera sits under the ceiling looking up.
TEST(Caustics, FlatMirrorCausticIsTheLightsImage) {
  testing::SceneBuilder b;
  const float I = 5.f, f0 = 0.8f;
  b.quad({0, 1, 0}, {0, 0, 0.5f}, {0.5f, 0, 0}, b.material(testing::mirror(glm::vec3(f0))), "mirror");
  b.quad({0, 3, 0}, {2.5f, 0, 0}, {0, 0, 2.5f}, b.material(testing::lambertian()), "ceiling");
  b.pointLight({0, 2, 0}, I);
  const float half = 2.f;
  b.scene().camera = testing::orthoCamera({0, 2.5f, 0}, {0, 1, 0}, {0, 0, 1}, half, 2.f);
  Scene scene = b.build("caustics-mirror");
  const int n = 64;
  RenderOutput out = renderer().render(scene, request(n, {{"cube_resolution", 512}}));
  const Image& caustics = findAov(out, "caustics");
  expectFinite(caustics);
  const float margin = 3.f * 2.f * half / n;
  int inside = 0, outside = 0;
  double maxOutside = 0.0;
  for (int py = 0; py < n; ++py)
    for (int px = 0; px < n; ++px) {
      // orthoCamera: image right = +x, image up = +z.
      const double x = -half + 2.0 * half * (px + 0.5) / n, z = half - 2.0 * half * (py + 0.5) / n;
      const double m = std::max(std::abs(x), std::abs(z));
      const double v = caustics.at(px, py)[1];
      if (m < 1.5 - margin) {
        const double d2 = x * x + 9.0 + z * z, d = std::sqrt(d2);
        const double cosI = 1.0 / std::sqrt(1.0 + (x * x + z * z) / 9.0);
        const double F = f0 + (1.0 - f0) * std::pow(1.0 - cosI, 5.0);
        const double expected = I * F * (3.0 / d) / d2 / kPi;
        EXPECT_NEAR(v, expected, 0.02 * expected) << px << "," << py;
        ++inside;
      } else if (m > 1.5 + margin) {
        maxOutside = std::max(maxOutside, v);
        ++outside;
      }
    }
  EXPECT_GT(inside, 1500);
  EXPECT_GT(outside, 500);
  EXPECT_EQ(maxOutside, 0.0);
}

// The caustic cubes' memory is bounded (CausticsPass::kMaxBytes, 512 MiB: six RGBA32F faces with their
// mip chain per generator, 8 MiB at 256 texels). The flat-mirror scene with 64 more mirrors beyond the
// light's range (generators without a pair still get a cube): 65 x 8 MiB at the default 256 is over the
// limit, so the cubes are drawn at 128 with a warning; a cube_resolution the request gives is a 422
// naming it, before anything is allocated.
TEST(Caustics, CubesStayWithinTheirMemoryLimit) {
  EXPECT_EQ(CausticsPass::cubeBytes(1, 256), 6.0 * 87381 * 16);  // 256^2 + 128^2 + ... + 1 texels
  EXPECT_GT(CausticsPass::cubeBytes(65, 256), CausticsPass::kMaxBytes);
  EXPECT_LT(CausticsPass::cubeBytes(64, 256), CausticsPass::kMaxBytes);
  testing::SceneBuilder b;
  const int mirror = b.material(testing::mirror(glm::vec3(0.8f)));
  b.quad({0, 1, 0}, {0, 0, 0.5f}, {0.5f, 0, 0}, mirror, "mirror");
  b.quad({0, 3, 0}, {2.5f, 0, 0}, {0, 0, 2.5f}, b.material(testing::lambertian()), "ceiling");
  for (int i = 0; i < 64; ++i) b.quad({40.f + 0.5f * (i % 8), 1, 0.5f * (i / 8)}, {0, 0, 0.1f}, {0.1f, 0, 0}, mirror, "far");
  b.pointLight({0, 2, 0}, 5.f);
  b.scene().lights[0].range = 10.f;
  b.scene().camera = testing::orthoCamera({0, 2.5f, 0}, {0, 1, 0}, {0, 0, 1}, 2.f, 2.f);
  Scene scene = b.build("caustics-cube-memory");
  RenderOutput out = renderer().render(scene, request(16));
  EXPECT_EQ(counter(out, "caustics", "generators"), 65.0);
  EXPECT_EQ(counter(out, "caustics", "pairs"), 1.0);
  EXPECT_EQ(counter(out, "caustics", "cube_resolution"), 128.0);
  EXPECT_LE(counter(out, "caustics", "cube_bytes"), CausticsPass::kMaxBytes);
  bool warned = false;
  for (const auto& w : out.stats.warnings) warned = warned || (w.rfind("caustics: 65 generators", 0) == 0 &&
                                                               w.find("drawn at 128^2") != std::string::npos);
  EXPECT_TRUE(warned);
  expectFinite(findAov(out, "caustics"));

  api::RenderRequest given = request(16, {{"cube_resolution", 256}});
  given.explicitParams["caustics"] = {"cube_resolution"};  // as the request's JSON names it
  const api::ApiError e = testing::thrownApiError([&] { renderer().render(scene, given); });  // 65 cubes of 256^2
  EXPECT_EQ(e.status, 422);
  EXPECT_EQ(e.pointer, "/passes/caustics/cube_resolution");
}

// Degenerate input (oracle 6), each with finite output and an exact zero where no light can arrive.
// (a) All-invalid hit image: a mirror facing up under a light and nothing above it, so every photon
// leaves the scene.
TEST(Caustics, AllInvalidHitImageGivesZeroCaustics) {
  testing::SceneBuilder b;
  b.quad({0, 0, 0}, {0, 0, 3}, {3, 0, 0}, b.material(testing::lambertian()), "floor");
  b.quad({0, 1, 0}, {0, 0, 0.5f}, {0.5f, 0, 0}, b.material(testing::mirror(glm::vec3(1.f))), "mirror");
  b.directionalLight({0, -1, 0}, 2.f);
  b.topDownOrtho(0.5f, 1.5f);
  Scene scene = b.build("caustics-all-invalid");
  RenderOutput out = renderer().render(scene, request(32, {{"energy_check", true}}));
  const Image& caustics = findAov(out, "caustics");
  expectFinite(caustics);
  EXPECT_EQ(counter(out, "caustics", "pairs"), 1.0);
  EXPECT_EQ(counter(out, "caustics", "valid_photons"), 0.0);
  EXPECT_EQ(counter(out, "caustics", "deposited_power"), 0.0);
  EXPECT_EQ(*std::max_element(caustics.pixels.begin(), caustics.pixels.end()), 0.f);
}

// (b) Total internal reflection everywhere: a narrow spot light enters the top of a tall glass column
// at 60 degrees; inside, every ray meets a side wall at 90 - 35.3 = 54.7 degrees, beyond the critical
// angle of 41.8, and is reflected until max_depth (4) ends it: no photon reaches a receiver.
TEST(Caustics, TotalInternalReflectionEverywhereGivesZeroCaustics) {
  testing::SceneBuilder b;
  b.quad({0, 0, 0}, {0, 0, 4}, {4, 0, 0}, b.material(testing::lambertian()), "floor");
  b.solidBox({-0.5f, 0.5f, -0.5f}, {0.5f, 6.5f, 0.5f}, b.material(testing::glass(1.5f)), "column");
  const glm::vec3 target(0, 6.5f, 0), from = target + 3.f * glm::vec3(-std::sin(glm::radians(60.f)), std::cos(glm::radians(60.f)), 0);
  b.spotLight(from, target - from, 50.f, 0.f, std::atan(0.15f / 3.f));
  b.topDownOrtho(0.4f, 2.f);
  Scene scene = b.build("caustics-tir");
  RenderOutput out = renderer().render(scene, request(32, {{"energy_check", true}}));
  const Image& caustics = findAov(out, "caustics");
  expectFinite(caustics);
  EXPECT_EQ(counter(out, "caustics", "pairs"), 2.0);  // the refraction image and the entry-reflection image
  EXPECT_EQ(counter(out, "caustics", "valid_photons"), 0.0);
  EXPECT_EQ(*std::max_element(caustics.pixels.begin(), caustics.pixels.end()), 0.f);
}

// (c) A generator outside the light's frustum: a spot light pointing away from the glass. The planner
// skips the pass with its reason, and nothing is added.
TEST(Caustics, GeneratorOutsideTheLightsConeIsSkippedWithAReason) {
  testing::SceneBuilder b;
  b.quad({0, 0, 0}, {0, 0, 3}, {3, 0, 0}, b.material(testing::lambertian()), "floor");
  b.sphere({0, 1, 0}, 0.3f, b.material(testing::glass(1.5f)), 32, 16);
  b.spotLight({2, 2, 0}, {1, -1, 0}, 10.f, 0.f, 0.3f);
  b.topDownOrtho(0.5f, 1.5f);
  Scene scene = b.build("caustics-outside-cone");
  EXPECT_EQ(CausticsPass::skipReason(scene), "no specular material in view of a light");
  RenderOutput out = renderer().render(scene, request(32));
  ASSERT_TRUE(out.stats.skipped.count("caustics"));
  EXPECT_EQ(out.stats.skipped.at("caustics"), "no specular material in view of a light");
  // Without a generator at all, and without a punctual light:
  testing::SceneBuilder c;
  c.quad({0, 0, 0}, {0, 0, 3}, {3, 0, 0}, c.material(testing::lambertian()), "floor");
  c.directionalLight({0, -1, 0}, 1.f);
  EXPECT_EQ(CausticsPass::skipReason(c.build("caustics-no-generator")), "no specular material (mirror or refractor) in the scene");
}

// (d) The focus: a glass sphere (R = 0.5, ior 1.5) under a directional light with the floor at its
// paraxial focus, 1.5 R below the centre, where the central triangles shrink below a texel and to
// zero area. Their power goes to one texel each: the deposit stays equal to the photon power (3%:
// the footprint edge, as in the energy test, plus the triangles bridging the sphere's silhouette,
// which the normal test drops) and everything is finite.
TEST(Caustics, FocusOfAGlassSphereConservesEnergyAndStaysFinite) {
  testing::SceneBuilder b;
  const float R = 0.5f;
  b.quad({0, 0, 0}, {0, 0, 2}, {2, 0, 0}, b.material(testing::lambertian()), "floor");
  b.sphere({0, 1.5f * R, 0}, R, b.material(testing::glass(1.5f)), 96, 48);
  b.directionalLight({0, -1, 0}, 1.f);
  b.topDownOrtho(0.2f * R, 0.5f);
  Scene scene = b.build("caustics-focus");
  RenderOutput out = renderer().render(scene, request(64, {{"energy_check", true}}));
  const Image& caustics = findAov(out, "caustics");
  expectFinite(caustics);
  expectFinite(findAov(out, "beauty"));
  const double photons = counter(out, "caustics", "photon_power");
  const double deposited = counter(out, "caustics", "deposited_power");
  const double lost = counter(out, "caustics", "lost_power");
  std::printf("focus: photon power %.5f, lost %.5f, deposited %.5f (ratio %.4f)\n", photons, lost, deposited,
              deposited / photons);
  EXPECT_GT(photons, 0.5);
  EXPECT_NEAR(deposited, photons - lost, 0.03 * photons);
  // The peak is at the centre of the image (the axis).
  int best = 0;
  for (int i = 0; i < 64 * 64; ++i)
    if (caustics.pixels[i * caustics.channels + 1] > caustics.pixels[best * caustics.channels + 1]) best = i;
  EXPECT_NEAR(best % 64, 31.5, 1.5);
  EXPECT_NEAR(best / 64, 31.5, 1.5);
}

// The glass sphere's paraxial focus (oracle 4): a ball lens of index n focuses parallel light at
// n R / (2 (n - 1)) = 1.5 R from its centre (principal planes at the centre). An opaque mask with a
// 0.1 x 0.1 hole (0.2 R) above the sphere keeps only paraxial rays; on floors at 1.1 .. 1.9 R below
// the centre the caustic's rms radius is smallest at 1.5 R, grows linearly with the distance from it
// (so it is symmetric: within 35% at 1.3 and 1.7 R), and is over twice as large 0.4 R away.
TEST(Caustics, GlassSpherePeaksAtItsParaxialFocus) {
  const float R = 0.5f;
  std::vector<double> rms;
  const std::vector<double> zs = {1.1, 1.3, 1.5, 1.7, 1.9};
  for (double z : zs) {
    testing::SceneBuilder b;
    const float cy = static_cast<float>(z * R);
    b.quad({0, 0, 0}, {0, 0, 0.5f}, {0.5f, 0, 0}, b.material(testing::lambertian()), "floor");
    b.sphere({0, cy, 0}, R, b.material(testing::glass(1.5f)), 128, 64);
    const int black = b.material(testing::lambertian(glm::vec3(0.f)));
    const float my = cy + R + 0.1f, a = 0.05f, w = 0.6f;  // mask: a square hole of half side a
    b.quad({0.5f * (a + w), my, 0}, {0, 0, w}, {0.5f * (w - a), 0, 0}, black, "mask+x");
    b.quad({-0.5f * (a + w), my, 0}, {0, 0, w}, {0.5f * (w - a), 0, 0}, black, "mask-x");
    b.quad({0, my, 0.5f * (a + w)}, {0, 0, 0.5f * (w - a)}, {a, 0, 0}, black, "mask+z");
    b.quad({0, my, -0.5f * (a + w)}, {0, 0, 0.5f * (w - a)}, {a, 0, 0}, black, "mask-z");
    b.directionalLight({0, -1, 0}, 1.f);
    b.topDownOrtho(0.02f, 0.05f);
    Scene scene = b.build("caustics-paraxial-" + std::to_string(z));
    const int n = 64;
    RenderOutput out = renderer().render(scene, request(n, {{"photon_resolution", 256}, {"cube_resolution", 1024}, {"energy_check", true}}));
    const Image& caustics = findAov(out, "caustics");
    expectFinite(caustics);
    double sw = 0, sr2 = 0;
    for (int py = 0; py < n; ++py)
      for (int px = 0; px < n; ++px) {
        const glm::vec2 p = floorPoint(px, py, n, 0.05f);
        const double v = caustics.at(px, py)[1];
        sw += v;
        sr2 += v * glm::dot(p, p);
      }
    ASSERT_GT(sw, 0.0) << z;
    rms.push_back(std::sqrt(sr2 / sw));
    std::printf("floor %.1f R below the centre: caustic rms radius %.5f\n", z, rms.back());
  }
  const auto smallest = std::min_element(rms.begin(), rms.end()) - rms.begin();
  EXPECT_EQ(zs[smallest], 1.5);
  EXPECT_GT(rms[0], 2.0 * rms[2]);
  EXPECT_GT(rms[4], 2.0 * rms[2]);
  EXPECT_NEAR(rms[1] / rms[3], 1.0, 0.35);
}

// The splat baseline deposits the same photons as disks of uniform irradiance dPhi / (pi r^2) in the
// receiver's plane: on a plane receiver all of their power (2%, the disks' rasterised edges), and
// under the slab the same plateau as the triangles once r spans several photons (here r = 0.05, 4.5
// photon spacings: 3% per pixel).
TEST(Caustics, SplatBaselineConservesEnergyAndMatchesThePlateau) {
  const float E = 2.f;
  Scene scene = slabScene(1.5f, 0.2f, 1.2f, 1.f, {0, -1, 0}, E, "caustics-splat");
  const int n = 64;
  RenderOutput out = renderer().render(
      scene, request(n, {{"method", "splat"}, {"splat_radius", 0.05}, {"energy_check", true}, {"cube_resolution", 512}}));
  const double photons = counter(out, "caustics", "photon_power");
  const double deposited = counter(out, "caustics", "deposited_power");
  std::printf("splat: photon power %.5f, deposited %.5f (ratio %.4f)\n", photons, deposited, deposited / photons);
  EXPECT_NEAR(deposited, photons, 0.02 * photons);
  EXPECT_GT(counter(out, "caustics", "splats"), 0.0);
  const Image& caustics = findAov(out, "caustics");
  expectFinite(caustics);
  const double under = 0.9216 * E / kPi;
  for (int py = 0; py < n; ++py)
    for (int px = 0; px < n; ++px) {
      const glm::vec2 p = floorPoint(px, py, n, 1.5f);
      if (std::max(std::abs(p.x), std::abs(p.y)) < 0.5f - 0.1f) {
        EXPECT_NEAR(caustics.at(px, py)[1], under, 0.03 * under) << px << "," << py;
      }
    }
}

// Every light path is counted once (ARCHITECTURE.md): a near-mirror (metal, roughness 0.1: specular
// for the raster passes, a glossy lobe for the photon tracer) reflects a point light onto the floor.
// When caustics runs it owns LS+DE and photon_gi leaves those photons out; when the request turns
// caustics off, photon_gi owns the class and splats them. The floor's caustics + indirect in the first
// frame must carry the energy of indirect alone in the second (within 5%: photon noise summed over the
// floor, and the glossy lobe's albedo at alpha = 0.01 against the mirror's Schlick factor), and what
// photon_gi still adds beside the caustics (floor -> mirror -> floor light) must be small (< 10%).
TEST(Caustics, NearMirrorCausticIsCountedOnceWithPhotonGi) {
  testing::SceneBuilder b;
  b.quad({0, 0, 0}, {0, 0, 3}, {3, 0, 0}, b.material(testing::lambertian()), "floor");
  Material nearMirror = testing::mirror(glm::vec3(0.9f));
  nearMirror.roughnessFactor = 0.1f;
  b.quad({-1, 1, 0}, {0, 0.8f, 0}, {0, 0, 0.8f}, b.material(nearMirror), "mirror");  // normal +x
  b.pointLight({0, 1.5f, 0}, 10.f);
  b.topDownOrtho(2.5f, 3.f);
  Scene scene = b.build("caustics-near-mirror");
  ASSERT_TRUE(scene.materials[1].isSpecular());
  const int n = 64;
  api::RenderRequest withCaustics = request(n, {{"cube_resolution", 512}});
  withCaustics.disabledPasses.clear();
  withCaustics.passes["photon_gi"] = {{"photons", 300000}};
  withCaustics.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"beauty", "direct", "caustics", "indirect"}, false}};
  api::RenderRequest withoutCaustics = withCaustics;
  withoutCaustics.passes.erase("caustics");
  withoutCaustics.disabledPasses.insert("caustics");
  withoutCaustics.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"beauty", "indirect"}, false}};
  RenderOutput a = renderer().render(scene, withCaustics);
  RenderOutput c = renderer().render(scene, withoutCaustics);
  EXPECT_EQ(a.stats.lightPaths.at("LS+DE"), "caustics");
  EXPECT_EQ(c.stats.lightPaths.at("LS+DE"), "photon_gi");
  const Image& causticsA = findAov(a, "caustics");
  const Image& indirectA = findAov(a, "indirect");
  const Image& indirectC = findAov(c, "indirect");
  double sumCaustics = 0, sumIndirectA = 0, sumIndirectC = 0;
  for (int py = 0; py < n; ++py)
    for (int px = 0; px < n; ++px) {
      sumCaustics += causticsA.at(px, py)[1];
      sumIndirectA += indirectA.at(px, py)[1];
      sumIndirectC += indirectC.at(px, py)[1];
    }
  std::printf("caustics %.4f + indirect %.4f = %.4f against photon_gi alone %.4f\n", sumCaustics, sumIndirectA,
              sumCaustics + sumIndirectA, sumIndirectC);
  EXPECT_GT(sumCaustics, 0.3 * sumIndirectC);
  EXPECT_NEAR(sumCaustics + sumIndirectA, sumIndirectC, 0.05 * sumIndirectC);
  EXPECT_LT(sumIndirectA, 0.1 * sumIndirectC);
}

// Against the reference light tracer (its caustics class, exactly L S+ D E) on the slab at 30 degrees:
// the mean of the caustics AOV over the plateau (x in [0.35, 0.95], |z| < 0.3, away from both edges)
// agrees with the light tracer's within 2%. The light tracer also carries light reflected twice inside
// the slab ((1 - F)^2 F^2, 3e-3 of it); its estimate is heavy-tailed at few paths (measured here: +5%
// at 64 paths per pixel, +0.6% at 1024, against the closed form that the technique meets exactly), so it
// runs 1024 paths per pixel (4M paths, about a second).
TEST(Caustics, SlabPlateauAgreesWithTheReferenceLightTracer) {
  const float theta = glm::radians(30.f);
  Scene scene = slabScene(1.5f, 0.2f, 1.2f, 1.f, {std::sin(theta), -std::cos(theta), 0.f}, 2.f, "caustics-vs-lt");
  const int n = 64;
  const api::RenderRequest req = request(n, {{"cube_resolution", 512}});
  RenderOutput out = renderer().render(scene, req);
  const Image& caustics = findAov(out, "caustics");
  rt::RayScene rays(scene);
  reference::LightTracer tracer(rays);
  reference::LightTracerOptions o;
  o.pathsPerPixel = 1024;
  o.seed = 3;
  const Image lt = tracer.render(makeFrameView(scene, req).camera, n, n, o);
  double sumOurs = 0, sumRef = 0;
  int count = 0;
  for (int py = 0; py < n; ++py)
    for (int px = 0; px < n; ++px) {
      const glm::vec2 p = floorPoint(px, py, n, 1.5f);
      if (p.x < 0.35f || p.x > 0.95f || std::abs(p.y) > 0.3f) continue;
      sumOurs += caustics.at(px, py)[1];
      sumRef += lt.at(px, py)[1];
      ++count;
    }
  std::printf("plateau mean: caustics %.5f, light tracer %.5f over %d pixels\n", sumOurs / count, sumRef / count, count);
  EXPECT_GT(count, 120);
  EXPECT_NEAR(sumOurs / sumRef, 1.0, 0.02);
}
// The entry's Fresnel reflection of a refractor (fresnel_reflection, the second hit image): a point
// light I at (0, 2, 0) over a glass slab whose top face lies at y = 1.2 lights the ceiling y = 3 from
// its image at (0, 0.4, 0): E = I F(cos_i) cos(theta_r) / d^2 with the exact dielectric F of ior 1.5,
// inside the footprint |x|, |z| < 0.5 (3 - 0.4) / (1.2 - 0.4) = 1.625 (2%). The reflection inside the
// slab off its bottom face, (1 - F)^2 F more, is not traced (one path per hit image); with
// fresnel_reflection false the ceiling gets nothing.
TEST(Caustics, GlassEntryReflectionLightsTheCeilingWithTheFresnelFactor) {
  testing::SceneBuilder b;
  const float I = 20.f;
  b.solidBox({-0.5f, 1.0f, -0.5f}, {0.5f, 1.2f, 0.5f}, b.material(testing::glass(1.5f)), "slab");
  b.quad({0, 3, 0}, {2.5f, 0, 0}, {0, 0, 2.5f}, b.material(testing::lambertian()), "ceiling");
  b.pointLight({0, 2, 0}, I);
  const float half = 2.f;
  b.scene().camera = testing::orthoCamera({0, 2.5f, 0}, {0, 1, 0}, {0, 0, 1}, half, 2.f);
  Scene scene = b.build("caustics-glass-reflection");
  const int n = 64;
  RenderOutput out = renderer().render(scene, request(n, {{"cube_resolution", 512}}));
  const Image& caustics = findAov(out, "caustics");
  expectFinite(caustics);
  const float margin = 3.f * 2.f * half / n;
  const double edge = 0.5 * (3.0 - 0.4) / (1.2 - 0.4);
  int inside = 0;
  for (int py = 0; py < n; ++py)
    for (int px = 0; px < n; ++px) {
      const double x = -half + 2.0 * half * (px + 0.5) / n, z = half - 2.0 * half * (py + 0.5) / n;
      if (std::max(std::abs(x), std::abs(z)) > edge - margin) continue;
      const double h = 3.0 - 0.4, d2 = x * x + h * h + z * z, d = std::sqrt(d2);
      const double F = rt::fresnelDielectric(static_cast<float>(h / d), 1.5f);
      const double expected = I * F * (h / d) / d2 / kPi;
      EXPECT_NEAR(caustics.at(px, py)[1], expected, 0.02 * expected) << px << "," << py;
      ++inside;
    }
  EXPECT_GT(inside, 2000);
  RenderOutput off = renderer().render(scene, request(n, {{"cube_resolution", 512}, {"fresnel_reflection", false}}));
  const Image& none = findAov(off, "caustics");
  EXPECT_EQ(*std::max_element(none.pixels.begin(), none.pixels.end()), 0.f);
}

// The focus against the reference light tracer at two cube resolutions (issue 14: the focus grew
// brighter than the light tracer's as C grew). A glass sphere (R = 0.5, ior 1.5) under a directional
// light, the floor at its paraxial focus 1.5 R below the centre, seen from above (64 px over 0.5 m:
// 7.8 mm pixels). The cube's texels on the floor are 5.9 mm at C 256 and 1.5 mm at C 1024; point
// samples of a cube finer than the pixels pick the irradiance at the pixel centre instead of the
// pixel's average (the light tracer's), so a focus narrower than a pixel was hit or missed (measured
// without footprint_filter: the central 6 x 6 pixels +10% at C 256 and -14% at C 1024, and on a floor
// at 1.25 R the image sum +18% at C 1024). With the footprint filter the camera pass reads the mip
// level whose texels cover the pixel: measured, the central window is +5.5% and +6.2% against the
// light tracer's (bound 9%: the rest is the reconstruction's, steady in C), its two values within 1%
// of each other (bound 3%), the image sums within 1.6% (bound 3%), and the brightest pixel is 8-9%
// below the light tracer's (the filter spreads a peak over about 1.7 pixels; bound: within 15%, and
// never above it by more than 3%). The light tracer's own noise at 1024 paths per pixel: its sums moved
// by 0.06% at 2048.
TEST(Caustics, FocusAgreesWithTheLightTracerAtTwoCubeResolutions) {
  const float R = 0.5f;
  testing::SceneBuilder b;
  b.quad({0, 0, 0}, {0, 0, 0.6f}, {0.6f, 0, 0}, b.material(testing::lambertian()), "floor");
  b.sphere({0, 1.5f * R, 0}, R, b.material(testing::glass(1.5f)), 96, 48);
  b.directionalLight({0, -1, 0}, 1.f);
  b.topDownOrtho(0.2f * R, 0.25f);
  Scene scene = b.build("caustics-focus-vs-lt");
  const int n = 64;
  struct Sums { double image = 0, centre = 0, peak = 0; };
  auto sums = [&](const Image& img) {
    Sums s;
    for (int py = 0; py < n; ++py)
      for (int px = 0; px < n; ++px) {
        const double v = img.at(px, py)[1];
        s.image += v;
        s.peak = std::max(s.peak, v);
        if (std::abs(px - 31.5) < 3 && std::abs(py - 31.5) < 3) s.centre += v;
      }
    return s;
  };
  rt::RayScene rays(scene);
  reference::LightTracer tracer(rays);
  reference::LightTracerOptions o;
  o.pathsPerPixel = 1024;
  o.seed = 5;
  const Sums ref = sums(tracer.render(makeFrameView(scene, request(n)).camera, n, n, o));
  std::printf("light tracer: image %.1f, centre 6x6 %.1f, peak %.2f\n", ref.image, ref.centre, ref.peak);
  std::vector<Sums> ours;
  for (int C : {256, 1024}) {
    RenderOutput out = renderer().render(scene, request(n, {{"cube_resolution", C}}));
    const Image& caustics = findAov(out, "caustics");
    expectFinite(caustics);
    ours.push_back(sums(caustics));
    const Sums& s = ours.back();
    std::printf("C %d: image %.1f (%.4f), centre 6x6 %.1f (%.4f), peak %.2f (%.4f)\n", C, s.image, s.image / ref.image,
                s.centre, s.centre / ref.centre, s.peak, s.peak / ref.peak);
    EXPECT_NEAR(s.image / ref.image, 1.0, 0.03) << C;
    EXPECT_NEAR(s.centre / ref.centre, 1.0, 0.09) << C;
    EXPECT_NEAR(s.peak / ref.peak, 1.0, 0.15) << C;
    EXPECT_LT(s.peak, 1.03 * ref.peak) << C;
  }
  EXPECT_NEAR(ours[1].centre / ours[0].centre, 1.0, 0.03);
}

// A caustic seen in a mirror (the secondary lookup, LS+DS+E). Neither reference renderer samples these
// paths (the path tracer cannot reach the light through the slab, the light tracer cannot connect to
// the camera through the mirror), so the oracle is the closed form: the slab at normal incidence puts
// 0.9216 E / pi on the white floor under it (tested directly above and against the light tracer), and a
// flat mirror of F0 = 0.9 seen at 45 degrees shows it times Schlick's F(cos 45) = 0.900216. The camera
// (orthographic, along (1, -1, 0)) sees only the vertical mirror at x = 1.5, whose reflection shows the
// floor at |x| < 0.22, |z| < 0.15, inside the plateau; the direct light there is the slab's shadow and
// the mirror is edge-on to the light, so beauty is the secondary lookup alone (2% per pixel, the
// slab's 1% plus the maps' reflected rays at nearest texels). With specular_lookup false beauty is 0.
TEST(Caustics, CausticSeenInAMirrorIsTheMirrorsFresnelTimesTheCaustic) {
  const float E = 2.f, f0 = 0.9f;
  testing::SceneBuilder b;
  b.quad({0, 0, 0}, {0, 0, 3}, {3, 0, 0}, b.material(testing::lambertian()), "floor");
  b.solidBox({-0.5f, 1.0f, -0.5f}, {0.5f, 1.2f, 0.5f}, b.material(testing::glass(1.5f)), "slab");
  b.quad({1.5f, 1.5f, 0}, {0, 0, 0.6f}, {0, 0.6f, 0}, b.material(testing::mirror(glm::vec3(f0))), "mirror");  // normal -x
  b.directionalLight({0, -1, 0}, E);
  const glm::vec3 d = glm::normalize(glm::vec3(1, -1, 0));
  b.scene().camera = testing::orthoCamera(glm::vec3(1.5f, 1.5f, 0) - 2.f * d, d, {1, 1, 0}, 0.15f, 6.f);
  Scene scene = b.build("caustics-in-mirror");
  const int n = 32;
  api::RenderRequest req = request(n, {{"cube_resolution", 512}});
  req.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"beauty", "direct", "specular", "caustics"}, false}};
  RenderOutput on = renderer().render(scene, req);
  EXPECT_EQ(on.stats.lightPaths.at("LS+DS+E"), "caustics");
  EXPECT_EQ(counter(on, "caustics", "specular_lookup"), 1.0);
  const Image& beauty = findAov(on, "beauty");
  expectFinite(beauty);
  const double F = f0 + (1.0 - f0) * std::pow(1.0 - std::sqrt(0.5), 5.0);
  const double expected = F * 0.9216 * E / kPi;
  double sum = 0.0, maxDirect = 0.0, maxSpecular = 0.0, maxCaustics = 0.0;
  int off = 0;
  for (int py = 0; py < n; ++py)
    for (int px = 0; px < n; ++px) {
      const double v = beauty.at(px, py)[1];
      sum += v;
      if (std::abs(v - expected) > 0.02 * expected) ++off;
      maxDirect = std::max<double>(maxDirect, findAov(on, "direct").at(px, py)[1]);
      maxSpecular = std::max<double>(maxSpecular, findAov(on, "specular").at(px, py)[1]);
      maxCaustics = std::max<double>(maxCaustics, findAov(on, "caustics").at(px, py)[1]);
    }
  std::printf("mirror: beauty mean %.5f (expected %.5f), %d of %d pixels off by > 2%%; max direct %.2g, specular %.2g, "
              "caustics AOV %.2g\n", sum / (n * n), expected, off, n * n, maxDirect, maxSpecular, maxCaustics);
  EXPECT_EQ(off, 0);
  EXPECT_NEAR(sum / (n * n), expected, 0.01 * expected);
  EXPECT_LT(maxDirect + maxSpecular, 1e-3 * expected);
  EXPECT_EQ(maxCaustics, 0.0);  // the AOV stays L S+ D E: the camera sees no diffuse surface
  req.passes["caustics"]["specular_lookup"] = false;
  RenderOutput without = renderer().render(scene, req);
  const Image& dark = findAov(without, "beauty");
  EXPECT_EQ(counter(without, "caustics", "specular_lookup"), 0.0);
  double maxDark = 0.0;
  for (int py = 0; py < n; ++py)
    for (int px = 0; px < n; ++px) maxDark = std::max<double>(maxDark, dark.at(px, py)[1]);
  EXPECT_LT(maxDark, 1e-3 * expected);
}

// cornell_glass's floor in the glass sphere's shadow (outside its caustic) is lit by the ceiling's hot
// spot through the sphere (L D S+ D E) and by light around it. The reference's path tracer samples the
// first (floor -> glass -> ceiling -> light); the photon tracer once ended every photon at the glass, and
// the frame's floor there was at 0.50 of the reference's (128 px run, docs/PERFORMANCE.md "caustics").
// Now photons cross glass after a diffuse bounce: the region's mean beauty (photon_gi + caustics, the
// frame's defaults) against the reference at 256 spp. Bound 12%: photon_gi's kernel blurs the shadow's
// edges over h (measured 0.934 here at 48 px, 1.054 at 128 px with supersampling 2; the noise of both
// region means is ~2%).
TEST(Caustics, FloorInTheGlassSpheresShadowGetsTheCeilingsLightThroughIt) {
  Scene scene = loadBuiltinScene("cornell_glass");
  const int n = 48;
  api::RenderRequest frame;
  frame.width = frame.height = n;
  frame.seed = 1;
  frame.passes["caustics"] = nlohmann::json::object();
  frame.passes["photon_gi"] = nlohmann::json::object();
  frame.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"beauty", "caustics", "gbuffer_position"}, false}};
  RenderOutput f = renderer().render(scene, frame);
  api::RenderRequest ref;
  ref.width = ref.height = n;
  ref.seed = 5;
  ref.passes["reference"] = {{"spp", 256}};
  ref.disabledPasses.insert("photon_gi");
  ref.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"reference"}, false}};
  RenderOutput r = renderer().render(scene, ref);
  const Image& beauty = findAov(f, "beauty");
  const Image& caustics = findAov(f, "caustics");
  const Image& position = findAov(f, "gbuffer_position");
  const Image& truth = findAov(r, "reference");
  expectFinite(beauty);
  // The scene's numbers (scenes/make_scenes.py): sphere centre and radius, the point light.
  const glm::vec3 centre(0.19f, 0.17f, 0.13f), light(0.f, 0.85f, 0.f);
  const float radius = 0.17f;
  double sumFrame = 0, sumRef = 0;
  int pixels = 0;
  for (int py = 0; py < n; ++py)
    for (int px = 0; px < n; ++px) {
      const float* p = position.at(px, py);
      if (position.channels < 3 || std::abs(p[1]) > 1e-3f || caustics.at(px, py)[1] > 0.1f) continue;  // floor, no caustic
      // Does the segment from the floor point to the light pass through the sphere?
      const glm::vec3 x(p[0], p[1], p[2]);
      const glm::vec3 d = glm::normalize(light - x);
      const float b = glm::dot(x - centre, d), c = glm::dot(x - centre, x - centre) - radius * radius;
      if (b * b - c <= 0.f || -b - std::sqrt(b * b - c) <= 0.f) continue;
      sumFrame += beauty.at(px, py)[1];
      sumRef += truth.at(px, py)[1];
      ++pixels;
    }
  std::printf("floor in the sphere's shadow: %d pixels, frame mean %.4f, reference mean %.4f, ratio %.4f\n", pixels,
              sumFrame / std::max(pixels, 1), sumRef / std::max(pixels, 1), sumFrame / sumRef);
  ASSERT_GT(pixels, 20);
  EXPECT_NEAR(sumFrame / sumRef, 1.0, 0.12);
}

// The caustic cubes (steps 1 to 3 and their mips) do not depend on the camera: a frame from another
// camera reuses them (cube_cached 1) and its caustics are those of a frame that drew them (energy_check
// redraws: its sums are counters of the drawing), to float rounding; a knob of the drawing (P) or a
// change of the specular maps (another scene) draws them again.
TEST(Caustics, CubesAreDrawnOncePerSceneAndKnobsNotPerCamera) {
  Scene scene = loadBuiltinScene("cornell_glass");
  const int n = 32;
  auto frame = [&](nlohmann::json caustics, bool moved) {
    api::RenderRequest req = request(n, std::move(caustics));
    if (moved) req.camera = api::CameraOverride{{0.25f, 0.55f, 1.7f}, {0.f, 0.45f, 0.f}, {0.f, 1.f, 0.f}, 42.f};
    return renderer().render(scene, req);
  };
  RenderOutput first = frame(nlohmann::json::object(), false);
  RenderOutput moved = frame(nlohmann::json::object(), true);
  EXPECT_EQ(counter(moved, "caustics", "cube_cached"), 1.0);
  RenderOutput drawn = frame({{"energy_check", true}}, true);
  EXPECT_EQ(counter(drawn, "caustics", "cube_cached"), 0.0);
  const Image& a = findAov(moved, "caustics");
  const Image& b = findAov(drawn, "caustics");
  ASSERT_EQ(a.pixels.size(), b.pixels.size());
  double sum = 0.0, maxDiff = 0.0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i) {
    sum += b.pixels[i];
    maxDiff = std::max<double>(maxDiff, std::abs(a.pixels[i] - b.pixels[i]));
  }
  ASSERT_GT(sum, 0.0);  // the moved camera sees the caustic
  EXPECT_LE(maxDiff, 1e-5 * sum / double(a.pixels.size()) + 1e-6);
  EXPECT_EQ(counter(frame({{"photon_resolution", 64}}, true), "caustics", "cube_cached"), 0.0);
  EXPECT_EQ(counter(frame(nlohmann::json::object(), false), "caustics", "cube_cached"), 0.0);  // P changed back
  EXPECT_EQ(counter(frame(nlohmann::json::object(), true), "caustics", "cube_cached"), 1.0);
}

// The cubes live in one texture every scene draws into. A frame that draws them without caching them
// (energy_check) must not leave the texture claiming the cubes it held before: cornell_glass, then
// cornell_mirror with energy_check, then cornell_glass again used to call the glass cubes cached and
// show the mirror's caustics (FrameResources::refill: a miss empties the resource until written).
TEST(Caustics, AnUncachedDrawingLeavesTheSharedCubesHoldingNothing) {
  const Scene glass = loadBuiltinScene("cornell_glass");
  const Scene mirror = loadBuiltinScene("cornell_mirror");
  const int n = 32;
  RenderOutput first = renderer().render(glass, request(n));
  RenderOutput other = renderer().render(mirror, request(n, {{"energy_check", true}}));
  EXPECT_EQ(counter(other, "caustics", "cube_cached"), 0.0);
  RenderOutput again = renderer().render(glass, request(n));
  EXPECT_EQ(counter(again, "caustics", "cube_cached"), 0.0) << "the texture holds cornell_mirror's cubes";
  const Image& a = findAov(first, "caustics");
  const Image& b = findAov(again, "caustics");
  const Image& m = findAov(other, "caustics");
  ASSERT_EQ(a.pixels.size(), b.pixels.size());
  double sum = 0.0, maxDiff = 0.0, maxOther = 0.0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i) {
    sum += a.pixels[i];
    maxDiff = std::max<double>(maxDiff, std::abs(a.pixels[i] - b.pixels[i]));
    maxOther = std::max<double>(maxOther, std::abs(a.pixels[i] - m.pixels[i]));
  }
  ASSERT_GT(sum, 0.0);
  const double mean = sum / double(a.pixels.size());
  EXPECT_GT(maxOther, 0.1 * mean) << "the two scenes' caustics differ";
  EXPECT_LE(maxDiff, 1e-5 * mean + 1e-6) << "cornell_glass after cornell_mirror has cornell_glass's caustics";
}

// secondary_max_depth bounds step 5's trees. Every level adds paths, so only light: beauty never falls
// with the depth. On cornell_glass each level adds some (depth 1: reflections off the sphere; 2: through
// it, in and out; 3-4: internal reflections, total near the silhouette), measured 10.77 / 11.36 / 13.58
// at depth 1 / 2 / 4 (32 px, summed over the frame, whose whole beauty sums to 4124).
TEST(Caustics, SecondaryLookupAddsLightWithEveryLevelOfItsTrees) {
  Scene scene = loadBuiltinScene("cornell_glass");
  const int n = 32;
  auto beautySum = [&](nlohmann::json caustics) {
    RenderOutput out = renderer().render(scene, request(n, std::move(caustics)));
    const Image& b = findAov(out, "beauty");
    expectFinite(b);
    double sum = 0.0;
    for (float v : b.pixels) sum += v;
    return std::make_pair(sum, out.stats);
  };
  const double none = beautySum({{"specular_lookup", false}}).first;
  std::vector<double> light;
  for (int depth : {1, 2, 4}) {
    auto [sum, stats] = beautySum({{"secondary_max_depth", depth}});
    for (const auto& p : stats.passes)
      if (p.name == "caustics") { EXPECT_EQ(p.counters.at("secondary_max_depth"), depth); }
    light.push_back(sum - none);
  }
  std::printf("secondary light at depth 1 / 2 / 4: %.4f / %.4f / %.4f of a frame of %.1f\n", light[0], light[1],
              light[2], none);
  EXPECT_GT(light[0], 0.0);
  EXPECT_GT(light[1], light[0]);
  EXPECT_GT(light[2], light[1]);
  EXPECT_LT(light[2], 0.05 * none);  // a small class of the frame's light
}

}  // namespace
}  // namespace radiant
