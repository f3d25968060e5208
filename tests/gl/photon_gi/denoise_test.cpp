// photon_gi's denoiser (renderer/shading/Denoiser.h, issue 32): against a converged reference it lowers
// the error of the frame's indirect light, keeps its mean, keeps texture (albedo) edges and geometric
// edges, and never makes a non-finite pixel.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "renderer/Renderer.h"
#include "renderer/scene/BuiltinScenes.h"
#include "tests/support/RenderTestSupport.h"
#include "tests/support/SceneBuilder.h"

namespace radiant {
namespace {

using testing::aov;
using testing::pass;
using testing::renderer;

double mean(const Image& img) {
  double s = 0;
  for (float v : img.pixels) s += v;
  return s / img.pixels.size();
}

// RMSE of a against b over the pixels where mask (if given) is set, all channels.
double rmse(const Image& a, const Image& b, const std::vector<bool>* mask = nullptr) {
  double s = 0;
  std::size_t n = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      if (mask && !(*mask)[static_cast<std::size_t>(y) * a.width + x]) continue;
      for (int c = 0; c < 3; ++c) {
        const double d = a.at(x, y)[c] - b.at(x, y)[c];
        s += d * d;
      }
      n += 3;
    }
  return std::sqrt(s / static_cast<double>(n));
}

// Pixels whose 5x5 neighbourhood holds another surface orientation (the box's corners and the blocks'
// edges): where a filter that ignores geometry would bleed light across.
std::vector<bool> geometricEdges(const Image& normal) {
  std::vector<bool> edge(static_cast<std::size_t>(normal.width) * normal.height, false);
  for (int y = 0; y < normal.height; ++y)
    for (int x = 0; x < normal.width; ++x) {
      const float* n = normal.at(x, y);
      for (int dy = -2; dy <= 2; ++dy)
        for (int dx = -2; dx <= 2; ++dx) {
          const int qx = x + dx, qy = y + dy;
          if (qx < 0 || qy < 0 || qx >= normal.width || qy >= normal.height) continue;
          const float* m = normal.at(qx, qy);
          if (n[0] * m[0] + n[1] * m[1] + n[2] * m[2] < 0.9f) edge[static_cast<std::size_t>(y) * normal.width + x] = true;
        }
    }
  return edge;
}

// The Cornell box at 64 px (supersampled k times), photon_gi's `indirect` raw and denoised, scored
// against a 2048-spp reference `indirect`: over the frame and on its geometric edges, and the denoised
// image's mean over the raw one's.
struct DenoiseScores {
  api::RenderRequest request;
  RenderOutput raw, clean;
  double rawErr = 0, cleanErr = 0, rawEdge = 0, cleanEdge = 0, meanRatio = 0;
};
DenoiseScores scoreTheCornellBox(const Scene& scene, int supersampling) {
  DenoiseScores d;
  api::RenderRequest& r = d.request;
  r.width = r.height = 64;
  r.supersampling = supersampling;
  r.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"indirect", "normal"}, false}};
  r.compare = api::CompareSpec{"reference", "indirect", 2048};
  r.passes["photon_gi"] = {{"denoise", false}};
  d.raw = renderer().render(scene, r);
  r.passes["photon_gi"] = {{"denoise", true}};
  d.clean = renderer().render(scene, r);
  const Image& truth = aov(d.clean, "reference");
  d.rawErr = rmse(aov(d.raw, "indirect"), truth);
  d.cleanErr = rmse(aov(d.clean, "indirect"), truth);
  const std::vector<bool> edges = geometricEdges(aov(d.clean, "normal"));
  d.rawEdge = rmse(aov(d.raw, "indirect"), truth, &edges);
  d.cleanEdge = rmse(aov(d.clean, "indirect"), truth, &edges);
  d.meanRatio = mean(aov(d.clean, "indirect")) / mean(aov(d.raw, "indirect"));
  std::printf("Cornell box 64 px, k = %d, indirect vs 2048 spp: rmse raw %.4f, denoised %.4f (x%.2f); on edges "
              "%.4f -> %.4f; mean ratio %.4f; truth mean %.4f\n",
              supersampling, d.rawErr, d.cleanErr, d.cleanErr / d.rawErr, d.rawEdge, d.cleanEdge, d.meanRatio,
              mean(truth));
  return d;
}

TEST(Denoise, LowersTheCornellBoxErrorKeepsTheMeanAndTheCorners) {
  const DenoiseScores d = scoreTheCornellBox(loadBuiltinScene("cornell_box"), 1);
  // Measured 2026-12-04 (llvmpipe): rmse 0.1345 -> 0.1199 (x0.89), 0.1460 -> 0.1335 on edges, mean
  // +0.33%. The truth's own noise (sigma 0.058 at 2048 spp, from two independent truths) is in both
  // figures: without it the frame's error falls 0.122 -> 0.105. What is left is bias the filter cannot
  // remove (the kernel's blur of the ceiling's hot spot), docs/PERFORMANCE.md, "Denoiser".
  EXPECT_LT(d.cleanErr, 0.95 * d.rawErr);
  EXPECT_NEAR(d.meanRatio, 1.0, 0.005);
  EXPECT_LT(d.cleanEdge, d.rawEdge);
  EXPECT_EQ(pass(d.clean, "photon_gi")->counters.at("denoise_iterations"), 3.0);
  EXPECT_EQ(pass(d.raw, "photon_gi")->counters.at("denoise_iterations"), 0.0);
}

// Supersampled (k = 2): the filter's steps count output pixels (2, 4 samples) and its default is 2
// passes. The same properties as at k = 1, against the same truth; 3 passes when the request says so.
TEST(Denoise, SupersampledFramesFilterInOutputPixels) {
  const Scene scene = loadBuiltinScene("cornell_box");
  DenoiseScores d = scoreTheCornellBox(scene, 2);
  // Measured 2026-12-06 (llvmpipe): rmse 0.1090 -> 0.0997 (x0.92), 0.1077 -> 0.1027 on edges, mean
  // +0.16%; 3 passes of steps 2, 4, 8: 0.1058.
  EXPECT_EQ(pass(d.clean, "photon_gi")->counters.at("denoise_iterations"), 2.0);
  EXPECT_EQ(pass(d.clean, "photon_gi")->counters.at("denoise_base_step"), 2.0);
  EXPECT_LT(d.cleanErr, 0.95 * d.rawErr);
  EXPECT_NEAR(d.meanRatio, 1.0, 0.005);
  EXPECT_LT(d.cleanEdge, d.rawEdge);
  d.request.passes["photon_gi"] = {{"denoise", true}, {"denoise_iterations", 3}};
  d.request.explicitParams["photon_gi"] = {"denoise", "denoise_iterations"};  // what the HTTP route records
  const RenderOutput three = renderer().render(scene, d.request);
  EXPECT_EQ(pass(three, "photon_gi")->counters.at("denoise_iterations"), 3.0);  // as given
  EXPECT_EQ(pass(three, "photon_gi")->counters.at("denoise_base_step"), 2.0);
}

// A closed room [-2, 2] x [-0.01, 2] x [-2, 2] of a double-sided Lambertian of albedo rho, a point light
// under its ceiling and an orthographic camera looking down at its floor.
testing::SceneBuilder room(float rho, float intensity) {
  testing::SceneBuilder b;
  Material walls = testing::lambertian(glm::vec3(rho));
  walls.doubleSided = true;
  b.box({-2.f, -0.01f, -2.f}, {2.f, 2.f, 2.f}, b.material(walls), "room");
  b.pointLight({0.f, 1.5f, 0.f}, intensity).topDownOrtho(1.9f, 1.5f);
  return b;
}

// A floor of 0.8 / 0.2 albedo squares in a white room lit by a point light: the floor's irradiance is
// smooth, so indirect / albedo must be continuous across every checker edge. The filter works on the
// demodulated radiance, so the edge survives; a filter of the radiance itself would mix 0.8 and 0.2
// across it (ratio ~4 off at the edge).
TEST(Denoise, AlbedoEdgesStaySharp) {
  testing::SceneBuilder b = room(0.8f, 10.f);
  const int light = b.material(testing::lambertian(glm::vec3(0.8f)));
  const int dark = b.material(testing::lambertian(glm::vec3(0.2f)));
  const int n = 6;
  const float cell = 3.f / n;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      b.quad({-1.5f + (i + 0.5f) * cell, 0.f, -1.5f + (j + 0.5f) * cell}, {0.5f * cell, 0, 0}, {0, 0, -0.5f * cell},
             (i + j) % 2 ? light : dark, "tile");
  const Scene scene = b.build("denoise-checker");
  api::RenderRequest r;
  r.width = r.height = 96;
  r.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"indirect", "albedo"}, false}};
  const RenderOutput out = renderer().render(scene, r);
  const Image& ind = aov(out, "indirect");
  const Image& alb = aov(out, "albedo");
  double sum = 0, worst = 0;
  int edges = 0;
  for (int y = 0; y < ind.height; ++y)
    for (int x = 0; x + 1 < ind.width; ++x) {
      const float a0 = alb.at(x, y)[0], a1 = alb.at(x + 1, y)[0];
      if (std::abs(a0 - a1) < 0.5f) continue;  // not a checker edge (pixels on one tile, or straddling)
      const double e0 = ind.at(x, y)[0] / a0, e1 = ind.at(x + 1, y)[0] / a1;  // irradiance / pi
      const double d = std::abs(std::log(e0 / e1));
      sum += d;
      worst = std::max(worst, d);
      ++edges;
    }
  std::printf("checker: %d edge pairs, mean |log ratio| of indirect / albedo %.4f, worst %.4f\n", edges, sum / edges, worst);
  ASSERT_GT(edges, 100);
  EXPECT_LT(sum / edges, 0.05);  // the photon noise (C = 10: 7.6%) left after filtering, and the true gradient
  EXPECT_LT(worst, 0.25);        // a radiance filter: log 4 = 1.39
}

// Zero albedo everywhere but one surface, a light of 1e30: the filter divides by the floored albedo and
// sums radiances near the float range; nothing it writes may be NaN or Inf.
TEST(Denoise, ZeroAlbedoAndHugeRadianceStayFinite) {
  testing::SceneBuilder b = room(0.f, 1e30f);
  const int floor = b.material(testing::lambertian(glm::vec3(1.f)));
  b.quad({0.f, 0.f, 0.f}, {1.f, 0, 0}, {0, 0, -1.f}, floor, "floor");
  b.quad({0.f, 1.9f, 0.f}, {1.f, 0, 0}, {0, 0, 1.f}, floor, "ceiling patch");  // lights the floor indirectly
  const Scene scene = b.build("denoise-extremes");
  api::RenderRequest r;
  r.width = r.height = 32;
  r.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"indirect", "beauty"}, false}};
  const RenderOutput out = renderer().render(scene, r);
  EXPECT_TRUE(testing::allFinite(out));
  float peak = 0.f;
  for (float v : aov(out, "indirect").pixels) peak = std::max(peak, v);
  EXPECT_GT(peak, 1e26f);  // the huge values did reach the filter
  for (const auto& p : out.stats.passes) EXPECT_EQ(p.counters.count("non_finite_pixels_zeroed"), 0u) << p.name;
}

}  // namespace
}  // namespace radiant
