// transparency (alphaMode BLEND): the pass's back-to-front over operator against the reference's
// stochastic pass-through, on two overlapping emissive quads before a lit wall.
#include <cmath>
#include <iostream>

#include <glm/glm.hpp>
#include <gtest/gtest.h>

#include "renderer/Renderer.h"
#include "tests/support/RenderTestSupport.h"
#include "tests/support/SceneBuilder.h"

namespace radiant {
namespace {

using testing::aov;
using testing::exrRequest;
using testing::renderer;

TEST(Transparency, BlendedSurfacesCompositeBackToFrontAsTheReference) {
  // Two emissive BLEND quads (alpha 0.5; red in front, blue behind, overlapping in the middle) before
  // a white Lambertian wall lit by a point light that is behind both quads (so they cast no shadow
  // and are not lit: what they show is their emission). glTF's over operator gives, where both
  // cover the wall: L = 0.5 red + 0.5 (0.5 blue + 0.5 wall); the reference's stochastic coverage has
  // the same expectation.
  testing::SceneBuilder b;
  b.quad({0, 0, -1}, {3, 0, 0}, {0, 3, 0}, b.material(testing::lambertian()), "wall");
  auto blended = [&](glm::vec3 emission) {
    Material m = testing::lambertian(glm::vec3(0.f));
    m.baseColorFactor.a = 0.5f;
    m.alphaMode = AlphaMode::Blend;
    m.emissiveFactor = emission;
    return b.material(m);
  };
  b.quad({0.25f, 0, 0}, {0.5f, 0, 0}, {0, 0.5f, 0}, blended({0, 0, 1}), "blue");
  b.quad({-0.25f, 0, 0.3f}, {0.5f, 0, 0}, {0, 0.5f, 0}, blended({1, 0, 0}), "red");
  b.pointLight({0, 0, -0.6f}, 0.4f);
  const Scene scene = b.build("transparency");
  api::RenderRequest req = exrRequest(48);
  req.defaultLighting = false;
  req.camera = api::CameraOverride{{0, 0, 3}, {0, 0, 0}, {0, 1, 0}, 40.f};
  req.compare = api::CompareSpec{"reference", "beauty", 256, 2};
  req.disabledPasses.insert("photon_gi");  // nothing here is lit indirectly
  const RenderOutput out = renderer().render(scene, req);
  const Image& beauty = aov(out, "beauty");
  const Image& ref = aov(out, "reference");
  // Away from edges (pixels whose 5x5 raster neighbourhood is flat): relative L1. At the quads' edges
  // the two differ by design: the raster samples each pixel at its centre, the reference filters over
  // more than a pixel. The reference's coverage is a coin flip per sample (a standard deviation of
  // 0.5 / sqrt(256) = 3% for a half-covered emission-1 pixel: a mean absolute deviation of ~2.5%).
  double err = 0.0, sum = 0.0;
  glm::dvec3 total(0.0), totalRef(0.0);
  int interior = 0;
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 48; ++x) {
      for (int c = 0; c < 3; ++c) total[c] += beauty.at(x, y)[c], totalRef[c] += ref.at(x, y)[c];
      if (x < 2 || y < 2 || x > 45 || y > 45) continue;
      bool flat = true;
      for (int dy = -2; dy <= 2 && flat; ++dy)
        for (int dx = -2; dx <= 2 && flat; ++dx)
          for (int c = 0; c < 3; ++c) flat = flat && std::abs(beauty.at(x + dx, y + dy)[c] - beauty.at(x, y)[c]) < 0.02f;
      if (!flat) continue;
      ++interior;
      for (int c = 0; c < 3; ++c) {
        err += std::abs(beauty.at(x, y)[c] - ref.at(x, y)[c]);
        sum += ref.at(x, y)[c];
      }
    }
  std::cout << "transparency: " << interior << " interior pixels, relative L1 raster/reference " << err / sum
            << "; image totals raster/reference - 1: " << total.r / totalRef.r - 1.0 << " "
            << total.g / totalRef.g - 1.0 << " " << total.b / totalRef.b - 1.0 << "\n";
  ASSERT_GT(interior, 500);
  EXPECT_LT(err / sum, 0.04);
  // The filter moves light across edges, it does not make or lose any: the image totals agree, up to
  // the raster's point-sampled coverage of a quad 17.6 pixels wide (17 or 18 columns: +-3%; measured
  // -2.5% red, +1.7% green, -2.1% blue).
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(total[c] / totalRef[c], 1.0, 0.035) << c;
  // Pixel rows through the quads' centre line: x = 24 is in the overlap, x = 14 red only, x = 34 blue only.
  auto wall = [&](const Image& img, int x) { return img.at(x, 24)[1] * 4.f; };  // green = 0.25 x the wall (both)
  for (const Image* img : {&beauty, &ref}) {
    const float* both = img->at(24, 24);
    // Over, back to front: red 0.5 + 0.25 wall, blue 0.25 + 0.25 wall (drawn the other way round the
    // two would swap).
    EXPECT_NEAR(both[0], 0.5f + 0.25f * wall(*img, 24), 0.05f) << img->aov;
    EXPECT_NEAR(both[2], 0.25f + 0.25f * wall(*img, 24), 0.05f) << img->aov;
    EXPECT_GT(both[0], both[2] + 0.15f) << img->aov;
    // One quad alone: half its emission plus half the wall.
    EXPECT_NEAR(img->at(14, 24)[0], 0.5f + img->at(14, 24)[1], 0.05f) << img->aov;
    EXPECT_NEAR(img->at(34, 24)[2], 0.5f + img->at(34, 24)[1], 0.05f) << img->aov;
  }
  bool ran = false;
  for (const auto& p : out.stats.passes)
    if (p.name == "transparency") ran = p.counters.at("blended_primitives") == 2.0;
  EXPECT_TRUE(ran);
}

}  // namespace
}  // namespace radiant
