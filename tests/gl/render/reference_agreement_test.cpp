// The raster path and the CPU reference must agree where they compute the same thing: the direct
// lighting of punctual lights. This is what makes "error against the reference" mean something.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "renderer/Renderer.h"
#include "renderer/metrics/Metrics.h"
#include "renderer/reference/PathTracer.h"
#include "renderer/scene/BuiltinScenes.h"
#include "tests/support/RenderTestSupport.h"
#include "tests/support/SceneBuilder.h"

namespace radiant {
namespace {

using testing::aov;
using testing::renderer;



TEST(ReferenceAgreement, CalibrationPlaneMatchesRasterAndClosedForm) {
  // Point light of intensity pi at height 1 over a white Lambertian plane: radiance 1.0 at the foot.
  testing::SceneBuilder b;
  int white = b.material(testing::lambertian());
  b.quad({0, 0, 0}, {20, 0, 0}, {0, 0, -20}, white).pointLight({0, 1, 0}, glm::pi<float>()).topDownOrtho(5.f, 0.5f);
  Scene scene = b.build("calib-ref");
  reference::PathTracer pt(scene);
  reference::ReferenceOptions o;
  o.spp = 16;
  o.maxBounces = 1;
  Image ref = pt.render(scene.camera, 16, 16, o);
  api::RenderRequest req;
  req.width = req.height = 16;
  req.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"direct"}, false}};
  RenderOutput out = renderer().render(scene, req);
  const Image& direct = aov(out, "direct");
  for (int y = 7; y <= 8; ++y)
    for (int x = 7; x <= 8; ++x) {
      EXPECT_NEAR(ref.at(x, y)[0], 1.0f, 0.01f);  // within 1% of the closed form
      EXPECT_NEAR(direct.at(x, y)[0], 1.0f, 0.01f);
    }
}

TEST(ReferenceAgreement, CornellBoxDirectMatchesReferenceDirectOnly) {
  // Reference bounce range [0, 1] (emission, sky and direct light) against the raster `direct` AOV.
  // Where both compute the same integral they must agree closely; the differences the two methods
  // legitimately have are local: pixel-centre sampling versus a box filter over the pixel (which
  // matters at silhouettes and in the steep hotspot on the ceiling 8 cm above the light) and PCF
  // shadow edges versus exact hard shadows. So the test bounds the bias on flat regions tightly and
  // the per-pixel error only through robust percentiles, not through an RMSE the hotspot dominates.
  Scene scene = loadBuiltinScene("cornell_box");
  api::RenderRequest req;
  req.width = req.height = 128;
  req.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"direct"}, false}};
  req.compare = api::CompareSpec{"reference", "direct", 16, 1};
  RenderOutput out = renderer().render(scene, req);
  ASSERT_FALSE(out.stats.metrics.is_null());
  const Image& direct = aov(out, "direct");
  const Image& ref = aov(out, "reference");
  // Flat regions (back wall, floor, left wall): means within 0.5%.
  auto ratio = [&](int x0, int y0, int x1, int y1) {
    double sd = 0, sr = 0;
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) sd += direct.at(x, y)[0], sr += ref.at(x, y)[0];
    return sd / sr;
  };
  EXPECT_NEAR(ratio(50, 30, 78, 50), 1.0, 0.005) << "back wall";
  EXPECT_NEAR(ratio(40, 110, 60, 120), 1.0, 0.005) << "floor";
  EXPECT_NEAR(ratio(5, 60, 12, 80), 1.0, 0.005) << "left wall";
  // Per-pixel relative error |d - r| / max(r, 0.05): median below 1%, 90th percentile below 10%.
  std::vector<double> rel;
  for (std::size_t i = 0; i < direct.pixels.size(); ++i)
    rel.push_back(std::abs(direct.pixels[i] - ref.pixels[i]) / std::max(ref.pixels[i], 0.05f));
  std::sort(rel.begin(), rel.end());
  std::printf("relative error: median %.4f p75 %.4f p90 %.4f p95 %.4f; ssim %.4f\n", rel[rel.size() / 2],
              rel[rel.size() * 3 / 4], rel[rel.size() * 9 / 10], rel[rel.size() * 95 / 100],
              out.stats.metrics["ssim"].get<double>());
  EXPECT_LT(rel[rel.size() / 2], 0.01);
  EXPECT_LT(rel[rel.size() * 9 / 10], 0.10);
  EXPECT_EQ(out.stats.metrics["rel_mse_epsilon"].get<double>(), 0.01);
  EXPECT_GT(out.stats.metrics["ssim"].get<double>(), 0.9);

  // A second request that changes only the compared technique's knobs reuses the ground truth.
  req.passes["direct"] = {{"pcf_radius", 2}};
  RenderOutput again = renderer().render(scene, req);
  EXPECT_TRUE(again.stats.metrics["reference_cached"].get<bool>());
}

TEST(ReferenceAgreement, AReferencePassIsScoredAgainstAnIndependentReference) {
  // compare.aov "reference" scores the reference pass against the reference in the same mode at the
  // compare block's spp, with its own seed. For an unbiased estimator with per-pixel variance s^2,
  // independent N-spp images differ by E[MSE] = 2 s^2 / N, and an N-spp image differs from an M-spp one
  // by s^2 (1/N + 1/M). With the frame's own seed the truth would share its first N samples (rt::Sampler
  // hashes pixel, sample and seed): MSE 0 at M = N (the cache returned the frame's own image) and
  // s^2 (1/N - 1/M) otherwise. So MSE(4 vs 4) / MSE(4 vs 64) is 2 / (1 + 1/16) = 1.88 when independent,
  // 0 when shared. The frame-wide RMSE of stats.metrics is dominated by a few ceiling pixels next to
  // the light (heavy-tailed: their ratio came out 1.42), so the ratio is taken over the lower half of
  // the image (floor and walls, 2048 pixels of direct light only): within +-25% of 1.88.
  Scene scene = loadBuiltinScene("cornell_box");
  api::RenderRequest req;
  req.width = req.height = 64;
  req.passes["reference"] = {{"spp", 4}, {"max_bounces", 1}};
  req.disabledPasses.insert("photon_gi");
  req.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"reference"}, false}};
  Image frame;
  auto lowerHalfMse = [&](int truthSpp) {
    req.compare = api::CompareSpec{"reference", "reference", truthSpp};
    const RenderOutput out = renderer().render(scene, req);
    EXPECT_EQ(out.stats.metrics.at("reference_mode"), "beauty");
    EXPECT_EQ(out.stats.metrics.at("max_bounces"), 1);  // the pass's own bounce range, not compare's 8
    EXPECT_GT(out.stats.metrics.at("rmse").get<double>(), 0.0);
    frame = aov(out, "reference");
    const Image& truth = out.compareReference;
    double sum = 0.0;
    for (int y = frame.height / 2; y < frame.height; ++y)
      for (int x = 0; x < frame.width; ++x)
        for (int c = 0; c < 3; ++c) sum += std::pow(double(frame.at(x, y)[c]) - truth.at(x, y)[c], 2.0);
    return sum / (frame.width * frame.height / 2 * 3);
  };
  const double equal = lowerHalfMse(4), converged = lowerHalfMse(64);
  std::printf("lower half: MSE 4 vs 4 spp %.6g, 4 vs 64 spp %.6g, ratio %.3f (independent: 1.88)\n", equal,
              converged, equal / converged);
  ASSERT_GT(converged, 0.0);
  EXPECT_GT(equal / converged, 1.88 * 0.75);
  EXPECT_LT(equal / converged, 1.88 * 1.25);
}

TEST(ReferenceAgreement, IdenticalImagesGiveZeroError) {
  // Comparing a frame with itself (an uploaded target equal to the frame) gives RMSE 0, SSIM 1 and a
  // PSNR of null (infinite), not a crash.
  Scene scene = loadBuiltinScene("cornell_box");
  api::RenderRequest req;
  req.width = req.height = 32;
  RenderOutput first = renderer().render(scene, req);
  req.compare = api::CompareSpec{"sha256:self", "beauty", 1, 1};
  RenderOutput out = renderer().render(scene, req, nullptr, FrameInputs{&aov(first, "beauty"), nullptr});
  EXPECT_EQ(out.stats.metrics["rmse"].get<double>(), 0.0);
  EXPECT_EQ(out.stats.metrics["ssim"].get<double>(), 1.0);
  EXPECT_TRUE(out.stats.metrics["psnr"].is_null());
}

}  // namespace
}  // namespace radiant

namespace radiant {
namespace {

// The reference pass with caustics: the Cornell box's point light through the smooth glass sphere is
// a caustic the path tracer cannot sample (a delta light behind a delta BSDF), so the pass adds the
// light tracer's L S+ D E image. With a point light the path tracer finds no caustic path at all, so
// beauty with caustics is exactly beauty without + the `caustics` mode, and the direct range holds none.
TEST(ReferenceAgreement, ReferenceBeautyAddsTheLightTracedCausticsOnce) {
  Scene scene = loadBuiltinScene("cornell_glass");
  auto render = [&](const nlohmann::json& params, double* traced = nullptr) {
    api::RenderRequest req;
    req.width = req.height = 32;
    req.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"reference"}, false}};
    req.passes["reference"] = params;
    RenderOutput out = testing::renderer().render(scene, req);
    for (const auto& p : out.stats.passes)
      if (p.name == "reference" && traced) *traced = p.counters.at("light_traced_caustics");
    return testing::aov(out, "reference");
  };
  double traced = -1;
  const Image with = render({{"spp", 4}, {"light_paths_per_pixel", 16}}, &traced);
  EXPECT_EQ(traced, 1.0);
  const Image without = render({{"spp", 4}, {"caustics", false}}, &traced);
  EXPECT_EQ(traced, 0.0);
  const Image caustics = render({{"spp", 4}, {"aov", "caustics"}, {"light_paths_per_pixel", 16}});
  render({{"spp", 4}, {"aov", "direct"}}, &traced);
  EXPECT_EQ(traced, 0.0);  // k <= 1 holds no caustic
  double sum = 0;
  for (std::size_t i = 0; i < with.pixels.size(); ++i) {
    ASSERT_TRUE(std::isfinite(with.pixels[i]));
    EXPECT_NEAR(with.pixels[i], without.pixels[i] + caustics.pixels[i], 1e-5f * (1.f + with.pixels[i]));
    sum += caustics.pixels[i];
  }
  EXPECT_GT(sum, 0.0);
}

}  // namespace
}  // namespace radiant
