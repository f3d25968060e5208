// Triangle edges on textured models (issue 29, items 1 and 2): the G-buffer's textures and normal maps
// on both sides of every shared edge, with numbers, on small glTF files the tests write.
#include <algorithm>
#include <array>
#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "renderer/Renderer.h"
#include "renderer/io/ImageIO.h"
#include "renderer/scene/GltfLoader.h"
#include "tests/support/RenderTestSupport.h"
#include "tests/unit/scene/GltfTestBuilder.h"

namespace radiant {
namespace {

using testing::aov;
using testing::renderer;
using json = nlohmann::json;

// ---- a quad that exactly fills a kSize x kSize frame: pixel (x, y) sees world
// (2 (x + .5) / kSize - 1, 1 - 2 (y + .5) / kSize, 0) -------------------------------------------------

constexpr int kSize = 32;
const api::CameraOverride kFillCamera{{0, 0, 2}, {0, 0, 0}, {0, 1, 0}, 2.f * 26.5650512f};  // tan(fov/2) = 1/2

glm::vec2 pixelCentreWorld(int x, int y) {
  return {2.f * (x + 0.5f) / kSize - 1.f, 1.f - 2.f * (y + 0.5f) / kSize};
}

// Distance in pixels from a pixel centre to the segment ab (world units on the quad, 2 / kSize per pixel).
float pixelDistanceToSegment(glm::vec2 p, glm::vec2 a, glm::vec2 b) {
  const glm::vec2 ab = b - a;
  const float t = std::clamp(glm::dot(p - a, ab) / glm::dot(ab, ab), 0.f, 1.f);
  return glm::length(p - (a + t * ab)) * kSize / 2.f;
}

bool insideTriangle(glm::vec2 p, glm::vec2 a, glm::vec2 b, glm::vec2 c) {
  auto side = [](glm::vec2 o, glm::vec2 u, glm::vec2 v) { return (u.x - o.x) * (v.y - o.y) - (u.y - o.y) * (v.x - o.x); };
  const float s0 = side(a, b, p), s1 = side(b, c, p), s2 = side(c, a, p);
  return (s0 >= 0 && s1 >= 0 && s2 >= 0) || (s0 <= 0 && s1 <= 0 && s2 <= 0);
}

// ---- 1. a texture atlas with contrasting regions on adjacent triangles ------------------------------

// A 16 x 16 atlas of 4 x 4 regions of 4 x 4 texels, each region one sRGB colour, all 16 far apart.
constexpr int kAtlas = 16, kRegion = 4;
const std::array<std::array<std::uint8_t, 3>, 16> kRegionColours{{
    {230, 40, 40}, {40, 200, 60}, {30, 60, 220}, {250, 240, 200}, {20, 20, 20}, {240, 160, 20},
    {150, 30, 200}, {20, 200, 210}, {120, 120, 120}, {250, 120, 180}, {90, 60, 20}, {200, 230, 40},
    {10, 90, 60}, {255, 255, 255}, {70, 20, 110}, {180, 200, 250},
}};

std::vector<std::uint8_t> atlasTexels() {
  std::vector<std::uint8_t> t(kAtlas * kAtlas * 4);
  for (int y = 0; y < kAtlas; ++y)
    for (int x = 0; x < kAtlas; ++x) {
      const auto& c = kRegionColours[std::size_t((y / kRegion) * (kAtlas / kRegion) + x / kRegion)];
      std::uint8_t* p = &t[std::size_t(y * kAtlas + x) * 4];
      p[0] = c[0], p[1] = c[1], p[2] = c[2], p[3] = 255;
    }
  return t;
}

// The filling quad as a 4 x 4 grid of cells, each cut by a diagonal (alternating), 32 triangles with
// their own vertices: triangle t's corner at world xy w gets uv uvOf(t, w, place), where place is the
// corner's place in the cell ((0, 1) bottom left, (1, 0) top right: the image's v runs down).
struct GridCard {
  std::vector<std::array<glm::vec2, 3>> triangles;  // world xy
};

template <class UvOf>
GridCard gridCard(test::GltfBuilder& b, int material, UvOf&& uvOf) {
  GridCard card;
  std::vector<glm::vec3> p, n;
  std::vector<glm::vec2> uv;
  std::vector<std::uint16_t> idx;
  constexpr int kCells = 4;
  for (int cy = 0; cy < kCells; ++cy)
    for (int cx = 0; cx < kCells; ++cx) {
      const float x0 = -1.f + 2.f * cx / kCells, x1 = x0 + 2.f / kCells;
      const float y0 = -1.f + 2.f * cy / kCells, y1 = y0 + 2.f / kCells;
      // Corners counter-clockwise from the bottom left.
      const std::array<glm::vec2, 4> corner{glm::vec2(x0, y0), glm::vec2(x1, y0), glm::vec2(x1, y1), glm::vec2(x0, y1)};
      const std::array<glm::vec2, 4> place{glm::vec2(0, 1), glm::vec2(1, 1), glm::vec2(1, 0), glm::vec2(0, 0)};
      const bool flip = (cx + cy) % 2 == 1;
      const std::array<std::array<int, 3>, 2> tris = flip ? std::array<std::array<int, 3>, 2>{{{0, 1, 3}, {1, 2, 3}}}
                                                          : std::array<std::array<int, 3>, 2>{{{0, 1, 2}, {0, 2, 3}}};
      for (const auto& tri : tris) {
        const int t = static_cast<int>(card.triangles.size());
        std::array<glm::vec2, 3> world{};
        for (int k = 0; k < 3; ++k) {
          const auto c = std::size_t(tri[std::size_t(k)]);
          world[std::size_t(k)] = corner[c];
          idx.push_back(static_cast<std::uint16_t>(p.size()));
          p.emplace_back(corner[c], 0.f);
          n.emplace_back(0.f, 0.f, 1.f);
          uv.push_back(uvOf(t, corner[c], place[c]));
        }
        card.triangles.push_back(world);
      }
    }
  const int mesh = b.mesh(json::array({test::trianglePrimitive<std::uint16_t>(b, p, idx, n, uv, material)}));
  b.scene({b.node({{"name", "grid card"}, {"mesh", mesh}})});
  return card;
}

// Triangle t maps into atlas region (5 t) mod 16, which differs from the regions of all its neighbours
// (within a cell t and t + 1, across cells t + 1 and t + 8): a uv seam at every edge, as an atlas has.
// Each triangle's uvs stay a texel inside its region, so that the bilinear lookup of the magnified base
// level (a cell is 8 pixels on 2 texels) reads that region's colour alone.
int atlasRegion(int triangle) { return (5 * triangle) % 16; }

glm::vec2 atlasUv(int triangle, glm::vec2, glm::vec2 place) {
  const int region = atlasRegion(triangle);
  const glm::vec2 origin(float(region % 4 * kRegion + 1), float(region / 4 * kRegion + 1));  // texels
  return (origin + 2.f * place) / float(kAtlas);
}

// A frame of the grid card's `aov`, one sample per pixel.
RenderOutput renderGridCard(const Scene& scene, const std::string& aovName) {
  api::RenderRequest req;
  req.width = req.height = kSize;
  req.supersampling = 1;  // one sample per pixel: a pixel is the surface under its centre
  req.camera = kFillCamera;
  req.outputs = {api::OutputSpec{api::ImageFormat::Exr, {aovName}, false}};
  return renderer().render(scene, req);
}

// Distance in pixels from the pixel centre to the nearest shared (interior) edge of the card.
float sharedEdgeDistance(const GridCard& card, glm::vec2 c) {
  float d = 1e9f;
  for (const auto& w : card.triangles)
    for (int k = 0; k < 3; ++k) {
      const glm::vec2 a = w[std::size_t(k)], e = w[std::size_t((k + 1) % 3)];
      const bool border = (std::abs(a.x - e.x) < 1e-6f && std::abs(std::abs(a.x) - 1.f) < 1e-6f) ||
                          (std::abs(a.y - e.y) < 1e-6f && std::abs(std::abs(a.y) - 1.f) < 1e-6f);
      if (!border) d = std::min(d, pixelDistanceToSegment(c, a, e));
    }
  return d;
}

// The triangles whose area holds the pixel centre, or lie within 0.05 pixel of it (either side of an
// edge through the centre is right).
std::vector<int> trianglesAt(const GridCard& card, glm::vec2 c) {
  std::vector<int> out;
  for (std::size_t t = 0; t < card.triangles.size(); ++t) {
    const auto& w = card.triangles[t];
    float d = 1e9f;
    for (int k = 0; k < 3; ++k) d = std::min(d, pixelDistanceToSegment(c, w[std::size_t(k)], w[std::size_t((k + 1) % 3)]));
    if (insideTriangle(c, w[0], w[1], w[2]) || d <= 0.05f) out.push_back(static_cast<int>(t));
  }
  return out;
}

TEST(TextureSeams, AlbedoOnBothSidesOfEverySharedEdgeIsItsTexelsColour) {
  test::GltfBuilder b;
  const int m = b.material({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}, {"metallicFactor", 0.0}}}});
  const GridCard card = gridCard(b, m, atlasUv);
  // Trilinear minification, as Fox's sampler: the base level is what a magnified texture must show.
  b.doc["samplers"] = json::array({{{"magFilter", 9729}, {"minFilter", 9987}}});
  b.doc["textures"] = json::array({{{"source", 0}, {"sampler", 0}}});
  b.doc["images"] = json::array({{{"uri", "data:image/png;base64," + test::base64(test::encodePng(kAtlas, kAtlas, atlasTexels()))}}});
  const Scene scene = loadSceneFromMemory(b.gltf());
  ASSERT_TRUE(scene.warnings.empty()) << scene.warnings[0];
  const Image& albedo = aov(renderGridCard(scene, "albedo"), "albedo");

  // Every pixel against the colour of the triangle under its centre, in 8-bit sRGB units; pixels within
  // 1.5 pixels of a shared edge are the edge pixels (both sides of it).
  float edgeError = 0.f, interiorError = 0.f;
  int edgePixels = 0, wrongEdgePixels = 0;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      const glm::vec2 c = pixelCentreWorld(x, y);
      float best = 1e9f;
      for (int t : trianglesAt(card, c)) {
        const auto& texel = kRegionColours[std::size_t(atlasRegion(t))];
        float err = 0.f;
        for (int ch = 0; ch < 3; ++ch) {
          const float v = albedo.at(x, y)[ch];
          ASSERT_TRUE(std::isfinite(v));
          err = std::max(err, std::abs(io::linearToSrgb(v) * 255.f - float(texel[std::size_t(ch)])));
        }
        best = std::min(best, err);
      }
      ASSERT_LT(best, 1e9f) << "pixel " << x << "," << y << " is on no triangle";
      if (sharedEdgeDistance(card, c) <= 1.5f) {
        ++edgePixels;
        edgeError = std::max(edgeError, best);
        if (best > 2.f) ++wrongEdgePixels;
      } else {
        interiorError = std::max(interiorError, best);
      }
    }
  std::cout << "atlas card albedo: largest error next to a shared edge " << edgeError << "/255 (" << wrongEdgePixels
            << " of " << edgePixels << " edge pixels above 2/255), inside the triangles " << interiorError << "/255\n";
  EXPECT_GT(edgePixels, kSize * kSize / 2);  // the grid's 56 shared edges border most pixels
  EXPECT_LE(edgeError, 2.f);
  EXPECT_LE(interiorError, 2.f);
  EXPECT_EQ(wrongEdgePixels, 0);
}

// The mip level, not only the texel: a 1-texel black and white checker, 64 x 64 texels, minified 3.3x
// (uv continuous across the card, each triangle drawn with its own vertices). Every level from 1 up
// averages to linear 0.5, while the base level alone shows black and white: a pixel next to an edge
// whose quad chose another level than the interior's (a helper invocation's gradient) would show it.
TEST(TextureSeams, MinifiedTextureTakesTheSameMipLevelNextToEdgesAsInside) {
  constexpr int kChecker = 64;
  std::vector<std::uint8_t> texels(kChecker * kChecker * 4);
  for (int y = 0; y < kChecker; ++y)
    for (int x = 0; x < kChecker; ++x) {
      std::uint8_t* p = &texels[std::size_t(y * kChecker + x) * 4];
      p[0] = p[1] = p[2] = (x + y) % 2 ? 255 : 0, p[3] = 255;
    }
  test::GltfBuilder b;
  const int m = b.material({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}, {"metallicFactor", 0.0}}}});
  constexpr float kTexelsPerPixel = 3.3f;  // LOD log2(3.3) = 1.7
  const GridCard card = gridCard(b, m, [&](int, glm::vec2 w, glm::vec2) {
    return glm::vec2(w.x + 1.f, 1.f - w.y) * (kSize / 2.f) * kTexelsPerPixel / float(kChecker);
  });
  b.doc["samplers"] = json::array({{{"magFilter", 9729}, {"minFilter", 9987}}});
  b.doc["textures"] = json::array({{{"source", 0}, {"sampler", 0}}});
  b.doc["images"] = json::array({{{"uri", "data:image/png;base64," + test::base64(test::encodePng(kChecker, kChecker, texels))}}});
  const Scene scene = loadSceneFromMemory(b.gltf());
  ASSERT_TRUE(scene.warnings.empty()) << scene.warnings[0];
  const Image& albedo = aov(renderGridCard(scene, "albedo"), "albedo");
  float edgeError = 0.f, interiorError = 0.f;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      const float v = albedo.at(x, y)[1];
      ASSERT_TRUE(std::isfinite(v));
      const float err = std::abs(io::linearToSrgb(v) - io::linearToSrgb(0.5f)) * 255.f;
      float& worst = sharedEdgeDistance(card, pixelCentreWorld(x, y)) <= 1.5f ? edgeError : interiorError;
      worst = std::max(worst, err);
    }
  std::cout << "minified checker albedo: largest error next to a shared edge " << edgeError
            << "/255, inside the triangles " << interiorError << "/255\n";
  // Levels 1-2 of the checker are 0.5 up to the 8-bit rounding of the mip chain.
  EXPECT_LE(edgeError, 2.f);
  EXPECT_LE(interiorError, 2.f);
}

}  // namespace
}  // namespace radiant
