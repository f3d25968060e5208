// Triangle edges on textured models (issue 29, items 1 and 2): the G-buffer's textures and normal maps
// on both sides of every shared edge, with numbers, on small glTF files the tests write.
#include <algorithm>
#include <array>
#include <cmath>
#include <iostream>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "renderer/Renderer.h"
#include "renderer/io/ImageIO.h"
#include "renderer/raytracing/RayScene.h"
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
  const RenderOutput out = renderGridCard(scene, "albedo");
  const Image& albedo = aov(out, "albedo");

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
  const RenderOutput out = renderGridCard(scene, "albedo");
  const Image& albedo = aov(out, "albedo");
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

// ---- 2. normal maps: the normal AOV against the reference's shading normal ---------------------------

// The reference path tracer's shading normal (RayScene::shade: the interpolated, normal-mapped normal)
// at the surface under each pixel centre, seen from the fill camera.
std::vector<glm::vec3> referenceShadingNormals(const Scene& scene) {
  const rt::RayScene rays(scene);
  std::vector<glm::vec3> out(std::size_t(kSize) * kSize, glm::vec3(0.f));
  const glm::vec3 eye(0.f, 0.f, 2.f);
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      rt::Ray ray;
      ray.org = eye;
      ray.dir = glm::normalize(glm::vec3(pixelCentreWorld(x, y), 0.f) - eye);
      rt::SurfaceHit hit;
      rt::Sampler sampler(std::uint64_t(y * kSize + x), 0, 1);
      rt::RayCounter counter;
      if (rays.intersect(ray, hit, sampler, counter)) out[std::size_t(y * kSize + x)] = rays.shade(hit, -ray.dir).frame.n;
    }
  return out;
}

// glTF's tangent-space normal of an 8-bit texel (2 texel / 255 - 1) in the frame (t, b, n), as
// material_decode.glsl's mapTangentNormal maps it.
glm::vec3 mappedNormal(const std::array<std::uint8_t, 3>& texel, glm::vec3 t, glm::vec3 b, glm::vec3 n) {
  const glm::vec3 tn = glm::vec3(texel[0], texel[1], texel[2]) * (2.f / 255.f) - 1.f;
  return glm::normalize(tn.x * t + tn.y * b + tn.z * n);
}

float angleDegrees(glm::vec3 a, glm::vec3 b) {
  const float la = glm::length(a), lb = glm::length(b);
  if (!(la > 0.f) || !(lb > 0.f)) return 180.f;
  return glm::degrees(std::acos(std::clamp(glm::dot(a / la, b / lb), -1.f, 1.f)));
}

// How far the raster's normal AOV and the reference's shading normal are from each other and from the
// closed form, pixel by pixel (the closed form of either triangle for a centre on an edge), split into
// pixels within 1.5 pixels of a shared edge (both sides of it) and the rest.
struct NormalErrors {
  float rasterReferenceEdge = 0.f, rasterReferenceInterior = 0.f;
  float rasterExactEdge = 0.f, rasterExactInterior = 0.f, referenceExact = 0.f;
  int edgePixels = 0;
};

template <class Expected>
NormalErrors normalErrors(const GridCard& card, const Image& normal, const std::vector<glm::vec3>& reference,
                          Expected&& expected) {
  NormalErrors e;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      const glm::vec2 c = pixelCentreWorld(x, y);
      const glm::vec3 raster(normal.at(x, y)[0], normal.at(x, y)[1], normal.at(x, y)[2]);
      EXPECT_TRUE(std::isfinite(raster.x) && std::isfinite(raster.y) && std::isfinite(raster.z));
      const glm::vec3 ref = reference[std::size_t(y * kSize + x)];
      float toRaster = 180.f, toReference = 180.f;
      const std::vector<int> under = trianglesAt(card, c);
      for (int t : under) {
        toRaster = std::min(toRaster, angleDegrees(raster, expected(t, c)));
        toReference = std::min(toReference, angleDegrees(ref, expected(t, c)));
      }
      // A centre on an edge belongs to either triangle (the rasteriser's tie rule and the ray's may pick
      // different ones): there both are held to the closed form only.
      const float between = under.size() == 1 ? angleDegrees(raster, ref) : 0.f;
          const bool edge = sharedEdgeDistance(card, c) <= 1.5f;
      e.edgePixels += edge;
      (edge ? e.rasterReferenceEdge : e.rasterReferenceInterior) =
          std::max(edge ? e.rasterReferenceEdge : e.rasterReferenceInterior, between);
      (edge ? e.rasterExactEdge : e.rasterExactInterior) = std::max(edge ? e.rasterExactEdge : e.rasterExactInterior, toRaster);
      e.referenceExact = std::max(e.referenceExact, toReference);
    }
  return e;
}

void printNormalErrors(const char* what, const NormalErrors& e) {
  std::cout << what << ": raster normal against the reference's shading normal, largest angle " << e.rasterReferenceEdge
            << " degrees next to a shared edge (" << e.edgePixels << " pixels), " << e.rasterReferenceInterior
            << " inside; against the closed form " << e.rasterExactEdge << " / " << e.rasterExactInterior
            << " (raster), " << e.referenceExact << " (reference)\n";
}

// A 16 x 16 normal-map atlas of 4 x 4 regions, each one tilt: 16 directions around the normal, tilted
// by 20-35 degrees.
std::array<std::uint8_t, 3> regionTilt(int region) {
  const float phi = 2.f * std::numbers::pi_v<float> * float(region) / 16.f;
  const float s = 0.35f + 0.1f * float(region % 3);
  const glm::vec3 tn(s * std::cos(phi), s * std::sin(phi), std::sqrt(1.f - s * s));
  std::array<std::uint8_t, 3> texel{};
  for (int c = 0; c < 3; ++c) texel[std::size_t(c)] = std::uint8_t(std::lround((tn[c] + 1.f) * 0.5f * 255.f));
  return texel;
}

std::string normalAtlasPng() {
  std::vector<std::uint8_t> t(kAtlas * kAtlas * 4);
  for (int y = 0; y < kAtlas; ++y)
    for (int x = 0; x < kAtlas; ++x) {
      const auto c = regionTilt((y / kRegion) * (kAtlas / kRegion) + x / kRegion);
      std::uint8_t* p = &t[std::size_t(y * kAtlas + x) * 4];
      p[0] = c[0], p[1] = c[1], p[2] = c[2], p[3] = 255;
    }
  return "data:image/png;base64," + test::base64(test::encodePng(kAtlas, kAtlas, t));
}

// The atlas card with a normal map instead of a base colour: each triangle reads its own region's tilt,
// and every other triangle mirrors its uvs in u (its tangent is -x, its handedness -1), so the frames of
// neighbours differ as well as their texels. No TANGENT in the file: the loader's MikkTSpace frames. The
// closed form: tangent +-x (the way u runs), bitangent +y (the way v falls: up the image), normal +z.
// Before the explicit texture derivatives (docs/GBUFFER.md) the raster's edge pixels read a coarse mip of
// the normal map: 33.5 degrees off the reference next to the edges (0.02 inside); now 0.02 everywhere.
TEST(NormalMapSeams, NormalAovMatchesTheReferencesShadingNormalOnBothSidesOfEveryEdge) {
  test::GltfBuilder b;
  const int m = b.material({{"normalTexture", {{"index", 0}}}, {"pbrMetallicRoughness", {{"metallicFactor", 0.0}}}});
  auto mirrored = [](int t) { return t % 2 == 1; };
  const GridCard card = gridCard(b, m, [&](int t, glm::vec2, glm::vec2 place) {
    if (mirrored(t)) place.x = 1.f - place.x;
    return atlasUv(t, {}, place);
  });
  b.doc["samplers"] = json::array({{{"magFilter", 9729}, {"minFilter", 9987}}});
  b.doc["textures"] = json::array({{{"source", 0}, {"sampler", 0}}});
  b.doc["images"] = json::array({{{"uri", normalAtlasPng()}}});
  const Scene scene = loadSceneFromMemory(b.gltf());
  ASSERT_TRUE(scene.warnings.empty()) << scene.warnings[0];
  ASSERT_FALSE(scene.meshes[0].tangents.empty());

  const RenderOutput out = renderGridCard(scene, "normal");
  const Image& normal = aov(out, "normal");
  const NormalErrors e = normalErrors(card, normal, referenceShadingNormals(scene), [&](int t, glm::vec2) {
    return mappedNormal(regionTilt(atlasRegion(t)), glm::vec3(mirrored(t) ? -1.f : 1.f, 0.f, 0.f), {0, 1, 0}, {0, 0, 1});
  });
  printNormalErrors("normal-map atlas card", e);
  // Bounds: the normal AOV is stored in half floats (11-bit mantissa: 0.03 degrees), the texels are the
  // same bytes in both languages; 0.25 degrees leaves room for the texture unit's filtering arithmetic.
  // A neighbouring region's tilt is 15 degrees or more away.
  EXPECT_GT(e.edgePixels, kSize * kSize / 2);
  EXPECT_LT(e.rasterReferenceEdge, 0.25f);
  EXPECT_LT(e.rasterReferenceInterior, 0.25f);
  EXPECT_LT(e.rasterExactEdge, 0.25f);
  EXPECT_LT(e.rasterExactInterior, 0.25f);
  EXPECT_LT(e.referenceExact, 0.25f);
}

// Mirrored uvs on shared vertices (the modelling trick of symmetric models): one 1x1 normal map, u = |x| / 2
// on a 4 x 4 grid whose vertices on x = 0 are shared by both halves, no TANGENT. MikkTSpace gives each half
// its own frame (the loader splits the seam's vertices); the normal AOV and the reference must show the
// texel's tilt mapped with tangent +x on the right, -x on the left, on both sides of the seam and of every
// other edge. Lengyel's per-vertex tangents cancelled on the seam (+x + -x) and bent the frames of the
// triangles next to it, in the raster and in the reference alike: 50.4 degrees off the closed form in
// both (the 1x1 map has no mip to get wrong); now 0.
TEST(NormalMapSeams, MirroredUvsOnSharedVerticesMapTheNormalInEachHalfsOwnFrame) {
  const std::array<std::uint8_t, 3> texel{200, 90, 230};
  test::GltfBuilder b;
  const int m = b.material({{"normalTexture", {{"index", 0}}}, {"pbrMetallicRoughness", {{"metallicFactor", 0.0}}}});
  constexpr int kCells = 4;
  std::vector<glm::vec3> p, n;
  std::vector<glm::vec2> uv;
  std::vector<std::uint16_t> idx;
  GridCard card;
  for (int j = 0; j <= kCells; ++j)
    for (int i = 0; i <= kCells; ++i) {
      const glm::vec2 w(-1.f + 2.f * i / kCells, -1.f + 2.f * j / kCells);
      p.emplace_back(w, 0.f);
      n.emplace_back(0.f, 0.f, 1.f);
      uv.emplace_back(0.5f * std::abs(w.x), 0.5f * (1.f - w.y));
    }
  auto at = [](int i, int j) { return static_cast<std::uint16_t>(j * (kCells + 1) + i); };
  for (int j = 0; j < kCells; ++j)
    for (int i = 0; i < kCells; ++i) {
      const std::array<std::uint16_t, 4> q{at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)};
      const bool flip = (i + j) % 2 == 1;
      const std::array<std::array<int, 3>, 2> tris = flip ? std::array<std::array<int, 3>, 2>{{{0, 1, 3}, {1, 2, 3}}}
                                                          : std::array<std::array<int, 3>, 2>{{{0, 1, 2}, {0, 2, 3}}};
      for (const auto& tri : tris) {
        std::array<glm::vec2, 3> world{};
        for (int k = 0; k < 3; ++k) {
          idx.push_back(q[std::size_t(tri[std::size_t(k)])]);
          world[std::size_t(k)] = glm::vec2(p[idx.back()]);
        }
        card.triangles.push_back(world);
      }
    }
  const int mesh = b.mesh(json::array({test::trianglePrimitive<std::uint16_t>(b, p, idx, n, uv, m)}));
  b.scene({b.node({{"name", "mirrored card"}, {"mesh", mesh}})});
  b.doc["textures"] = json::array({{{"source", 0}}});
  b.doc["images"] = json::array(
      {{{"uri", "data:image/png;base64," + test::base64(test::encodePng(1, 1, {texel[0], texel[1], texel[2], 255}))}}});
  const Scene scene = loadSceneFromMemory(b.gltf());
  ASSERT_TRUE(scene.warnings.empty()) << scene.warnings[0];

  const RenderOutput out = renderGridCard(scene, "normal");
  const Image& normal = aov(out, "normal");
  const NormalErrors e = normalErrors(card, normal, referenceShadingNormals(scene), [&](int t, glm::vec2) {
    const auto& w = card.triangles[std::size_t(t)];
    const bool right = w[0].x + w[1].x + w[2].x > 0.f;
    return mappedNormal(texel, glm::vec3(right ? 1.f : -1.f, 0.f, 0.f), {0, 1, 0}, {0, 0, 1});
  });
  printNormalErrors("mirrored-uv card", e);
  EXPECT_LT(e.rasterReferenceEdge, 0.25f);
  EXPECT_LT(e.rasterReferenceInterior, 0.25f);
  EXPECT_LT(e.rasterExactEdge, 0.25f);
  EXPECT_LT(e.rasterExactInterior, 0.25f);
  EXPECT_LT(e.referenceExact, 0.25f);
}

}  // namespace
}  // namespace radiant
