// photon_gi on llvmpipe (Stürzlinger & Bastos 1997). Each test asserts a number fixed by the kernel
// estimate or by the reference (../shared/notes/papers-000-003.md, B5):
// - one photon of power phi on a Lambertian plane: sum_pixels L pi / rho A_pixel = phi (0.5%);
// - a constant field of N uniform photons: L = (N phi / A) rho / pi, relative noise 0.757 / C for the
//   biweight kernel; 1/2 at a straight edge and 1/4 at a right-angled corner without renormalisation,
//   1 with it;
// - splatting and gathering the same photons give the same image;
// - the built-in Cornell box against the reference path tracer (indirect and beauty), the cache of
//   photons across camera changes, refinement, scale invariance and finiteness.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>

#include <gtest/gtest.h>

#include "renderer/frame/FrameResources.h"
#include "renderer/frame/FrameView.h"
#include "renderer/frame/GpuScene.h"
#include "renderer/frame/PassContext.h"
#include "renderer/scene/BuiltinScenes.h"
#include "renderer/techniques/gbuffer/GBuffer.h"
#include "renderer/techniques/photon_gi/PhotonGi.h"
#include "renderer/techniques/photon_gi/Splatting.h"
#include "renderer/shading/PhotonGrid.h"
#include "tests/support/RenderTestSupport.h"
#include "tests/support/SceneBuilder.h"

namespace radiant {
namespace {

using photon_gi::GpuSplat;
using photon_gi::SplatSettings;
using testing::aov;
using testing::pass;
using testing::renderer;

// A G-buffer of `scene` from its own camera, and the photon_gi splatting stage fed with test photons.
class SplatHarness {
public:
  SplatHarness(const Scene& scene, int size) : scene_(scene) {
    renderer();  // creates the EGL context and makes it current
    gpu_ = std::make_unique<GpuScene>(scene_);
    api::RenderRequest r;
    r.width = r.height = size;
    view_ = makeFrameView(scene_, r);
    res_.beginFrame(*gpu_, view_, nullptr);
    // What the Renderer allocates before any pass (renderer/frame/FrameAllocation.h): the declared outputs.
    res_.texture("indirect", GL_TEXTURE_2D, GL_RGBA32F, size, size);
    res_.texture("beauty", GL_TEXTURE_2D, GL_RGBA32F, size, size);
    api::PassStats stats;
    Params params;
    gbuffer_.prepare(scene_, params, res_);
    PassContext ctx{scene_, *gpu_, view_, params, res_, shaders_, stats};
    gbuffer_.execute(ctx);
  }
  // The `indirect` image (RGB, row 0 = top) for these splats.
  Image run(std::vector<GpuSplat> splats, const SplatSettings& settings) {
    const photon_gi::SplatGrid grid = photon_gi::buildSplatGrid(std::move(splats));
    photon_gi::declareSplatResources(res_, grid, settings, true);
    photon_gi::splatAndResolve(res_, shaders_, view_, settings, grid, true, false);
    std::vector<float> rgba(static_cast<std::size_t>(view_.width) * view_.height * 4);
    res_.texture("indirect").download(0, GL_RGBA, GL_FLOAT, rgba.data(), rgba.size() * sizeof(float));
    Image img = Image::make("indirect", view_.width, view_.height, 3);
    for (int y = 0; y < view_.height; ++y)
      for (int x = 0; x < view_.width; ++x)
        for (int c = 0; c < 3; ++c)
          img.at(x, y)[c] = rgba[(static_cast<std::size_t>(view_.height - 1 - y) * view_.width + x) * 4 + c];
    return img;
  }
  const FrameView& view() const { return view_; }

private:
  Scene scene_;
  gl::ShaderLibrary shaders_;
  FrameResources res_{shaders_};
  std::unique_ptr<GpuScene> gpu_;
  FrameView view_;
  GBufferPass gbuffer_;
};

constexpr float kRho = 0.5f;
constexpr float kHalf = 1.f;        // the plane is [-1, 1]^2 in x, z (area 4)
constexpr float kViewHalf = 1.25f;  // the camera sees [-1.25, 1.25]^2
constexpr int kSize = 128;

Scene plane() {
  testing::SceneBuilder b;
  const int m = b.material(testing::lambertian(glm::vec3(kRho)));
  b.quad(glm::vec3(0.f), {kHalf, 0, 0}, {0, 0, -kHalf}, m, "plane");  // faces +y
  b.topDownOrtho(2.f, kViewHalf);
  return b.build();
}

SplatSettings settings(photon_gi::Method method, bool renormalize) {
  SplatSettings s;
  s.method = method;
  s.renormalize = renormalize;
  return s;
}

double pixelArea() { return std::pow(2.0 * kViewHalf / kSize, 2); }

TEST(PhotonGi, SinglePhotonDepositsItsPower) {
  // Sum over pixels of L pi / rho A_pixel = phi k-integral = phi: catches eq. 2's 1/h (must be 1/h^2).
  SplatHarness h(plane(), kSize);
  const float phi = 3.f;
  for (auto method : {photon_gi::Method::Splat, photon_gi::Method::Gather})
    for (float radius : {0.15f, 0.4f}) {
      const Image img = h.run({photon_gi::photonSplat(glm::vec3(0.1f, 0.f, -0.2f), radius, glm::vec3(0, 1, 0),
                                                     glm::vec3(0, 1, 0), glm::vec3(phi))},
                              settings(method, false));
      double sum = 0.0;
      for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) sum += img.at(x, y)[0];
      EXPECT_NEAR(sum * M_PI / kRho * pixelArea(), phi, 0.005 * phi)
          << (method == photon_gi::Method::Splat ? "splat" : "gather") << ", h = " << radius;
    }
}

TEST(PhotonGi, DiffuseOnlyPhotonsLeaveTheGlossyLobeToItsOwner) {
  // A photon flagged diffuse-only (a sky photon whose glossy reflection `direct`'s prefiltered
  // environment owns) adds nothing to a metal, and the same photon unflagged adds its glossy lobe.
  testing::SceneBuilder b;
  Material metal = testing::lambertian(glm::vec3(0.9f));
  metal.metallicFactor = 1.f;
  metal.roughnessFactor = 0.5f;
  const int m = b.material(metal);
  b.quad(glm::vec3(0.f), {kHalf, 0, 0}, {0, 0, -kHalf}, m, "metal");
  b.topDownOrtho(2.f, kViewHalf);
  SplatHarness h(b.build(), 64);
  double sums[2] = {0, 0};
  for (int flagged = 0; flagged < 2; ++flagged) {
    const Image img = h.run({photon_gi::photonSplat(glm::vec3(0.f), 0.4f, glm::vec3(0, 1, 0), glm::vec3(0, 1, 0),
                                                   glm::vec3(1.f), flagged == 1)},
                            settings(photon_gi::Method::Gather, false));
    for (float v : img.pixels) sums[flagged] += v;
  }
  EXPECT_GT(sums[0], 1.0);
  EXPECT_EQ(sums[1], 0.0);
}

struct FieldStats {
  double interior = 0, interiorStd = 0;
  double edge = 0, edgeExpected = 0;      // mean over pixels within a pixel of the edge x = +1
  double corner = 0, cornerExpected = 0;  // mean over the pixels nearest to the four corners
};

// Fraction of the biweight kernel's mass (radius 1) at (0, 0) that lies in x < a, z < b (midpoint
// quadrature): what an unrenormalised estimate gives, relative to the interior, at a pixel a and b
// kernel radii inside a corner (b large: an edge).
double biweightMassInside(double a, double b) {
  const int n = 600;
  double inside = 0, all = 0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double x = -1 + (i + 0.5) * 2.0 / n, z = -1 + (j + 0.5) * 2.0 / n;
      const double r2 = x * x + z * z;
      if (r2 >= 1) continue;
      const double k = (1 - r2) * (1 - r2);
      all += k;
      if (x < a && z < b) inside += k;
    }
  return inside / all;
}

// Photons uniform on the plane, all arriving along the normal, each of power phi.
FieldStats constantField(SplatHarness& h, int n, float C, photon_gi::Method method, bool renormalize, Image* out = nullptr,
                         bool ppm = false, double ppmBase = 0.0) {
  const double area = 4.0;
  const float radius = PhotonGiPass::kernelRadius(C, area, n, ppm, n, ppmBase, 2.0 / 3.0);  // eq. 3 (or progressive)
  const float phi = 1.f;
  std::mt19937 rng(12345);
  std::uniform_real_distribution<float> u(-kHalf, kHalf);
  std::vector<GpuSplat> splats;
  for (int i = 0; i < n; ++i)
    splats.push_back(photon_gi::photonSplat(glm::vec3(u(rng), 0.f, u(rng)), radius, glm::vec3(0, 1, 0),
                                            glm::vec3(0, 1, 0), glm::vec3(phi)));
  if (renormalize) {
    testing::SceneBuilder b;
    b.quad(glm::vec3(0.f), {kHalf, 0, 0}, {0, 0, -kHalf}, 0, "plane");
    const Scene s = b.build();
    photon_gi::appendCoveragePoints(s.meshes[0], static_cast<std::size_t>(64 * area / (M_PI * radius * radius)), radius,
                                    splats);
  }
  const Image img = h.run(std::move(splats), settings(method, renormalize));
  if (out) *out = img;
  const double expected = n * phi / area * kRho / M_PI;
  FieldStats f;
  double sum = 0, sum2 = 0;
  int count = 0, edgeCount = 0;
  const int size = img.width;
  const float pixel = 2.f * kViewHalf / size;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const glm::vec2 p = testing::topDownPixelToWorld(x, y, size, kViewHalf);
      const double v = img.at(x, y)[0] / expected;
      const float dx = kHalf - std::abs(p.x), dz = kHalf - std::abs(p.y);
      if (dx > radius && dz > radius) { sum += v; sum2 += v * v; ++count; }
      // Pixels whose centre is within a pixel of the edge x = +1, at least h from the other edges.
      if (p.x > 0 && dx > 0 && dx < pixel && dz > radius) {
        f.edge += v;
        f.edgeExpected += renormalize ? 1.0 : biweightMassInside(dx / radius, 2.0);
        ++edgeCount;
      }
    }
  f.interior = sum / count;
  f.interiorStd = std::sqrt(std::max(0.0, sum2 / count - f.interior * f.interior));
  f.edge /= edgeCount;
  f.edgeExpected /= edgeCount;
  // Each corner: the pixel whose centre is nearest to it from inside.
  for (glm::vec2 corner : {glm::vec2(1, 1), glm::vec2(-1, 1), glm::vec2(1, -1), glm::vec2(-1, -1)}) {
    int cx = 0, cy = 0;
    float best = 1e9f;
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x) {
        const glm::vec2 p = testing::topDownPixelToWorld(x, y, size, kViewHalf);
        if (std::abs(p.x) >= kHalf || std::abs(p.y) >= kHalf) continue;
        const float d = glm::length(corner * kHalf - p);
        if (d < best) { best = d; cx = x; cy = y; }
      }
    const glm::vec2 p = testing::topDownPixelToWorld(cx, cy, size, kViewHalf);
    f.corner += img.at(cx, cy)[0] / expected / 4;
    f.cornerExpected += (renormalize ? 1.0
                                     : biweightMassInside((kHalf - std::abs(p.x)) / radius, (kHalf - std::abs(p.y)) / radius)) /
                        4;
  }
  return f;
}

TEST(PhotonGi, ConstantFieldMeanNoiseEdgesAndCorners) {
  SplatHarness h(plane(), kSize);
  for (float C : {10.f, 20.f}) {
    const int n = static_cast<int>(4.0 * C * C / (0.25 * 0.25));  // h = 0.25
    const FieldStats f = constantField(h, n, C, photon_gi::Method::Splat, false);
    // Mean: the estimator is unbiased for a constant field (to the pixel's distance from the photons).
    EXPECT_NEAR(f.interior, 1.0, 0.02) << "C = " << C;
    // Noise floor sqrt(int k^2) / C = 0.757 / C for the biweight, whatever N is (+-20%).
    EXPECT_NEAR(f.interiorStd, 0.757 / C, 0.2 * 0.757 / C) << "C = " << C;
    // Without renormalisation half the kernel hangs over a straight edge and three quarters over a
    // corner: 1/2 and 1/4 exactly at the boundary. The pixel centres are up to a pixel (h / 13) inside,
    // so the expected values are the kernel mass inside at each pixel (quadrature), 0.52-0.56 and
    // 0.26-0.3; the tolerance is 2.5 sigma of the photon noise at the edge.
    std::printf("C %.0f: interior %.4f, noise %.4f (0.757/C = %.4f), edge %.3f (expected %.3f), corner %.3f (%.3f)\n", C,
                f.interior, f.interiorStd, 0.757 / C, f.edge, f.edgeExpected, f.corner, f.cornerExpected);
    EXPECT_NEAR(f.edgeExpected, 0.5, 0.07);
    EXPECT_NEAR(f.edge, f.edgeExpected, 0.05) << "C = " << C;
    EXPECT_NEAR(f.cornerExpected, 0.25, 0.06);
    EXPECT_NEAR(f.corner, f.cornerExpected, 0.05) << "C = " << C;
  }
  const FieldStats r = constantField(h, static_cast<int>(4.0 * 400 / 0.0625), 20.f, photon_gi::Method::Splat, true);
  std::printf("renormalised: interior %.4f, edge %.3f, corner %.3f\n", r.interior, r.edge, r.corner);
  EXPECT_NEAR(r.interior, 1.0, 0.02);
  EXPECT_NEAR(r.edge, 1.0, 0.06);
  EXPECT_NEAR(r.corner, 1.0, 0.1);
}

TEST(PhotonGi, PaperRadiusHasANoiseFloorProgressiveRadiusDoesNot) {
  // Eq. 3 keeps pi C^2 photons per kernel whatever N is: the relative noise stays 0.757 / C. With
  // h_schedule = ppm, h^2 grows by (N / N0)^alpha, so the photons per kernel grow as N^alpha and the noise
  // falls as N^(-alpha/2): 4x the photons give 4^(-1/3) = 0.63 of the noise (alpha = 2/3).
  EXPECT_NEAR(PhotonGiPass::kernelRadius(30.f, 4.0, 900.0, false, 0, 0, 0), 2.0, 1e-6);
  EXPECT_NEAR(PhotonGiPass::kernelRadius(30.f, 4.0, 900.0, true, 8000.0, 1000.0, 2.0 / 3.0), 2.0 * 2.0, 1e-5);
  SplatHarness h(plane(), kSize);
  const int n = 6000;
  const FieldStats paper1 = constantField(h, n, 10.f, photon_gi::Method::Gather, false);
  const FieldStats paper4 = constantField(h, 4 * n, 10.f, photon_gi::Method::Gather, false);
  const FieldStats ppm1 = constantField(h, n, 10.f, photon_gi::Method::Gather, false, nullptr, true, n);
  const FieldStats ppm4 = constantField(h, 4 * n, 10.f, photon_gi::Method::Gather, false, nullptr, true, n);
  std::printf("noise: paper %.4f -> %.4f, ppm %.4f -> %.4f\n", paper1.interiorStd, paper4.interiorStd, ppm1.interiorStd,
              ppm4.interiorStd);
  EXPECT_NEAR(paper4.interiorStd / paper1.interiorStd, 1.0, 0.15);
  EXPECT_NEAR(ppm4.interiorStd / ppm1.interiorStd, std::pow(4.0, -1.0 / 3.0), 0.1);
  EXPECT_NEAR(ppm4.interior, 1.0, 0.02);
}

TEST(PhotonGi, SplatAndGatherAgreeOnTheSamePhotons) {
  SplatHarness h(plane(), kSize);
  Image a, b;
  constantField(h, 20000, 15.f, photon_gi::Method::Splat, true, &a);
  constantField(h, 20000, 15.f, photon_gi::Method::Gather, true, &b);
  double maxRel = 0.0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i)
    maxRel = std::max(maxRel, std::abs(double(a.pixels[i]) - b.pixels[i]) / (std::abs(double(b.pixels[i])) + 1e-3));
  EXPECT_LT(maxRel, 1e-3);  // float summation order only
}

TEST(PhotonGi, GatherSeesEveryPhotonWhenACellHoldsMoreThan65536) {
  // Large kernels make cells large: here every pixel's 27 cells hold all 80000 photons. llvmpipe ends a
  // single shader loop after 65535 iterations without a word; the gather must still see every photon.
  SplatHarness h(plane(), 16);
  Image a, b;
  constantField(h, 80000, 200.f, photon_gi::Method::Splat, false, &a);
  constantField(h, 80000, 200.f, photon_gi::Method::Gather, false, &b);
  double sa = 0, sb = 0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i) { sa += a.pixels[i]; sb += b.pixels[i]; }
  EXPECT_GT(sa, 0.0);
  EXPECT_NEAR(sb / sa, 1.0, 1e-3);
}

// The CPU walk of photon_gi/grid.glsl over grid g: the 27 cells around each query point's own, less the
// neighbours farther from the point than g.walkReach. It must meet every splat that reaches the point
// exactly once: a miss loses light, a second meeting counts it twice. Returns the (point, splat) pairs
// within reach; `skipped` counts the neighbour cells the reach test left out.
struct WalkCheck {
  int reached = 0, reachedWide = 0;
  std::size_t skipped = 0;
};
WalkCheck checkGridWalk(const photon_gi::SplatGrid& g, const std::vector<GpuSplat>& originals, std::mt19937& rng) {
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  const float reachScale = std::sqrt(1.f + kPhotonPlaneTolerance * kPhotonPlaneTolerance);
  WalkCheck w;
  for (int q = 0; q < 3000; ++q) {
    // Half the points anywhere (and beyond the splats' bounds), half near a splat, at up to 1.1 reaches.
    glm::vec3 x(1.1f * u(rng), 1.1f * u(rng), 1.1f * u(rng));
    if (q % 2 == 1) {
      const GpuSplat& s = originals[std::size_t(0.5f * (u(rng) + 1.f) * float(originals.size() - 1))];
      x = glm::vec3(s.positionRadius) + 0.64f * s.positionRadius.w * reachScale * glm::vec3(u(rng), u(rng), u(rng));
    }
    std::map<int, int> met;  // splat -> meetings within its reach
    const glm::ivec3 c = glm::ivec3(glm::floor((x - g.origin) / g.cellSize));
    for (int k = 0; k < 27; ++k) {
      const glm::ivec3 cell = c + glm::ivec3(k % 3, (k / 3) % 3, k / 9) - 1;
      if (glm::any(glm::lessThan(cell, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(cell, g.dims))) continue;
      const glm::vec3 lo = g.origin + glm::vec3(cell) * g.cellSize;
      const glm::vec3 gap = glm::max(glm::max(lo - x, x - (lo + g.cellSize)), glm::vec3(0.f));
      if (glm::dot(gap, gap) > g.walkReach * g.walkReach) {
        ++w.skipped;
        continue;
      }
      const std::size_t index = (std::size_t(cell.z) * g.dims.y + cell.y) * g.dims.x + cell.x;
      for (std::uint32_t e = g.cellStart[index]; e < g.cellStart[index + 1]; ++e) {
        const GpuSplat& s = g.splats[e];
        if (glm::length(x - glm::vec3(s.positionRadius)) < s.positionRadius.w * reachScale) ++met[int(s.power.r)];
      }
    }
    for (std::size_t i = 0; i < originals.size(); ++i) {
      const GpuSplat& s = originals[i];
      const bool reaches = glm::length(x - glm::vec3(s.positionRadius)) < s.positionRadius.w * reachScale;
      const auto it = met.find(int(i));
      const int meetings = it == met.end() ? 0 : it->second;
      w.reached += reaches;
      w.reachedWide += reaches && s.positionRadius.w >= 0.1f;
      if (meetings != (reaches ? 1 : 0)) {
        ADD_FAILURE() << "splat " << i << " (h " << s.positionRadius.w << ") met " << meetings << " times at a point it "
                      << (reaches ? "reaches" : "does not reach");
        return w;
      }
    }
  }
  return w;
}

// The gather grid with kernels of very different sizes (Splatting.h buildSplatGrid): cells follow the
// small kernels and the wide ones are copied every third cell across their reach; the walk cannot skip
// a neighbour cell then (a copy lies away from its splat).
TEST(PhotonGi, GridWalkMeetsEverySplatThatReachesAPointExactlyOnce) {
  std::mt19937 rng(31);
  std::uniform_real_distribution<float> u(-1.f, 1.f), small(0.02f, 0.05f), wide(0.1f, 0.2f);
  std::vector<GpuSplat> splats;
  for (int i = 0; i < 4000; ++i) {
    const float h = i % 50 == 0 ? wide(rng) : small(rng);
    GpuSplat s = photon_gi::photonSplat(glm::vec3(u(rng), u(rng), u(rng)), h, glm::vec3(0, 1, 0), glm::vec3(0, 1, 0),
                                        glm::vec3(float(i)));  // the power names the splat
    splats.push_back(s);
  }
  const std::vector<GpuSplat> originals = splats;
  const photon_gi::SplatGrid g = photon_gi::buildSplatGrid(splats);
  const float reachScale = std::sqrt(1.f + kPhotonPlaneTolerance * kPhotonPlaneTolerance);
  EXPECT_EQ(g.originals, originals.size());
  EXPECT_GT(g.count, g.originals);                          // the wide kernels were copied
  EXPECT_LE(g.count, 4 * g.originals);                      // copies at most 3x the splats
  EXPECT_LT(g.cellSize, 0.1f * reachScale);                 // cells follow the small kernels
  EXPECT_TRUE(std::isinf(g.walkReach));                     // no neighbour is skipped
  std::size_t flaggedCopies = 0;
  for (const GpuSplat& s : g.splats) flaggedCopies += (s.wiFlags & photon_gi::kSplatCopy) != 0;
  EXPECT_EQ(flaggedCopies, g.count - g.originals);          // the splat method draws each once
  const WalkCheck w = checkGridWalk(g, originals, rng);
  EXPECT_GT(w.reached, 1500);  // the walk was asked about many splats, wide (copied) and small
  EXPECT_GT(w.reachedWide, 300);
  EXPECT_EQ(w.skipped, 0u);
  std::printf("grid: cell %.4f, %zu entries for %zu splats; %d (point, splat) pairs within reach, %d of a wide one\n",
              g.cellSize, g.count, g.originals, w.reached, w.reachedWide);
}

// Kernels of similar sizes: every splat is stored once, in a cell at least its reach wide, and the walk
// skips the neighbour cells farther than the widest reach from the point (grid.glsl u_walkReach): on
// kernels of 0.6-1 of the cell's reach, about a fifth of them, and it still meets every splat exactly once.
TEST(PhotonGi, GridWalkSkipsNeighboursBeyondTheWidestReach) {
  std::mt19937 rng(37);
  std::uniform_real_distribution<float> u(-1.f, 1.f), radius(0.03f, 0.05f);
  std::vector<GpuSplat> splats;
  for (int i = 0; i < 4000; ++i)
    splats.push_back(photon_gi::photonSplat(glm::vec3(u(rng), u(rng), u(rng)), radius(rng), glm::vec3(0, 1, 0),
                                            glm::vec3(0, 1, 0), glm::vec3(float(i))));
  const std::vector<GpuSplat> originals = splats;
  const photon_gi::SplatGrid g = photon_gi::buildSplatGrid(splats);
  const float reachScale = std::sqrt(1.f + kPhotonPlaneTolerance * kPhotonPlaneTolerance);
  ASSERT_EQ(g.count, g.originals);  // no copies
  EXPECT_GE(g.walkReach, 0.05f * 0.999f * reachScale);
  EXPECT_LE(g.walkReach, g.cellSize * 1.0001f);  // positions lie inside their cells
  const WalkCheck w = checkGridWalk(g, originals, rng);
  EXPECT_GT(w.reached, 1500);
  EXPECT_GT(w.skipped, 3000u * 27u / 10u);  // more than a tenth of the neighbours
  std::printf("grid: cell %.4f, reach %.4f; %d pairs within reach, %zu of %d neighbour cells skipped\n", g.cellSize,
              g.walkReach, w.reached, w.skipped, 3000 * 27);
}

// The same on the GPU: splatting (originals only) and gathering (copies met once) agree when a few
// wide kernels are copied across the grid.
TEST(PhotonGi, SplatAndGatherAgreeWithCopiedWideKernels) {
  SplatHarness h(plane(), 64);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-kHalf, kHalf);
  std::vector<GpuSplat> splats;
  for (int i = 0; i < 6000; ++i)
    splats.push_back(photon_gi::photonSplat(glm::vec3(u(rng), 0.f, u(rng)), i % 40 == 0 ? 0.2f : 0.06f,
                                            glm::vec3(0, 1, 0), glm::vec3(0, 1, 0), glm::vec3(1.f)));
  ASSERT_GT(photon_gi::buildSplatGrid(splats).count, splats.size());  // copies were made
  const Image a = h.run(splats, settings(photon_gi::Method::Splat, false));
  const Image b = h.run(splats, settings(photon_gi::Method::Gather, false));
  double maxRel = 0.0, sum = 0.0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i) {
    maxRel = std::max(maxRel, std::abs(double(a.pixels[i]) - b.pixels[i]) / (std::abs(double(b.pixels[i])) + 1e-3));
    sum += b.pixels[i];
  }
  EXPECT_GT(sum, 0.0);
  EXPECT_LT(maxRel, 1e-3);  // float summation order only
}

// ---- The technique on whole scenes --------------------------------------------------------------

double mean(const Image& img) {
  double s = 0;
  for (float v : img.pixels) s += v;
  return s / img.pixels.size();
}

TEST(PhotonGi, IntegratingSphereSplatsOnlyIndirectLight) {
  // A point light of power Phi = 4 pi I at the centre of a closed sphere of albedo rho = 1/2 (f0 = 0,
  // so the glTF dielectric reflects 0.500 at every angle, tests/unit/raytracing): bounce k carries
  // Phi rho^k, so the indirect irradiance (k >= 1, the bounce filter) is Phi rho / (1 - rho) / A = Phi / A
  // and a wall seen from the centre has L = rho / pi Phi / A. The direct light (bounce 0, Phi / A) must
  // not be splatted: it would double L.
  testing::SceneBuilder b;
  Material m = testing::lambertian(glm::vec3(0.5f));
  m.doubleSided = true;
  const int mat = b.material(m);
  b.sphere(glm::vec3(0.f), 1.f, mat, 64, 32);
  b.pointLight(glm::vec3(0.f), 1.f);
  Scene scene = b.build("integrating-sphere");
  const double area = photon_gi::meshArea(scene.meshes[0]);
  api::RenderRequest r;
  r.width = r.height = 32;
  r.camera = api::CameraOverride{{0.f, 0.f, 0.f}, {0.f, 0.f, -1.f}, {0.f, 1.f, 0.f}, 60.f};
  r.passes["photon_gi"] = {{"photons", 400000}, {"max_bounces", 30}, {"C", 20}};
  r.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"indirect"}, false}};
  const RenderOutput out = renderer().render(scene, r);
  const double expected = 0.5 / M_PI * (4 * M_PI) / area;
  std::printf("integrating sphere: L_indirect %.4f, expected %.4f\n", mean(aov(out, "indirect")), expected);
  EXPECT_NEAR(mean(aov(out, "indirect")), expected, 0.03 * expected);
}

// ---- The technique on the built-in Cornell box ---------------------------------------------------

api::RenderRequest cornellRequest(int size, nlohmann::json params = nlohmann::json::object()) {
  api::RenderRequest r;
  r.width = r.height = size;
  for (const auto& [key, value] : params.items()) r.explicitParams["photon_gi"].insert(key);  // as the parser does
  r.passes["photon_gi"] = std::move(params);
  r.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"beauty", "direct", "indirect"}, false}};
  return r;
}

TEST(PhotonGi, CornellBoxIndirectAndBeautyAgainstTheReference) {
  const Scene scene = loadBuiltinScene("cornell_box");
  api::RenderRequest r = cornellRequest(48, {{"photons", 500000}});
  r.compare = api::CompareSpec{"reference", "indirect", 512};
  const RenderOutput out = renderer().render(scene, r);
  const api::PassStats* p = pass(out, "photon_gi");
  ASSERT_NE(p, nullptr);
  std::printf("GL renderer %s; photon_gi %.0f ms CPU (trace %.0f ms), rmse %.4f vs reference indirect\n",
              out.stats.device.at("renderer").c_str(), p->cpuMs, p->counters.at("trace_ms"),
              out.stats.metrics["rmse"].get<double>());
  // Energy: every indirect path counted once. The mean indirect radiance over the frame agrees with
  // the reference's bounces 2.. within 4% (the reference's own noise at 512 spp is ~1% of the mean;
  // the kernel blurs light from the bright ceiling spot, edges are renormalised).
  const double ours = mean(aov(out, "indirect")), truth = mean(aov(out, "reference"));
  EXPECT_NEAR(ours / truth, 1.0, 0.04);
  // Per pixel: RMSE measured 0.16 at 48 px, most of it the reference's own noise at 512 spp (the
  // bright ceiling spot makes its indirect light noisy) and edge pixels that the raster G-buffer does
  // not anti-alias. 0.2 fails for double counting (RMSE > 1), a 1/h kernel or a lost bounce.
  EXPECT_LT(out.stats.metrics["rmse"].get<double>(), 0.2);

  api::RenderRequest rb = cornellRequest(48, {{"photons", 500000}});
  rb.compare = api::CompareSpec{"reference", "beauty", 512};
  const RenderOutput beauty = renderer().render(scene, rb);
  EXPECT_NEAR(mean(aov(beauty, "beauty")) / mean(aov(beauty, "reference")), 1.0, 0.04);
  EXPECT_EQ(testing::cacheEvent(beauty, "photon_gi_photons"), 1);  // same photons, re-splatted
  for (const auto& pass : beauty.stats.passes) EXPECT_EQ(pass.counters.count("non_finite_pixels_zeroed"), 0u);
}

TEST(PhotonGi, LayeredMaterialsReceiveIndirectLightAsTheReference) {
  // The Cornell box with every surface under KHR_materials_sheen (a white sheen over the walls'
  // colours), a clear coat of roughness 0.4 (above min_glossy_roughness: photons estimate its lobe) and
  // KHR_materials_specular at half weight. The photon tracer scatters with the shared BSDF
  // (rt::GltfBsdf, layers included); the splats must evaluate the same layered BSDF at the receiver
  // (photon.glsl), or the frame's indirect light misses the sheen's reflection and the coat's (measured
  // 0.831 of the reference with the base-only receiver; 0.986 with the layers). Bound: 5%, the plain
  // box's 4% plus the
  // coat's glossy lobe blurred by the kernel (GlossyBoxIndirectAgainstTheReference).
  Scene scene = loadBuiltinScene("cornell_box");
  for (Material& m : scene.materials) {
    if (m.isEmissive()) continue;
    m.sheenColorFactor = glm::vec3(0.8f);
    m.sheenRoughnessFactor = 0.4f;
    m.clearcoatFactor = 1.f;
    m.clearcoatRoughnessFactor = 0.4f;
    m.specularFactor = 0.5f;
  }
  scene.digest = "sha256:layered-cornell-box";
  api::RenderRequest r = cornellRequest(48, {{"photons", 500000}});
  r.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"indirect"}, false}};
  r.compare = api::CompareSpec{"reference", "indirect", 512};
  const RenderOutput out = renderer().render(scene, r);
  const double ours = mean(aov(out, "indirect")), truth = mean(aov(out, "reference"));
  std::printf("layered Cornell box: photon_gi / reference indirect = %.3f, rmse %.4f\n", ours / truth,
              out.stats.metrics["rmse"].get<double>());
  EXPECT_NEAR(ours / truth, 1.0, 0.05);
}

// Block gathering against the full gather with the same (cached) photons: the frame's light within 1%,
// no pixel left dark where the full gather has light, and the error against the reference's indirect
// no more than errorBound times the full gather's (what the knob trades).
void expectBlockGatherKeepsTheLight(int gatherStep, double errorBound = 1.05) {
  const Scene scene = loadBuiltinScene("cornell_box");
  api::RenderRequest full = cornellRequest(64, {{"photons", 200000}, {"gather_step", 1}});
  full.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"indirect"}, false}};
  full.compare = api::CompareSpec{"reference", "indirect", 256};
  api::RenderRequest blocks = full;
  blocks.passes["photon_gi"]["gather_step"] = gatherStep;
  blocks.explicitParams["photon_gi"].insert("gather_step");
  const RenderOutput a = renderer().render(scene, full);
  const RenderOutput b = renderer().render(scene, blocks);
  const Image& ia = aov(a, "indirect");
  const Image& ib = aov(b, "indirect");
  EXPECT_NEAR(mean(ib) / mean(ia), 1.0, 0.01);
  const double m = mean(ia);
  int dark = 0;
  for (std::size_t i = 0; i < ia.pixels.size(); ++i) {
    ASSERT_TRUE(std::isfinite(ib.pixels[i]));
    if (ia.pixels[i] > 0.05 * m && ib.pixels[i] == 0.f) ++dark;
  }
  EXPECT_EQ(dark, 0);
  const double ra = a.stats.metrics["rmse"].get<double>(), rb = b.stats.metrics["rmse"].get<double>();
  std::printf("indirect rmse vs reference: gather_step 1 %.4f, %d %.4f; mean ratio %.4f\n", ra, gatherStep, rb,
              mean(ib) / mean(ia));
  EXPECT_LT(rb, errorBound * ra);
}

TEST(PhotonGi, GatherStepSpreadsBlockSamplesWithoutLosingLight) {
  // gather_step 2 gathers one pixel per 2x2 block and spreads it over the block's pixels on the same
  // surface; pixels with no such sample get their own gather. Measured rmse 0.2056 (step 1) and 0.2051
  // at 64 px, where a block is 2/3 of the kernel radius (against the compare truth's own seed).
  expectBlockGatherKeepsTheLight(2);
}

// gather_step 4 runs the fix-up cascade (Splatting.cpp): pixels without a matching step-4 block sample
// try step-2 samples taken at marked block centres before the full gather (after the neighbour fill,
// upsample.comp u_refine = 2). Measured 0.2056 against 0.2056, mean ratio 1.0002 (0.2055, 1.0004 with
// the neighbour fill); 2026-12-06: 0.1944 against 0.2011 (ratio 1.034), and with the low-discrepancy
// photons (rt::Sampler::lowDiscrepancy) 0.1948 against 0.2047 (1.051), mean ratio 1.0029: a bound of
// 1.07 here (the reference's own noise at 256 spp is most of both errors).
TEST(PhotonGi, GatherStepFourCascadesItsFixUpsWithoutLosingLight) { expectBlockGatherKeepsTheLight(4, 1.07); }

// gather_step counts output pixels: on a frame supersampled k = 2 the gather takes one sample per
// 2k x 2k block of the supersampled image (the counter reports the step in those pixels, 4), so it
// gathers as many block samples as at k = 1. The error against the reference's indirect is not above
// 1.05 times k = 1's (measured 0.1909 against 0.2139 at 48 px; 0.1899 against 0.2170 with the
// neighbour fill, which gives most of k = 2's unmatched edge samples a matched neighbour's estimate:
// the pixel's samples average its surfaces as the reference does).
TEST(PhotonGi, GatherStepCountsOutputPixelsWhenSupersampled) {
  const Scene scene = loadBuiltinScene("cornell_box");
  api::RenderRequest one = cornellRequest(48, {{"photons", 200000}, {"gather_step", 2}});
  one.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"indirect"}, false}};
  one.compare = api::CompareSpec{"reference", "indirect", 256};
  api::RenderRequest two = one;
  two.supersampling = 2;
  const RenderOutput a = renderer().render(scene, one);
  const RenderOutput b = renderer().render(scene, two);
  EXPECT_EQ(b.stats.supersampling, 2);
  EXPECT_EQ(pass(a, "photon_gi")->counters.at("gather_step"), 2.0);
  EXPECT_EQ(pass(b, "photon_gi")->counters.at("gather_step"), 4.0);
  const double ma = mean(aov(a, "indirect")), mb = mean(aov(b, "indirect")), mr = mean(aov(a, "reference"));
  const double ra = a.stats.metrics["rmse"].get<double>(), rb = b.stats.metrics["rmse"].get<double>();
  std::printf("indirect mean: k = 1 %.5f, k = 2 %.5f, reference %.5f; rmse vs reference: k = 1 %.4f, k = 2 %.4f\n",
              ma, mb, mr, ra, rb);
  // Energy: the supersampled frame's mean is the reference's (measured within 0.2%, 0.4% with the
  // neighbour fill: 0.9693 against 0.9658; bound 1%, the
  // photon noise of the mean); k = 1's is 2.2% low at 48 px, where one sample per pixel misses the
  // box's edges. So k = 2 is no farther from the reference's mean than k = 1, and within 3% of it.
  EXPECT_NEAR(mb / mr, 1.0, 0.01);
  EXPECT_LE(std::abs(mb - mr), std::abs(ma - mr));
  EXPECT_NEAR(mb / ma, 1.0, 0.03);
  EXPECT_LT(rb, 1.05 * ra);
}

// Without a gather_step of its own, a supersampled frame's step is one output pixel in 64 of its size,
// 2 to 4 (PhotonGi.cpp): 2 at 128 px, 4 at 256 px; a request's own step is run as asked. At 256 px the
// wider block gives the light of step 2 (the validated default) on the same photons, pixel by pixel
// within the photon noise's scale.
TEST(PhotonGi, DefaultGatherBlockGrowsWithTheFrame) {
  const Scene scene = loadBuiltinScene("cornell_box");
  api::RenderRequest asked = cornellRequest(256, {{"gather_step", 2}});
  asked.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"indirect"}, false}};
  asked.supersampling = 2;
  api::RenderRequest adaptive = cornellRequest(256);
  adaptive.outputs = asked.outputs;
  adaptive.supersampling = 2;
  const RenderOutput a = renderer().render(scene, asked);
  const RenderOutput b = renderer().render(scene, adaptive);
  EXPECT_EQ(pass(a, "photon_gi")->counters.at("gather_step"), 4.0);
  EXPECT_EQ(pass(b, "photon_gi")->counters.at("gather_step"), 8.0);
  const Image& ia = aov(a, "indirect");
  const Image& ib = aov(b, "indirect");
  double d2 = 0;
  for (std::size_t i = 0; i < ia.pixels.size(); ++i) d2 += double(ia.pixels[i] - ib.pixels[i]) * (ia.pixels[i] - ib.pixels[i]);
  const double ma = mean(ia), mb = mean(ib), rel = std::sqrt(d2 / ia.pixels.size()) / ma;
  std::printf("256 px, k = 2: gather_step 2 mean %.5f, default (4) mean %.5f, relative RMS difference %.4f\n", ma, mb, rel);
  EXPECT_NEAR(mb / ma, 1.0, 0.01);
  EXPECT_LT(rel, 0.06);  // measured 0.038 (llvmpipe, 2026-12-05)
  adaptive.width = adaptive.height = 128;
  EXPECT_EQ(pass(renderer().render(scene, adaptive), "photon_gi")->counters.at("gather_step"), 4.0);
}

TEST(PhotonGi, GlossyBoxIndirectAgainstTheReference) {
  // The paper's Glosbox: the tall block is a glossy metal (roughness 0.3), whose indirect light is all
  // glossy reflection of the walls, evaluated per pixel with the glTF BRDF. The frame mean and the
  // block's own pixels (the glossy surface: a mask of the pixels where the reference and ours see
  // metal) must match the reference.
  const Scene scene = loadBuiltinScene("cornell_glossy");
  api::RenderRequest r = cornellRequest(48, {{"photons", 500000}});
  r.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"indirect", "material"}, false}};
  r.compare = api::CompareSpec{"reference", "indirect", 512};
  const RenderOutput out = renderer().render(scene, r);
  const Image& ours = aov(out, "indirect");
  const Image& truth = aov(out, "reference");
  const Image& material = aov(out, "material");
  EXPECT_NEAR(mean(ours) / mean(truth), 1.0, 0.05);
  double a = 0, b = 0;
  int n = 0;
  for (int y = 0; y < ours.height; ++y)
    for (int x = 0; x < ours.width; ++x)
      if (material.at(x, y)[0] > 0.99f) {  // metallic
        a += ours.at(x, y)[0] + ours.at(x, y)[1] + ours.at(x, y)[2];
        b += truth.at(x, y)[0] + truth.at(x, y)[1] + truth.at(x, y)[2];
        ++n;
      }
  ASSERT_GT(n, 50);
  std::printf("glossy block: %d pixels, photon_gi / reference indirect = %.3f; frame %.3f\n", n, a / b,
              mean(ours) / mean(truth));
  // The glossy lobe (alpha = 0.09) is narrower than most kernels are wide, so photons blur it: 15%.
  EXPECT_NEAR(a / b, 1.0, 0.15);
}

TEST(PhotonGi, SkyLightIsCountedOnceWithAmbientOcclusion) {
  // With a sky, photon_gi owns the sky's light on diffuse surfaces, its first bounce (L(sky)DE) included
  // (environment photons), so ambient_occlusion, which would add ambient x AO, owns nothing and is
  // culled: together with `direct` the beauty must hold each path once. The Cornell box is open at the
  // front, so the sky lights it; the frame mean is compared with the reference's beauty.
  const Scene scene = loadBuiltinScene("cornell_box");
  api::RenderRequest r = cornellRequest(32, {{"photons", 300000}});
  r.ambient = glm::vec3(2.f);
  r.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"beauty", "indirect"}, false}};
  r.compare = api::CompareSpec{"reference", "beauty", 512};
  const RenderOutput out = renderer().render(scene, r);
  EXPECT_EQ(pass(out, "ambient_occlusion"), nullptr);
  ASSERT_EQ(out.stats.skipped.count("ambient_occlusion"), 1u);
  EXPECT_EQ(out.stats.skipped.at("ambient_occlusion").rfind("culled: ", 0), 0u) << out.stats.skipped.at("ambient_occlusion");
  const double ratio = mean(aov(out, "beauty")) / mean(aov(out, "reference"));
  api::RenderRequest noSky = r;
  noSky.ambient = glm::vec3(0.f);
  const RenderOutput dark = renderer().render(scene, noSky);
  // The sky's share of the frame: what a double count (or a missing term) would add (or remove).
  const double skyShare = 1.0 - mean(aov(dark, "reference")) / mean(aov(out, "reference"));
  std::printf("sky: beauty / reference = %.3f, the sky's share of the reference = %.3f\n", ratio, skyShare);
  EXPECT_GT(skyShare, 0.15);
  EXPECT_NEAR(ratio, 1.0, 0.04);
  EXPECT_EQ(out.stats.lightPaths.at("L(sky)DE"), "photon_gi");
  EXPECT_EQ(out.stats.lightPaths.at("LD+DE"), "photon_gi");
  EXPECT_EQ(out.stats.lightPaths.at("L(point)DE"), "direct");
}

TEST(PhotonGi, CameraChangeReusesPhotonsAndMorePhotonsExtendThem) {
  const Scene scene = loadBuiltinScene("cornell_box");
  api::RenderRequest r = cornellRequest(32, {{"photons", 40000}, {"max_bounces", 5}});
  r.seed = 77;
  const RenderOutput first = renderer().render(scene, r);
  const bool traced = pass(first, "photon_gi")->counters.at("photons_traced") == 40000.0;
  EXPECT_TRUE(traced || testing::cacheEvent(first, "photon_gi_photons") == 1);
  api::RenderRequest moved = r;
  moved.camera = api::CameraOverride{{0.2f, 0.6f, 1.8f}, {0.f, 0.4f, 0.f}, {0.f, 1.f, 0.f}, 45.f};
  moved.width = 40;
  const RenderOutput second = renderer().render(scene, moved);
  EXPECT_EQ(testing::cacheEvent(second, "photon_gi_photons"), 1);
  EXPECT_EQ(testing::cacheEvent(second, "photon_gi_splats"), 1);  // radii and grid do not depend on the view
  EXPECT_EQ(pass(second, "photon_gi")->counters.at("photons_traced"), 0.0);
  api::RenderRequest more = r;
  more.passes["photon_gi"]["photons"] = 60000;
  const RenderOutput third = renderer().render(scene, more);
  EXPECT_EQ(pass(third, "photon_gi")->counters.at("photons_traced"), 20000.0);  // only the new ones
  EXPECT_EQ(testing::cacheEvent(third, "photon_gi_splats"), 0);
}

// The splat buffers hold one photon set at a time: a scene rendered again after another scene (its splats
// still cached) must gather its own photons, not the other's. Scene B is scene A with 4x the light, so
// B's indirect light is 4x A's; A again must give A's image exactly (same photons, same seed). Before
// the fix A again gathered B's splats (4x): the Fox sample rendered after BoxTextured came out unlit.
TEST(PhotonGi, ASceneRenderedAgainAfterAnotherGathersItsOwnPhotons) {
  const Scene a = loadBuiltinScene("cornell_box");
  Scene b = a;
  for (Light& l : b.lights) l.intensity *= 4.f;
  b.digest = a.digest + "-4x-light";
  const api::RenderRequest r = cornellRequest(24, {{"photons", 30000}});
  const RenderOutput first = renderer().render(a, r);
  const RenderOutput other = renderer().render(b, r);
  const RenderOutput again = renderer().render(a, r);
  EXPECT_EQ(testing::cacheEvent(again, "photon_gi_splats"), 1);
  EXPECT_EQ(pass(again, "photon_gi")->counters.at("splats_rebuilt"), 1.0);
  const double meanA = mean(aov(first, "indirect"));
  ASSERT_GT(meanA, 0.0);
  EXPECT_NEAR(mean(aov(other, "indirect")) / meanA, 4.0, 0.04);
  const Image& x = aov(first, "indirect");
  const Image& y = aov(again, "indirect");
  double maxDiff = 0.0;
  for (std::size_t i = 0; i < x.pixels.size(); ++i) maxDiff = std::max(maxDiff, double(std::abs(x.pixels[i] - y.pixels[i])));
  EXPECT_LT(maxDiff, 1e-5 * std::max(1.0, meanA));
}

TEST(PhotonGi, ScaledScenesGiveTheSameImage) {
  // Scaling geometry by s and light intensity by s^2 leaves every radiance unchanged.
  const Scene base = loadBuiltinScene("cornell_box");
  const api::RenderRequest r = cornellRequest(32, {{"photons", 60000}});
  const double reference = mean(aov(renderer().render(base, r), "indirect"));
  for (float s : {1e-3f, 1e4f}) {
    Scene scaled = base;
    for (MeshInstance& m : scaled.meshes) {
      for (glm::vec3& p : m.positions) p *= s;
      m.bounds = Bounds{};
      for (const glm::vec3& p : m.positions) m.bounds.extend(p);
    }
    for (Light& l : scaled.lights) { l.position *= s; l.intensity *= s * s; }
    scaled.camera.world[3] = glm::vec4(glm::vec3(scaled.camera.world[3]) * s, 1.f);
    scaled.camera.znear *= s;
    scaled.features = computeFeatures(scaled);
    scaled.digest = base.digest + "-scaled-" + std::to_string(s);
    const RenderOutput out = renderer().render(scaled, r);
    EXPECT_TRUE(testing::allFinite(out)) << "scale " << s;
    EXPECT_NEAR(mean(aov(out, "indirect")) / reference, 1.0, 0.02) << "scale " << s;
  }
}

TEST(PhotonGi, UnlitSurfacesGetNoPhotons) {
  // KHR_materials_unlit everywhere: the photons are absorbed at their first hit and the G-buffer marks
  // the pixels unlit, so the indirect AOV is exactly 0.
  Scene scene = loadBuiltinScene("cornell_box");
  for (Material& m : scene.materials) m.unlit = true;
  scene.digest += "-unlit";
  const RenderOutput out = renderer().render(scene, cornellRequest(24, {{"photons", 20000}}));
  for (float v : aov(out, "indirect").pixels) ASSERT_EQ(v, 0.f);
  EXPECT_EQ(pass(out, "photon_gi")->counters.at("records"), 0.0);
}

TEST(PhotonGi, PlannerOwnershipAndOptOut) {
  const Scene scene = loadBuiltinScene("cornell_box");
  api::RenderRequest off = cornellRequest(16);
  off.passes.erase("photon_gi");
  off.disabledPasses.insert("photon_gi");
  off.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"beauty"}, false}};
  const RenderOutput a = renderer().render(scene, off);
  EXPECT_EQ(pass(a, "photon_gi"), nullptr);
  EXPECT_NE(a.stats.skipped.at("photon_gi").find("turned off"), std::string::npos);
  api::RenderRequest env = off;
  env.disabledPasses.clear();
  env.passes["env_diffuse"] = nlohmann::json::object();
  const RenderOutput b = renderer().render(scene, env);
  EXPECT_EQ(pass(b, "photon_gi"), nullptr);
  EXPECT_EQ(b.stats.skipped.at("photon_gi"), "LD+DE is owned by env_diffuse");
  // What photon_gi would have supplied besides goes to the next claimant: the sky's first bounce to
  // ambient_occlusion, which the box has no sky for (so no one owns it), the area lights' to no one.
  EXPECT_EQ(b.stats.lightPaths.at("LD+DE"), "env_diffuse");
  EXPECT_EQ(b.stats.lightPaths.count("L(area)DE"), 0u);
  env.passes["photon_gi"] = nlohmann::json::object();
  EXPECT_THROW(renderer().render(scene, env), api::ApiError);
}

// Asking for env_diffuse's AOV plans env_diffuse, which then owns LD+DE: photon_gi is dropped as when
// env_diffuse is named, so asking for an output does not change the frame. Before requires_paths both
// ran, LD+DE on env_diffuse's receivers was added into beauty twice, and photon_gi's indirect light
// elsewhere beside it: the 32 px frame's mean beauty was 2.62 asked against 1.42 named (+84%).
TEST(PhotonGi, AskingForEnvDiffusesAovCountsIndirectDiffuseLightOnce) {
  const Scene scene = loadBuiltinScene("cornell_box");
  api::RenderRequest named;
  named.width = named.height = 16;
  named.passes["env_diffuse"] = nlohmann::json::object();
  named.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"beauty"}, false}};
  api::RenderRequest asked = named;
  asked.passes.clear();
  asked.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"beauty", "indirect_diffuse"}, false}};
  const RenderOutput a = renderer().render(scene, named);
  const RenderOutput b = renderer().render(scene, asked);
  ASSERT_EQ(b.stats.skipped.count("photon_gi"), 1u);
  EXPECT_EQ(b.stats.skipped.at("photon_gi"), "LD+DE is owned by env_diffuse");
  ASSERT_NE(pass(b, "env_diffuse"), nullptr);
  const double beautyNamed = mean(aov(a, "beauty")), beautyAsked = mean(aov(b, "beauty"));
  EXPECT_GT(beautyNamed, 0.0);
  EXPECT_NEAR(beautyAsked, beautyNamed, 1e-6 * beautyNamed);
}

}  // namespace
}  // namespace radiant
