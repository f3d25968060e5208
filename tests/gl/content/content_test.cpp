// glTF content on screen, with numbers: the default studio lighting of a lightless scene, unlit
// materials, texture transforms moving a known texel to a known pixel, and partial camera overrides.
#include <cmath>

#include <gtest/gtest.h>

#include "renderer/Renderer.h"
#include "renderer/io/ImageIO.h"
#include "renderer/scene/Environment.h"
#include "renderer/scene/GltfLoader.h"
#include "renderer/scene/StudioEnvironment.h"
#include "tests/support/RenderTestSupport.h"
#include "tests/support/SceneBuilder.h"
#include "tests/unit/scene/GltfTestBuilder.h"

namespace radiant {
namespace {

using testing::aov;
using testing::renderer;
using json = nlohmann::json;

api::RenderRequest exrRequest(int size) {
  api::RenderRequest req;
  req.width = req.height = size;
  req.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"beauty"}, false}};
  return req;
}

// ---- default lighting --------------------------------------------------------------------------

TEST(DefaultLighting, StudioMapIsNeutralAndItsMeanIsAsDocumented) {
  const Image& map = studioEnvironment();
  ASSERT_EQ(map.width, kStudioEnvironmentWidth);
  for (std::size_t i = 0; i < map.pixels.size(); i += 3) {
    ASSERT_EQ(map.pixels[i], map.pixels[i + 1]);  // grey: never tints a material
    ASSERT_EQ(map.pixels[i], map.pixels[i + 2]);
    ASSERT_GT(map.pixels[i], 0.f);
  }
  // StudioEnvironment.h: fill 0.5 + 0.3 y above (hemisphere mean 0.65), 0.2 below, so the fill alone
  // averages (0.65 + 0.2) / 2 = 0.425 over the sphere; the key adds 8 * (its smoothstep-weighted solid
  // angle ~0.082 sr) / (4 pi) ~ 0.052 (at most 8 * 0.214 sr / 4 pi = 0.136).
  const float mean = environmentAverage(map).x;
  EXPECT_GT(mean, 0.425f + 0.02f);
  EXPECT_LT(mean, 0.425f + 0.136f);
  // The brightest texel is the key's centre direction (radiance 8 + the fill there).
  EXPECT_NEAR(studioRadiance(glm::normalize(glm::vec3(1.f, 1.25f, 1.f))), 8.f + 0.5f + 0.3f * 1.25f / std::sqrt(3.5625f),
              1e-4f);
}

// A white Lambertian quad facing the camera, no lights: lit by the studio map's mean radiance
// through the ambient pass (L = albedo * mean * AO, AO = 1 on an open plane).
TEST(DefaultLighting, LightlessSceneIsLitAndSaysSo) {
  testing::SceneBuilder b;
  const int m = b.material(testing::lambertian(glm::vec3(0.8f)));
  b.quad({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, m);
  const Scene scene = b.build("lightless");
  api::RenderRequest req = exrRequest(32);
  req.camera = api::CameraOverride{{0, 0, 1.5f}, {0, 0, 0}, {0, 1, 0}, 40.f};
  const RenderOutput out = renderer().render(scene, req);
  EXPECT_EQ(out.stats.lighting, "default");
  const float mean = environmentAverage(studioEnvironment()).x;
  const Image& beauty = aov(out, "beauty");
  // Centre 8x8 pixels, away from the quad's edge where the AO kernel sees the void.
  double sum = 0.0;
  for (int y = 12; y < 20; ++y)
    for (int x = 12; x < 20; ++x) sum += beauty.at(x, y)[1];
  const double centre = sum / 64.0;
  // The bound: the ambient term is exactly 0.8 * mean on an unoccluded plane; 5% covers the AO
  // estimator's noise after its 4x4 blur.
  EXPECT_NEAR(centre, 0.8 * mean, 0.05 * 0.8 * mean);
  // Not black, with margin: at least half the unoccluded value.
  EXPECT_GT(centre, 0.4 * mean);

  // Opting out renders the lightless scene black, and says so.
  req.defaultLighting = false;
  const RenderOutput dark = renderer().render(scene, req);
  EXPECT_EQ(dark.stats.lighting, "none");
  EXPECT_EQ(aov(dark, "beauty").at(16, 16)[1], 0.f);
  // An ambient in the request replaces the default.
  req.defaultLighting = true;
  req.ambient = glm::vec3(0.25f);
  const RenderOutput amb = renderer().render(scene, req);
  EXPECT_EQ(amb.stats.lighting, "ambient");
  EXPECT_NEAR(aov(amb, "beauty").at(16, 16)[1], 0.8 * 0.25, 0.05 * 0.8 * 0.25);
}

// ---- a quad that exactly fills a 32x32 frame: pixel (x, y) sees uv ((x + .5) / 32, (y + .5) / 32) ----

constexpr int kSize = 32;
const api::CameraOverride kFillCamera{{0, 0, 2}, {0, 0, 0}, {0, 1, 0}, 2.f * 26.5650512f};  // tan(fov/2) = 1/2

// A 4x4 texture whose texel (i, j) has sRGB red 85 i and green 85 j: its column and row can be read
// back from a linear pixel colour.
std::vector<std::uint8_t> gridTexels() {
  std::vector<std::uint8_t> t(4 * 4 * 4);
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) {
      std::uint8_t* p = &t[(j * 4 + i) * 4];
      p[0] = std::uint8_t(85 * i);
      p[1] = std::uint8_t(85 * j);
      p[2] = 0;
      p[3] = 255;
    }
  return t;
}

// Which texel column / row a linear value came from (nearest of srgbToLinear(85 k / 255)).
int texelIndex(float linear) {
  int best = 0;
  for (int k = 1; k < 4; ++k)
    if (std::abs(io::srgbToLinear(85.f * k / 255.f) - linear) < std::abs(io::srgbToLinear(85.f * best / 255.f) - linear))
      best = k;
  return best;
}

// The filling quad with an unlit, textured material; `transform` is the KHR_texture_transform object
// (null = none). Nearest filtering and clamping, so a pixel shows exactly one texel.
Scene texturedQuad(const json& transform, bool unlit = true, glm::vec4 baseColor = glm::vec4(1.f)) {
  test::GltfBuilder b;
  json info = {{"index", 0}};
  if (!transform.is_null()) info["extensions"] = {{"KHR_texture_transform", transform}};
  json mat = {{"pbrMetallicRoughness", {{"baseColorTexture", info}, {"metallicFactor", 0.0},
                                        {"baseColorFactor", {baseColor.r, baseColor.g, baseColor.b, baseColor.a}}}}};
  if (unlit) mat["extensions"] = {{"KHR_materials_unlit", json::object()}};
  const int m = b.material(mat);
  const int mesh = b.mesh(json::array({test::trianglePrimitive<std::uint16_t>(
      b, {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}}, {0, 1, 2, 0, 2, 3}, {}, {{0, 1}, {1, 1}, {1, 0}, {0, 0}}, m)}));
  b.scene({b.node({{"name", "card"}, {"mesh", mesh}})});
  b.doc["samplers"] = json::array({{{"magFilter", 9728}, {"minFilter", 9728}, {"wrapS", 33071}, {"wrapT", 33071}}});
  b.doc["textures"] = json::array({{{"source", 0}, {"sampler", 0}}});
  b.doc["images"] = json::array({{{"uri", "data:image/png;base64," + test::base64(test::encodePng(4, 4, gridTexels()))}}});
  b.doc["extensionsUsed"] = json::array({"KHR_texture_transform", "KHR_materials_unlit"});
  return loadSceneFromMemory(b.gltf());
}

RenderOutput renderCard(const Scene& scene, bool withReference = false) {
  api::RenderRequest req = exrRequest(kSize);
  req.camera = kFillCamera;
  if (withReference) req.compare = api::CompareSpec{"reference", "beauty", 4, 2};
  return renderer().render(scene, req);
}

struct Texel { int i, j; };
Texel texelAt(const Image& img, int x, int y) { return {texelIndex(img.at(x, y)[0]), texelIndex(img.at(x, y)[1])}; }

TEST(TextureTransform, OffsetAndScaleMoveAKnownTexelToAKnownPixel) {
  // Without a transform pixel (3, 3) (uv ~ (0.11, 0.11)) shows texel (0, 0) and pixel (28, 3) texel (3, 0).
  const RenderOutput plain = renderCard(texturedQuad(nullptr));
  EXPECT_EQ(texelAt(aov(plain, "beauty"), 3, 3).i, 0);
  EXPECT_EQ(texelAt(aov(plain, "beauty"), 28, 3).i, 3);
  // uv' = (0.5, 0.25) + 0.5 uv: pixel (3, 3) -> uv' (0.555, 0.305) -> texel (2, 1);
  // pixel (28, 20) (uv (0.89, 0.64)) -> uv' (0.945, 0.57) -> texel (3, 2).
  const RenderOutput moved = renderCard(texturedQuad({{"offset", {0.5, 0.25}}, {"scale", {0.5, 0.5}}}), true);
  for (const char* which : {"beauty", "reference"}) {
    SCOPED_TRACE(which);
    const Image& img = aov(moved, which);
    EXPECT_EQ(texelAt(img, 3, 3).i, 2);
    EXPECT_EQ(texelAt(img, 3, 3).j, 1);
    EXPECT_EQ(texelAt(img, 28, 20).i, 3);
    EXPECT_EQ(texelAt(img, 28, 20).j, 2);
    // Unlit + texture: the pixel is the texel's linear value exactly (sRGB decode of 170 = 0.402).
    EXPECT_NEAR(img.at(3, 3)[0], io::srgbToLinear(170.f / 255.f), 2e-3f);
  }
}

TEST(TextureTransform, RotationTurnsUvCounterClockwiseAsTheSpecWrites) {
  // rotation pi/2, offset (1, 0): u' = 1 - v, v' = u (KHR_texture_transform's T R S).
  // Pixel (3, 12) (uv (0.11, 0.39)) -> uv' (0.61, 0.11) -> texel (2, 0); pixel (20, 28) (uv (0.64, 0.89))
  // -> uv' (0.11, 0.64) -> texel (0, 2).
  const RenderOutput turned =
      renderCard(texturedQuad({{"offset", {1.0, 0.0}}, {"rotation", 1.57079632679}}));
  const Image& img = aov(turned, "beauty");
  EXPECT_EQ(texelAt(img, 3, 12).i, 2);
  EXPECT_EQ(texelAt(img, 3, 12).j, 0);
  EXPECT_EQ(texelAt(img, 20, 28).i, 0);
  EXPECT_EQ(texelAt(img, 20, 28).j, 2);
}

// ---- unlit ---------------------------------------------------------------------------------------

TEST(Unlit, EqualsBaseColourWhateverLightsTheScene) {
  // A white texel row (texel (3, 3) is sRGB (255, 255, 0)) times a base colour factor; a bright point
  // light in front would add diffuse and specular light to a lit material.
  Scene scene = texturedQuad(nullptr, true, glm::vec4(0.25f, 0.5f, 0.75f, 1.f));
  Light l;
  l.type = LightType::Point;
  l.intensity = 50.f;
  l.position = {0.3f, 0.2f, 1.f};
  scene.lights.push_back(l);
  scene.features = computeFeatures(scene);
  const RenderOutput out = renderCard(scene, true);
  EXPECT_EQ(out.stats.lighting, "scene");
  for (const char* which : {"beauty", "reference"}) {
    SCOPED_TRACE(which);
    const Image& img = aov(out, which);
    // Pixel (28, 28): texel (3, 3), linear (1, 1, 0) times the factor.
    EXPECT_NEAR(img.at(28, 28)[0], 0.25f, 2e-3f);
    EXPECT_NEAR(img.at(28, 28)[1], 0.5f, 2e-3f);
    EXPECT_NEAR(img.at(28, 28)[2], 0.f, 2e-3f);
  }
  // The same card lit: clearly brighter than its base colour where the light is.
  const RenderOutput lit = [&] {
    Scene s = texturedQuad(nullptr, false, glm::vec4(0.25f, 0.5f, 0.75f, 1.f));
    s.lights = scene.lights;
    s.features = computeFeatures(s);
    return renderCard(s);
  }();
  EXPECT_GT(aov(lit, "beauty").at(28, 28)[1], 0.5f * 1.5f);
}

// ---- camera overrides and stats --------------------------------------------------------------------

TEST(Camera, PartialOverrideKeepsTheAutomaticFramingAndStatsReportIt) {
  testing::SceneBuilder b;
  const int m = b.material(testing::lambertian(glm::vec3(0.8f)));
  b.box({-1, 0, -1}, {1, 2, 1}, m, "crate");
  const Scene scene = b.build("crate");
  api::RenderRequest req = exrRequest(32);
  const RenderOutput automatic = renderer().render(scene, req);
  ASSERT_TRUE(automatic.stats.camera.is_object());
  EXPECT_EQ(automatic.stats.camera["source"], "auto");
  // The automatic camera looks at the bounds centre (0, 1, 0) from +Z.
  EXPECT_NEAR(automatic.stats.camera["target"][1].get<double>(), 1.0, 1e-5);
  const double autoZ = automatic.stats.camera["position"][2].get<double>();
  EXPECT_NEAR(automatic.stats.camera["yfov_deg"].get<double>(), glm::degrees(0.6911), 1e-3);
  // stats.scene: bounds and node names.
  EXPECT_EQ(automatic.stats.scene["bounds"]["min"], json::array({-1.0, 0.0, -1.0}));
  EXPECT_EQ(automatic.stats.scene["bounds"]["max"], json::array({1.0, 2.0, 1.0}));
  EXPECT_EQ(automatic.stats.scene["nodes"].size(), 6u);

  // Only yfov: still framed (looks at the centre), from farther away for a narrower field:
  // the distance to fit a sphere is r / sin(fov/2), so halving tan(fov/2) roughly doubles it.
  api::CameraOverride narrow;
  narrow.hasPosition = narrow.hasTarget = narrow.hasUp = false;
  narrow.yfovDegrees = 20.f;
  req.camera = narrow;
  const RenderOutput zoomed = renderer().render(scene, req);
  EXPECT_EQ(zoomed.stats.camera["source"], "request+auto");
  EXPECT_NEAR(zoomed.stats.camera["yfov_deg"].get<double>(), 20.0, 1e-4);
  EXPECT_NEAR(zoomed.stats.camera["target"][1].get<double>(), 1.0, 1e-5);
  const float r = scene.features.bounds.radius();
  EXPECT_NEAR(zoomed.stats.camera["position"][2].get<double>(), r / std::sin(glm::radians(10.0)), 1e-3);
  EXPECT_GT(zoomed.stats.camera["position"][2].get<double>(), 1.8 * (autoZ));
  // The centre pixel sees the crate (not the sky) in both.
  EXPECT_GT(aov(zoomed, "beauty").at(16, 16)[1], 0.f);

  // Only a position: looks at the bounds centre from there.
  api::CameraOverride moved;
  moved.hasTarget = moved.hasUp = moved.hasYfov = false;
  moved.position = {4.f, 1.f, 0.f};
  req.camera = moved;
  const RenderOutput side = renderer().render(scene, req);
  EXPECT_NEAR(side.stats.camera["forward"][0].get<double>(), -1.0, 1e-5);
  EXPECT_NEAR(side.stats.camera["forward"][1].get<double>(), 0.0, 1e-5);
  EXPECT_NEAR(side.stats.camera["target"][1].get<double>(), 1.0, 1e-5);
  EXPECT_NEAR(side.stats.camera["yfov_deg"].get<double>(), glm::degrees(0.6911), 1e-3);
}

}  // namespace
}  // namespace radiant
