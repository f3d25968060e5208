// glTF content on screen, with numbers: the default-lighting rule (studio environment unless the scene
// has punctual lights), the background (transparent, a colour), unlit
// materials, texture transforms moving a known texel to a known pixel, and partial camera overrides.
#include <array>
#include <atomic>
#include <cmath>

#include <glm/gtc/type_ptr.hpp>
#include <gtest/gtest.h>

#include "renderer/Renderer.h"
#include "renderer/io/ImageIO.h"
#include "renderer/scene/BuiltinScenes.h"
#include "renderer/scene/Environment.h"
#include "renderer/scene/GltfLoader.h"
#include "renderer/scene/MaterialDecode.h"
#include "renderer/raytracing/Bsdf.h"
#include "renderer/scene/StudioEnvironment.h"
#include "renderer/shading/ImageBasedLighting.h"
#include "tests/support/RenderTestSupport.h"
#include "tests/support/SceneBuilder.h"
#include "tests/unit/scene/GltfTestBuilder.h"

namespace radiant {
namespace {

using testing::aov;
using testing::renderer;
using json = nlohmann::json;
using rt::GltfBsdf;

using testing::exrRequest;

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

// A white Lambertian quad facing the camera (+Z), no lights: lit by the studio map through the ambient
// pass, L = albedo * E(+Z) / pi * AO with E the map's SH irradiance (AO = 1 on an open plane); the
// split-sum specular adds B(1, 1) Lpre ~ 1e-3 for this F0 = 0 material.
TEST(DefaultLighting, LightlessSceneIsLitAndSaysSo) {
  testing::SceneBuilder b;
  const int m = b.material(testing::lambertian(glm::vec3(0.8f)));
  b.quad({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, m);
  const Scene scene = b.build("lightless");
  api::RenderRequest req = exrRequest(32);
  req.camera = api::CameraOverride{{0, 0, 1.5f}, {0, 0, 0}, {0, 1, 0}, 40.f};
  req.disabledPasses.insert("photon_gi");  // measures the raster's IBL/AO terms; photon_gi would own L(sky)DE
  const RenderOutput out = renderer().render(scene, req);
  EXPECT_EQ(out.stats.lighting, "default");
  const float mean = environmentAverage(studioEnvironment()).x;
  const float irradiance = ibl::irradianceFromSh(ibl::irradianceSh(studioEnvironment()), {0, 0, 1}).x;
  const Image& beauty = aov(out, "beauty");
  // Centre 8x8 pixels, away from the quad's edge where the AO kernel sees the void.
  double sum = 0.0;
  for (int y = 12; y < 20; ++y)
    for (int x = 12; x < 20; ++x) sum += beauty.at(x, y)[1];
  const double centre = sum / 64.0;
  // The bound: the diffuse term is exactly 0.8 E / pi on an unoccluded plane; 5% covers the AO
  // estimator's noise after its 4x4 blur and the specular term.
  const double expected = 0.8 * irradiance / glm::pi<float>();
  EXPECT_NEAR(centre, expected, 0.05 * expected);
  // Not black, with margin: the studio lights a white surface facing any direction with at least its
  // floor's 0.2 (E / pi >= 0.2 where the floor fills the hemisphere), so at least 0.8 * 0.2 / 2 here.
  EXPECT_GT(centre, 0.08);
  EXPECT_GT(expected, 0.8 * mean);  // the key faces this plane: brighter than the mean

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

// ---- the default-lighting rule (issue 29, item 7) --------------------------------------------------

// The white quad of LightlessSceneIsLitAndSaysSo seen head-on, and what the studio map gives it.
const api::CameraOverride kQuadCamera{{0, 0, 1.5f}, {0, 0, 0}, {0, 1, 0}, 40.f};
double studioLitWhite() {  // 0.8 E(+Z) / pi
  return 0.8 * ibl::irradianceFromSh(ibl::irradianceSh(studioEnvironment()), {0, 0, 1}).x / glm::pi<float>();
}
double centreMean(const RenderOutput& out) {  // green over the centre 8x8 pixels of a 32x32 beauty
  const Image& beauty = aov(out, "beauty");
  double sum = 0.0;
  for (int y = 12; y < 20; ++y)
    for (int x = 12; x < 20; ++x) sum += beauty.at(x, y)[1];
  return sum / 64.0;
}

// An emissive surface is no lighting set-up: DamagedHelmet's visor made its file count as lit, and it
// rendered black. A white quad facing the camera and, behind it and facing away (it lights nothing the
// camera sees), an emissive quad: the studio map lights the white quad exactly as when it is alone.
TEST(DefaultLighting, EmissiveOnlySceneIsLitByTheStudioEnvironment) {
  testing::SceneBuilder b;
  const int white = b.material(testing::lambertian(glm::vec3(0.8f)));
  Material glow = testing::lambertian(glm::vec3(0.f));
  glow.emissiveFactor = glm::vec3(4.f);
  const int emissive = b.material(glow);
  b.quad({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, white);
  b.quad({0, 0, -1}, {0, 0.25f, 0}, {0.25f, 0, 0}, emissive, "visor");  // normal -Z
  const Scene scene = b.build("emissive-only");
  ASSERT_TRUE(scene.lights.empty());
  ASSERT_TRUE(scene.features.hasEmissive());
  api::RenderRequest req = exrRequest(32);
  req.camera = kQuadCamera;
  req.disabledPasses.insert("photon_gi");  // the raster's IBL/AO terms, as LightlessSceneIsLitAndSaysSo
  const RenderOutput out = renderer().render(scene, req);
  EXPECT_EQ(out.stats.lighting, "scene+default");
  EXPECT_EQ(out.stats.lightingReason,
            "the scene has no punctual lights (its emissive surfaces light little beyond themselves), and the "
            "request names no ambient or environment; with the scene's own emissive surfaces");
  // 0.8 E / pi within LightlessSceneIsLitAndSaysSo's 5% (AO noise, the F0 = 0 specular); black before.
  EXPECT_NEAR(centreMean(out), studioLitWhite(), 0.05 * studioLitWhite());

  // Opting out keeps the scene's own light only: the emitter faces away, so the quad is black.
  req.defaultLighting = false;
  const RenderOutput own = renderer().render(scene, req);
  EXPECT_EQ(own.stats.lighting, "scene");
  EXPECT_EQ(own.stats.lightingReason, "default_lighting is false: the scene's own emissive surfaces");
  EXPECT_EQ(aov(own, "beauty").at(16, 16)[1], 0.f);
}

// A file whose only light is a directional key (GlamVelvetSofa's 3 lux) keeps exactly its own light, as
// the reference renders it (docs/API.md, "Default lighting"): a 1 lux key straight onto the white quad
// gives 0.8 * 1 / pi, the same frame as with the default lighting turned off.
TEST(DefaultLighting, KeyLightOnlySceneKeepsItsOwnLight) {
  testing::SceneBuilder b;
  b.quad({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, b.material(testing::lambertian(glm::vec3(0.8f))));
  b.directionalLight({0, 0, -1}, 1.f);
  const Scene scene = b.build("key-only");
  api::RenderRequest req = exrRequest(32);
  req.camera = kQuadCamera;
  req.disabledPasses.insert("photon_gi");
  const RenderOutput out = renderer().render(scene, req);
  EXPECT_EQ(out.stats.lighting, "scene");
  EXPECT_EQ(out.stats.lightingReason,
            "the scene has punctual lights, a lighting set-up of its own (a room such as the Cornell boxes): "
            "the scene's own lights");
  const double key = 0.8 / glm::pi<double>();
  EXPECT_NEAR(centreMean(out), key, 0.02 * key);
  req.defaultLighting = false;
  const RenderOutput own = renderer().render(scene, req);
  EXPECT_EQ(own.stats.lighting, "scene");
  EXPECT_EQ(centreMean(own), centreMean(out));
}

// Point and spot lights are a lighting set-up of their own (a closed room): the built-in Cornell box is
// rendered bit for bit as with the default lighting turned off.
TEST(DefaultLighting, PointLightsKeepTheirOwnLightAndTheCornellBoxIsUnchanged) {
  const Scene scene = loadBuiltinScene("cornell_box");
  ASSERT_FALSE(scene.lights.empty());
  api::RenderRequest req = exrRequest(32);
  const RenderOutput lit = renderer().render(scene, req);
  EXPECT_EQ(lit.stats.lighting, "scene");
  EXPECT_EQ(lit.stats.lightingReason,
            "the scene has punctual lights, a lighting set-up of its own (a room such as the Cornell boxes): "
            "the scene's own lights");
  req.defaultLighting = false;
  const RenderOutput own = renderer().render(scene, req);
  EXPECT_EQ(own.stats.lighting, "scene");
  EXPECT_EQ(aov(lit, "beauty").pixels, aov(own, "beauty").pixels);
}

// ---- background (issue 29, item 8) -----------------------------------------------------------------

// A white quad of half-size 1/2 in a frame of half-size 1 (kFillCamera below): it covers exactly pixels
// 8..23 of 32 in x and y, with its edges on pixel (and supersample) boundaries, so every pixel is
// covered wholly or not at all.
TEST(Background, TransparentIsCoverageAndAColourShowsWhereNothingIsHit) {
  testing::SceneBuilder b;
  b.quad({0, 0, 0}, {0.5f, 0, 0}, {0, 0.5f, 0}, b.material(testing::lambertian(glm::vec3(0.8f))));
  const Scene scene = b.build("background-card");
  api::RenderRequest req = exrRequest(32);
  req.camera = api::CameraOverride{{0, 0, 2}, {0, 0, 0}, {0, 1, 0}, 2.f * 26.5650512f};
  req.disabledPasses.insert("photon_gi");
  const RenderOutput sky = renderer().render(scene, req);
  EXPECT_THROW(aov(sky, "alpha"), std::runtime_error) << "no alpha unless asked for";
  auto covered = [](int x, int y) { return x >= 8 && x < 24 && y >= 8 && y < 24; };

  req.background.kind = api::Background::Kind::Transparent;
  const RenderOutput clear = renderer().render(scene, req);
  const Image& alpha = aov(clear, "alpha");
  const Image& beauty = aov(clear, "beauty");
  ASSERT_EQ(alpha.channels, 1);
  int mismatches = 0;
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) {
      const float* p = beauty.at(x, y);
      const float* s = aov(sky, "beauty").at(x, y);
      if (covered(x, y))  // alpha 1 and the surface's colour, as with the sky behind it
        mismatches += alpha.at(x, y)[0] != 1.f || p[0] != s[0] || p[1] != s[1] || p[2] != s[2];
      else  // alpha 0 and colour 0 (premultiplied), where the sky was not black
        mismatches += alpha.at(x, y)[0] != 0.f || p[0] != 0.f || p[1] != 0.f || p[2] != 0.f || s[1] <= 0.f;
    }
  EXPECT_EQ(mismatches, 0);
  // The PNG: RGBA with alpha 0 off the quad and 255 on it.
  io::PngOptions png;
  png.toneMap = api::ToneMap::Aces;
  png.alpha = &alpha;
  const std::string bytes = io::encodePng(beauty, png);
  const Image a = io::decodeImage(bytes, "alpha");
  ASSERT_EQ(a.width, 32);
  EXPECT_EQ(a.at(0, 0)[0], 0.f);
  EXPECT_EQ(a.at(7, 16)[0], 0.f);
  EXPECT_EQ(a.at(8, 16)[0], 1.f);  // 255 / 255
  EXPECT_EQ(a.at(23, 23)[0], 1.f);
  EXPECT_EQ(a.at(24, 23)[0], 0.f);

  // A colour: shown exactly where nothing is hit, the quad unchanged.
  req.background = api::Background{api::Background::Kind::Colour, glm::vec3(0.25f, 0.5f, 2.f)};
  const RenderOutput coloured = renderer().render(scene, req);
  EXPECT_THROW(aov(coloured, "alpha"), std::runtime_error);
  mismatches = 0;
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) {
      const float* p = aov(coloured, "beauty").at(x, y);
      const glm::vec3 shown = covered(x, y) ? glm::make_vec3(aov(sky, "beauty").at(x, y)) : glm::vec3(0.25f, 0.5f, 2.f);
      mismatches += glm::make_vec3(p) != shown;
    }
  EXPECT_EQ(mismatches, 0);
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
  // Raster lookups only: photon_gi splats the default sky's photons on the unlit card's G-buffer stand-in.
  req.disabledPasses.insert("photon_gi");
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

TEST(Unlit, AMirrorReflectsTheUnlitBaseColour) {
  // A white mirror floor seen straight down reflects an unlit ceiling above the camera: Schlick F = 1
  // for a white metal, so the reflection is the ceiling's base colour exactly, with no light anywhere
  // (default lighting off: a shaded ceiling would be black).
  testing::SceneBuilder b;
  Material mirror;
  mirror.metallicFactor = 1.f;
  mirror.roughnessFactor = 0.f;
  Material ceiling = testing::lambertian(glm::vec3(0.2f, 0.4f, 0.6f));
  ceiling.unlit = true;
  ceiling.doubleSided = true;
  b.quad({0, 0, 0}, {50, 0, 0}, {0, 0, -50}, b.material(mirror), "mirror");
  b.quad({0, 3, 0}, {50, 0, 0}, {0, 0, 50}, b.material(ceiling), "ceiling");  // faces down, behind the camera
  b.topDownOrtho(2.f, 1.f);
  const Scene scene = b.build("unlit-mirror");
  api::RenderRequest req = exrRequest(8);
  req.defaultLighting = false;
  req.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"beauty", "specular"}, false}};
  const RenderOutput out = renderer().render(scene, req);
  const Image& spec = aov(out, "specular");
  for (int y = 2; y < 6; ++y)
    for (int x = 2; x < 6; ++x) {
      EXPECT_NEAR(spec.at(x, y)[0], 0.2f, 2e-3f);
      EXPECT_NEAR(spec.at(x, y)[1], 0.4f, 2e-3f);
      EXPECT_NEAR(spec.at(x, y)[2], 0.6f, 2e-3f);
    }
}

// ---- KHR_materials_volume ------------------------------------------------------------------------------

// A glTF file: an absorbing glass slab (mesh 2 x 2 x 0.2, KHR_materials_volume c = (0.5, 0.8, 1) at
// attenuationDistance 0.2) in a node scaled by `scale` along z, between an orthographic camera and a back
// emitter, an emitter behind the camera. attenuationDistance is in world units and the rays cross the
// scaled slab, 0.2 scale thick: a = c^scale per crossing, so the specular AOV is the slab test's four
// paths F E + (1-F)^2 a back + (1-F)^2 F a^2 E + (1-F)^2 F^2 a^3 back (specular_test), from the file.
TEST(Volume, GltfSlabAbsorbsOverItsWorldThicknessInTheRaster) {
  const glm::vec3 c(0.5f, 0.8f, 1.f), E(1.f, 0.8f, 0.6f), back(0.5f, 0.25f, 0.125f);
  for (float scale : {1.f, 2.f}) {
    test::GltfBuilder b;
    const int glass = b.material({{"pbrMetallicRoughness", {{"metallicFactor", 0.0}, {"roughnessFactor", 0.0}}},
                                  {"extensions",
                                   {{"KHR_materials_transmission", {{"transmissionFactor", 1.0}}},
                                    {"KHR_materials_volume",
                                     {{"thicknessFactor", 0.2}, {"attenuationDistance", 0.2}, {"attenuationColor", {c.r, c.g, c.b}}}}}}});
    auto emitter = [&](glm::vec3 e) {
      return b.material({{"pbrMetallicRoughness", {{"baseColorFactor", {0, 0, 0, 1}}, {"metallicFactor", 1.0}}},
                         {"emissiveFactor", {e.r, e.g, e.b}}, {"doubleSided", true}});
    };
    const int front = emitter(E), rear = emitter(back);
    std::vector<glm::vec3> p, n;
    std::vector<std::uint16_t> idx;
    auto face = [&](glm::vec3 centre, glm::vec3 u, glm::vec3 v) {  // counter-clockwise around u x v
      const auto base = static_cast<std::uint16_t>(p.size());
      for (glm::vec2 k : {glm::vec2(-1, -1), glm::vec2(1, -1), glm::vec2(1, 1), glm::vec2(-1, 1)}) {
        p.push_back(centre + k.x * u + k.y * v);
        n.push_back(glm::normalize(glm::cross(u, v)));
      }
      for (int i : {0, 1, 2, 0, 2, 3}) idx.push_back(static_cast<std::uint16_t>(base + i));
    };
    const glm::vec3 X(1, 0, 0), Y(0, 1, 0), Z(0, 0, 0.1f);
    face(Z, X, Y), face(-Z, Y, X), face(X, Y, Z), face(-X, Z, Y), face(Y, Z, X), face(-Y, X, Z);
    const int slab = b.mesh(json::array({test::trianglePrimitive<std::uint16_t>(b, p, idx, n, {}, glass)}));
    auto quad = [&](float z, int material) {
      return b.mesh(json::array({test::trianglePrimitive<std::uint16_t>(
          b, {{-3, -3, z}, {3, -3, z}, {3, 3, z}, {-3, 3, z}}, {0, 1, 2, 0, 2, 3}, {}, {}, material)}));
    };
    const int frontQuad = quad(4.f, front), rearQuad = quad(-4.f, rear);
    b.doc["cameras"] = json::array({{{"type", "orthographic"},
                                     {"orthographic", {{"xmag", 0.6}, {"ymag", 0.6}, {"znear", 0.01}, {"zfar", 10.0}}}}});
    b.scene({b.node({{"name", "slab"}, {"mesh", slab}, {"scale", {1.0, 1.0, scale}}}),
             b.node({{"mesh", frontQuad}}), b.node({{"mesh", rearQuad}}),
             b.node({{"camera", 0}, {"translation", {0.0, 0.0, 2.0}}})});
    b.doc["extensionsUsed"] = json::array({"KHR_materials_transmission", "KHR_materials_volume"});
    Scene scene = loadSceneFromMemory(b.gltf());
    ASSERT_TRUE(scene.warnings.empty()) << scene.warnings[0];
    const int size = 17;
    api::RenderRequest req = exrRequest(size);
    req.defaultLighting = false;
    req.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"beauty", "specular"}, false}};
    req.passes["specular"] = {{"cube_resolution", 256}, {"max_depth", 4}};
    const RenderOutput out = renderer().render(scene, req);
    const Image& spec = aov(out, "specular");
    const float F = 0.04f, T2 = (1 - F) * (1 - F);
    for (int y = size / 4; y < 3 * size / 4; y += 2)
      for (int x = size / 4; x < 3 * size / 4; x += 2)
        for (int k = 0; k < 3; ++k) {
          const float a = std::pow(c[k], scale);
          const float expected = F * E[k] + T2 * a * back[k] + T2 * F * a * a * E[k] + T2 * F * F * a * a * a * back[k];
          ASSERT_TRUE(std::isfinite(spec.at(x, y)[k]));
          // 2%: the specular pass's bound on a glass slab (specular_test).
          EXPECT_NEAR(spec.at(x, y)[k], expected, 0.02f * expected) << "scale " << scale << " pixel " << x << "," << y << " channel " << k;
        }
  }
}

// ---- image-based lighting: the white furnace ---------------------------------------------------------

// Directional albedo of the glTF BSDF at n.v = mu, by the ray-tracing core's own sampler (renderer/raytracing/
// Bsdf.h: an implementation independent of the raster's tables): the mean of f cos / pdf.
float directionalAlbedo(const GltfBsdf& bsdf, float mu, int n = 20000) {
  const glm::vec3 wo(std::sqrt(std::max(0.f, 1.f - mu * mu)), 0.f, mu);
  double sum = 0.0;
  std::uint32_t state = 12345u;
  auto next = [&] {
    state = state * 1664525u + 1013904223u;
    return float(state >> 8) / 16777216.f;
  };
  for (int i = 0; i < n; ++i) {
    GltfBsdf::Sample s;
    if (bsdf.sample(wo, next(), next(), {(i + next()) / n, next()}, s) && s.wi.z > 0.f) sum += s.weight.g;
  }
  return float(sum / n);
}

// A sphere under a uniform environment map of radiance 1 reflects, at each pixel, its directional
// albedo E(n.v): the raster's split-sum specular (direct) plus SH irradiance diffuse (ambient_occlusion,
// AO = 1 on a convex sphere) must give it. Bound 2% (the brief), on the mean over the pixels with
// n.v > 0.2 (at grazing angles the 32x32 table and the AO kernel at the silhouette dominate).
void whiteFurnace(const Material& material, const std::string& name, double* meanErr, double* maxErr) {
  testing::SceneBuilder b;
  b.sphere({0, 0, 0}, 1.f, b.material(material), 96, 48);
  const Scene scene = b.build(name);
  Image env = Image::make("environment", 32, 16, 3);
  for (float& v : env.pixels) v = 1.f;
  api::RenderRequest req;
  req.width = req.height = 64;
  req.environment = "sha256:" + std::string(64, 'f');
  req.camera = api::CameraOverride{{0, 0, 4}, {0, 0, 0}, {0, 1, 0}, 35.f};
  req.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"beauty", "normal"}, false}};
  req.passes["ambient_occlusion"] = nlohmann::json{{"radius", 0.2}};
  req.disabledPasses.insert("photon_gi");  // the raster's split-sum + SH terms alone (photon_gi owns L(sky)DE)
  const RenderOutput out = renderer().render(scene, req, nullptr, FrameInputs{nullptr, &env});
  const Image& beauty = aov(out, "beauty");
  const Image& normal = aov(out, "normal");
  GltfBsdf bsdf;
  bsdf.baseColor = glm::vec3(material.baseColorFactor);
  bsdf.metallic = material.metallicFactor;
  bsdf.roughness = material.roughnessFactor;
  bsdf.ior = material.ior;
  bsdf.eta = material.ior;
  // The layers as the decoder gives them (factors only here; the coat normal is the sphere's normal).
  const gpu::MaterialParams layers = decodeBsdfInputs(material, [](const TextureRef&, bool) { return glm::vec4(1.f); });
  bsdf.clearcoat = layers.clearcoat.x;
  bsdf.clearcoatRoughness = layers.clearcoat.y;
  bsdf.sheenColor = glm::vec3(layers.sheen);
  bsdf.sheenRoughness = layers.sheen.w;
  bsdf.specularColor = glm::vec3(layers.specular);
  bsdf.specularWeight = layers.specular.w;
  std::vector<float> table(21);
  for (int k = 0; k <= 20; ++k) table[std::size_t(k)] = directionalAlbedo(bsdf, std::max(0.05f * k, 1e-3f));
  const float t = std::tan(glm::radians(17.5f));
  double sum = 0.0, worst = 0.0;
  int count = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const glm::vec3 n(normal.at(x, y)[0], normal.at(x, y)[1], normal.at(x, y)[2]);
      if (glm::length(n) < 0.5f) continue;
      const glm::vec3 dir = glm::normalize(glm::vec3((2.f * (x + 0.5f) / 64.f - 1.f) * t, (1.f - 2.f * (y + 0.5f) / 64.f) * t, -1.f));
      const float mu = glm::dot(n, -dir);
      if (mu < 0.2f) continue;
      const float f = mu / 0.05f;
      const int k = std::min(int(f), 19);
      const float expected = table[std::size_t(k)] + (f - k) * (table[std::size_t(k) + 1] - table[std::size_t(k)]);
      const double err = std::abs(beauty.at(x, y)[1] - expected) / expected;
      sum += err;
      worst = std::max(worst, err);
      ++count;
    }
  ASSERT_GT(count, 500);
  *meanErr = sum / count;
  *maxErr = worst;
}

TEST(ImageBasedLighting, WhiteFurnaceRoughMetalAndLambertGiveTheirDirectionalAlbedo) {
  Material metal;
  metal.baseColorFactor = glm::vec4(1.f);
  metal.metallicFactor = 1.f;
  metal.roughnessFactor = 1.f;
  double meanErr = 0, maxErr = 0;
  whiteFurnace(metal, "furnace-metal", &meanErr, &maxErr);
  std::cout << "rough metal: mean relative error " << meanErr << ", max " << maxErr << "\n";
  EXPECT_LT(meanErr, 0.02);
  whiteFurnace(testing::lambertian(glm::vec3(1.f)), "furnace-lambert", &meanErr, &maxErr);
  std::cout << "lambert: mean relative error " << meanErr << ", max " << maxErr << "\n";
  EXPECT_LT(meanErr, 0.02);
}

TEST(ImageBasedLighting, WhiteFurnaceLayeredDielectricGivesItsDirectionalAlbedo) {
  // KHR_materials_clearcoat, _sheen and _specular under a uniform sky: the direct pass's layered
  // split-sum and ambient_occlusion's diffuse base, attenuated by the layers as the split-sum
  // attenuates the base's specular (ibl.glsl's layered iblDiffuseWeight), against the directional
  // albedo of the reference's BSDF (rt::GltfBsdf with the same layers). The split-sum takes the
  // layers' attenuation of the base at mu alone (the BSDF's sheen scaling is min over both directions):
  // measured 3.4% mean, bound 4%. With the layers left out of the AO term (as before 2026-12-02) the
  // same sphere was 13.6% off.
  Material m = testing::lambertian(glm::vec3(0.6f));
  m.ior = 1.5f;
  m.roughnessFactor = 0.5f;
  m.clearcoatFactor = 1.f;
  m.clearcoatRoughnessFactor = 0.3f;
  m.sheenColorFactor = glm::vec3(0.5f);
  m.sheenRoughnessFactor = 0.5f;
  m.specularFactor = 0.5f;
  m.specularColorFactor = glm::vec3(1.f, 0.8f, 0.6f);
  double meanErr = 0, maxErr = 0;
  whiteFurnace(m, "furnace-layered", &meanErr, &maxErr);
  std::cout << "layered dielectric: mean relative error " << meanErr << ", max " << maxErr << "\n";
  EXPECT_LT(meanErr, 0.04);
}

TEST(ImageBasedLighting, TablesMatchTheirClosedForms) {
  const glm::vec3 d = ibl::dfgAt(1.f, 0.f, 4096);
  // A smooth metal (roughness -> 0) reflects everything: A + B -> 1; head-on Fc(1) = 0 so B -> 0.
  EXPECT_NEAR(d.x + d.y, 1.f, 0.01f);
  EXPECT_NEAR(d.y, 0.f, 1e-3f);
  // Uniform map: SH irradiance is pi in every direction, and the prefiltered map is 1 at every level.
  Image env = Image::make("e", 16, 8, 3);
  for (float& v : env.pixels) v = 1.f;
  const auto sh = ibl::irradianceSh(env);
  for (const glm::vec3 n : {glm::vec3(0, 1, 0), glm::vec3(0, -1, 0), glm::normalize(glm::vec3(1, 2, -3))})
    EXPECT_NEAR(ibl::irradianceFromSh(sh, n).x, glm::pi<float>(), 1e-3f);  // midpoint rule at 512 x 256
  const std::vector<float> pre = ibl::prefilterEnvironment(env);
  for (std::size_t i = 0; i < pre.size(); i += 4) ASSERT_NEAR(pre[i], 1.f, 1e-5f);
  // Directional: a map bright only above (L = 1 for y > 0) gives a normal pointing up E = pi and one
  // pointing down E = 0, each within the SH l <= 2 truncation (Ramamoorthi and Hanrahan: ~3% of pi).
  Image sky = Image::make("sky", 64, 32, 3);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 64; ++x) sky.at(x, y)[0] = sky.at(x, y)[1] = sky.at(x, y)[2] = 1.f;
  const auto s2 = ibl::irradianceSh(sky);
  EXPECT_NEAR(ibl::irradianceFromSh(s2, {0, 1, 0}).x, glm::pi<float>(), 0.1f * glm::pi<float>());
  EXPECT_NEAR(ibl::irradianceFromSh(s2, {0, -1, 0}).x, 0.f, 0.1f * glm::pi<float>());
  EXPECT_NEAR(ibl::irradianceFromSh(s2, {1, 0, 0}).x, 0.5f * glm::pi<float>(), 0.05f * glm::pi<float>());
}

// A map one texel wide (issue 30: a 1 x 6000 EXR held the render thread 90 s, deaf to the deadline):
// the irradiance integral samples each axis to its own density, so the map's SH equal those of the same
// map 64 texels wide (each row repeated) within the midpoint rule's error; a raised cancel flag stops
// both the SH and the prefilter (rt::Cancelled).
TEST(ImageBasedLighting, AOneTexelWideMapIntegratesAsItsWideningAndStopsWhenCancelled) {
  constexpr int kHeight = 6000;
  Image thin = Image::make("thin", 1, kHeight, 3), wide = Image::make("wide", 64, kHeight, 3);
  for (int y = 0; y < kHeight; ++y) {
    const float v = 1.f + float(y % 7) + (y < kHeight / 3 ? 4.f : 0.f);  // brighter above: l = 1 terms
    for (int c = 0; c < 3; ++c) thin.at(0, y)[c] = v * (1.f + 0.5f * c);
    for (int x = 0; x < 64; ++x)
      for (int c = 0; c < 3; ++c) wide.at(x, y)[c] = thin.at(0, y)[c];
  }
  const auto a = ibl::irradianceSh(thin), b = ibl::irradianceSh(wide);
  for (int i = 0; i < 9; ++i)
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[i][c], b[i][c], 1e-4 * std::abs(b[0][c])) << i << " " << c;
  EXPECT_GT(ibl::irradianceFromSh(a, {0, 1, 0}).x, ibl::irradianceFromSh(a, {0, -1, 0}).x);  // not a constant
  const std::atomic<bool> raised{true};
  EXPECT_THROW(ibl::irradianceSh(thin, rt::Cancel(&raised)), rt::Cancelled);
  EXPECT_THROW(ibl::prefilterEnvironment(thin, rt::Cancel(&raised)), rt::Cancelled);
}

// glTF's default material (a mesh with no material) is metallic 1, roughness 1, white (spec 3.9.6):
// under the default lighting its only response is specular, which the split-sum IBL supplies.
TEST(ImageBasedLighting, MeshWithoutMaterialFollowsTheSpecAndIsNotBlackUnderDefaultLighting) {
  test::GltfBuilder b;
  const int mesh = b.mesh(json::array({test::trianglePrimitive<std::uint16_t>(
      b, {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}}, {0, 1, 2, 0, 2, 3})}));
  b.scene({b.node({{"mesh", mesh}})});
  const Scene scene = loadSceneFromMemory(b.gltf());
  ASSERT_EQ(scene.meshes[0].material, -1);
  EXPECT_EQ(scene.material(-1).metallicFactor, 1.f);
  EXPECT_EQ(scene.material(-1).roughnessFactor, 1.f);
  api::RenderRequest req = exrRequest(kSize);
  req.camera = kFillCamera;
  const RenderOutput out = renderer().render(scene, req);
  EXPECT_EQ(out.stats.lighting, "default");
  // Head-on (n.v ~ 1 at the centre): L = Lpre(R) (A + B)(1, 1), and the studio's GGX-prefiltered radiance
  // at roughness 1 is at least its floor's 0.2 in any direction.
  const glm::vec3 ab = ibl::dfgAt(1.f, 1.f);
  const float centre = aov(out, "beauty").at(16, 16)[1];
  EXPECT_GT(centre, 0.2f * (ab.x + ab.y));
  EXPECT_LT(centre, 8.8f * (ab.x + ab.y));  // and below the key's peak
}

// Split-sum against the reference path tracer on a white-ish metal sphere under a sun-and-sky map,
// at roughness 0.2, 0.5 and 1 (issue 12 asks to state the error). The errors, measured on this
// machine, are printed and recorded in docs/TECHNIQUES.md; the bounds are those measurements with a
// margin for the reference's Monte Carlo noise (256 spp: ~1% on the sphere mean) and llvmpipe, so the
// test catches a regression of the tables or the prefilter, not the method's known bias.
Image sunSky() {
  Image env = Image::make("environment", 128, 64, 3);
  const glm::vec3 sun = glm::normalize(glm::vec3(0.6f, 0.8f, 0.4f));
  for (int y = 0; y < env.height; ++y)
    for (int x = 0; x < env.width; ++x) {
      const float u = (x + 0.5f) / env.width, v = (y + 0.5f) / env.height;
      const float phi = (u - 0.5f) * 2.f * glm::pi<float>(), theta = v * glm::pi<float>();
      const glm::vec3 d(std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi));
      glm::vec3 L = d.y > 0.f ? glm::mix(glm::vec3(0.6f, 0.7f, 0.9f), glm::vec3(0.2f, 0.35f, 0.8f), d.y)
                              : glm::vec3(0.15f, 0.12f, 0.1f);
      if (glm::dot(d, sun) > std::cos(glm::radians(4.f))) L += glm::vec3(60.f, 55.f, 45.f);
      float* p = env.at(x, y);
      p[0] = L.x; p[1] = L.y; p[2] = L.z;
    }
  return env;
}

TEST(ImageBasedLighting, SplitSumAgainstTheReferenceOnAMetalSphereUnderASunSky) {
  const Image env = sunSky();
  // Measured (2026-12-01, llvmpipe): sphere-mean error -1.2%, -2.6%, -6.4%; relative L1 7.4%, 10.7%,
  // 27%; PSNR 34.0, 30.9, 25.2 dB. The error grows with roughness: Karis' n = v = R prefilter misses
  // the lobe's stretching at grazing angles, which widens with alpha.
  const float bound[3] = {0.04f, 0.06f, 0.12f}, boundL1[3] = {0.12f, 0.16f, 0.35f};
  int k = 0;
  for (float roughness : {0.2f, 0.5f, 1.f}) {
    testing::SceneBuilder b;
    Material metal;
    metal.baseColorFactor = glm::vec4(0.9f, 0.9f, 0.9f, 1.f);
    metal.metallicFactor = 1.f;
    metal.roughnessFactor = roughness;
    b.sphere({0, 0, 0}, 1.f, b.material(metal), 96, 48);
    const Scene scene = b.build("sunsky-metal-" + std::to_string(roughness));
    api::RenderRequest req;
    req.width = req.height = 48;
    req.environment = "sha256:" + std::string(64, 'a');
    req.camera = api::CameraOverride{{0, 0, 4}, {0, 0, 0}, {0, 1, 0}, 35.f};
    req.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"beauty", "normal"}, false}};
    req.compare = api::CompareSpec{"reference", "beauty", 256, 1};
    req.disabledPasses.insert("photon_gi");  // the split-sum specular alone (photon_gi's sky photons add glossy light)
    const RenderOutput out = renderer().render(scene, req, nullptr, FrameInputs{nullptr, &env});
    const Image& beauty = aov(out, "beauty");
    const Image& ref = aov(out, "reference");
    const Image& normal = aov(out, "normal");
    double a = 0.0, r = 0.0, absErr = 0.0;
    for (int y = 0; y < 48; ++y)
      for (int x = 0; x < 48; ++x) {
        if (glm::length(glm::vec3(normal.at(x, y)[0], normal.at(x, y)[1], normal.at(x, y)[2])) < 0.5f) continue;
        for (int c = 0; c < 3; ++c) {
          a += beauty.at(x, y)[c];
          r += ref.at(x, y)[c];
          absErr += std::abs(beauty.at(x, y)[c] - ref.at(x, y)[c]);
        }
      }
    const double meanErr = std::abs(a - r) / r, l1 = absErr / r;
    std::cout << "roughness " << roughness << ": sphere mean radiance raster/reference - 1 = " << (a / r - 1.0)
              << ", relative L1 " << l1 << ", PSNR " << out.stats.metrics["psnr"] << " dB\n";
    EXPECT_LT(meanErr, bound[k]) << "roughness " << roughness;
    EXPECT_LT(l1, boundL1[k]) << "roughness " << roughness;
    ++k;
  }
}

// The environment's importance-sampling distribution is derived data of the map: built once per
// environment digest and size, reused by every later render (the reference and photon_gi both read it).
TEST(ImageBasedLighting, EnvironmentDistributionIsBuiltOncePerEnvironmentDigest) {
  const Image env = sunSky();
  testing::SceneBuilder b;
  b.sphere({0, 0, 0}, 1.f, b.material(testing::lambertian()), 32, 16);
  const Scene scene = b.build("env-distribution");
  // Lookups of the map's distribution (the reference's) and photon_gi's (drawn by the residual plus
  // half the sun: sunSky's sun is split off as a light, and sky_lights 0 leaves the sky's first hits to
  // photons), as hits and misses.
  struct Lookups { int hits = 0, misses = 0, photonHits = 0, photonMisses = 0; };
  auto render = [&](const std::string& digest, int spp, int skyLights = 0) {
    api::RenderRequest req = exrRequest(32);
    req.passes["direct"] = {{"sky_lights", skyLights}};
    req.environment = "sha256:" + digest;
    req.camera = api::CameraOverride{{0, 0, 4}, {0, 0, 0}, {0, 1, 0}, 35.f};
    req.compare = api::CompareSpec{"reference", "beauty", spp, 1};  // a new spp: the reference re-renders
    const RenderOutput out = renderer().render(scene, req, nullptr, FrameInputs{nullptr, &env});
    Lookups l;
    for (const api::CacheEvent& e : out.stats.cache) {
      if (e.what == "environment_distribution") (e.hit ? l.hits : l.misses)++;
      if (e.what == "photon_gi_environment_distribution") (e.hit ? l.photonHits : l.photonMisses)++;
    }
    return l;
  };
  const std::string a(64, 'c'), other(64, 'd');
  const Lookups first = render(a, 1);
  EXPECT_EQ(first.misses, 1);        // built once in the first frame (for the reference)
  EXPECT_EQ(first.photonMisses, 1);  // and photon_gi's once
  const Lookups second = render(a, 2);
  EXPECT_EQ(second.misses + second.photonMisses, 0);  // the same environment: every lookup is a hit
  EXPECT_GE(second.hits, 1);
  EXPECT_GE(second.photonHits, 1);
  const Lookups third = render(other, 2);  // another digest: built again
  EXPECT_EQ(third.misses, 1);
  EXPECT_EQ(third.photonMisses, 1);
  // With the sky lights (the default) no first hit of the sky is splatted: photon_gi draws by the map
  // itself and shares its distribution, which is built already.
  const Lookups fourth = render(other, 3, 32);
  EXPECT_EQ(fourth.misses + fourth.photonMisses + fourth.photonHits, 0);
  EXPECT_GE(fourth.hits, 2);
}

// ---- KHR_materials_clearcoat, _sheen, _specular: raster against the reference ---------------------

// A sphere lit by one point light and nothing else (no sky, no ambient): a convex object has no
// interreflection, so the reference's image is direct light alone and the raster `direct` pass must
// give it. Returns the sphere's mean radiance (green) in raster and reference and the PSNR.
struct LitSphere {
  double raster = 0.0, reference = 0.0, psnr = 0.0;
  std::vector<glm::vec3> rasterPixels, referencePixels;  // the sphere's pixels
};
// sum |a - b| / sum b over the sphere's pixels (green channel).
double relativeL1(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b) {
  double num = 0.0, den = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    num += std::abs(a[i].g - b[i].g);
    den += b[i].g;
  }
  return num / den;
}
LitSphere litSphere(const Material& material, const std::string& name) {
  testing::SceneBuilder b;
  b.sphere({0, 0, 0}, 1.f, b.material(material), 96, 48);
  b.pointLight({1.5f, 2.f, 3.f}, 40.f);
  const Scene scene = b.build(name);
  api::RenderRequest req;
  req.width = req.height = 48;
  req.defaultLighting = false;
  req.camera = api::CameraOverride{{0, 0, 4}, {0, 0, 0}, {0, 1, 0}, 35.f};
  req.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"beauty", "normal"}, false}};
  req.compare = api::CompareSpec{"reference", "beauty", 64, 1};
  const RenderOutput out = renderer().render(scene, req);
  const Image& beauty = aov(out, "beauty");
  const Image& ref = aov(out, "reference");
  const Image& normal = aov(out, "normal");
  LitSphere r;
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 48; ++x) {
      if (glm::length(glm::vec3(normal.at(x, y)[0], normal.at(x, y)[1], normal.at(x, y)[2])) < 0.5f) continue;
      r.rasterPixels.emplace_back(beauty.at(x, y)[0], beauty.at(x, y)[1], beauty.at(x, y)[2]);
      r.referencePixels.emplace_back(ref.at(x, y)[0], ref.at(x, y)[1], ref.at(x, y)[2]);
      r.raster += beauty.at(x, y)[1];
      r.reference += ref.at(x, y)[1];
    }
  r.raster /= double(r.rasterPixels.size());
  r.reference /= double(r.rasterPixels.size());
  r.psnr = out.stats.metrics["psnr"];
  std::cout << name << ": sphere mean raster " << r.raster << " reference " << r.reference << ", relative L1 "
            << relativeL1(r.rasterPixels, r.referencePixels) << ", PSNR " << r.psnr << " dB\n";
  return r;
}

TEST(Layers, ClearcoatSheenAndSpecularAgreeWithTheReferenceAndChangeTheImage) {
  Material plain;
  plain.baseColorFactor = glm::vec4(0.6f, 0.3f, 0.2f, 1.f);
  plain.metallicFactor = 0.f;
  plain.roughnessFactor = 0.6f;
  Material coated = plain;
  coated.clearcoatFactor = 1.f;
  coated.clearcoatRoughnessFactor = 0.15f;
  Material dark = plain;
  dark.baseColorFactor = glm::vec4(0.1f, 0.1f, 0.1f, 1.f);
  Material sheen = dark;
  sheen.sheenColorFactor = glm::vec3(0.9f, 0.9f, 0.9f);
  sheen.sheenRoughnessFactor = 0.5f;
  Material specular = plain;
  specular.specularFactor = 0.f;  // a pure Lambertian base: no highlight at all
  const LitSphere p = litSphere(plain, "layers-plain");
  const LitSphere c = litSphere(coated, "layers-clearcoat");
  const LitSphere d = litSphere(dark, "layers-dark");
  const LitSphere s = litSphere(sheen, "layers-sheen");
  const LitSphere k = litSphere(specular, "layers-specular");
  // Raster and reference agree on each sphere's mean within 3% (the raster's one sample per pixel at
  // the silhouette and the reference's 64-spp noise are what is left), and pixel by pixel (relative L1)
  // within the bounds below, set from the measured values (printed above) with margin.
  for (const LitSphere* r : {&p, &c, &d, &s, &k}) EXPECT_NEAR(r->raster, r->reference, 0.03 * r->reference);
  const double l1Coat = relativeL1(c.rasterPixels, c.referencePixels);
  const double l1Sheen = relativeL1(s.rasterPixels, s.referencePixels);
  // Measured 2026-12-01 (llvmpipe): 0.9% for the plain, dark and specular-0 spheres, 2.7% with the coat
  // (its sharp highlight over one-sample pixels), 3.6% with the sheen (strongest at the silhouette).
  for (const LitSphere* r : {&p, &d, &k}) EXPECT_LT(relativeL1(r->rasterPixels, r->referencePixels), 0.02);
  EXPECT_LT(l1Coat, 0.05);
  EXPECT_LT(l1Sheen, 0.06);
  // Each layer changes the image by more than raster and reference differ, in both renderers:
  // the coat adds a sharp highlight and takes (1 - Fc) of the base (the means barely move), the sheen
  // lifts a dark base (a white sheen reflects ~E(mu)), no specular removes the base's highlight.
  const double coatChange = relativeL1(c.referencePixels, p.referencePixels);
  EXPECT_GT(coatChange, 2.0 * l1Coat);
  EXPECT_GT(relativeL1(c.rasterPixels, p.rasterPixels), 2.0 * l1Coat);
  EXPECT_GT(s.reference, 1.5 * d.reference);
  EXPECT_GT(s.raster, 1.5 * d.raster);
  EXPECT_LT(k.raster, 0.97 * p.raster);
  EXPECT_LT(k.reference, 0.97 * p.reference);
  std::cout << "clear coat: changes the image by " << coatChange << " (relative L1), raster/reference differ by "
            << l1Coat << "; sheen: raster/reference " << l1Sheen << "\n";
}

// ---- the layered extensions' textures: factor x texel, with KHR_texture_transform ------------------

// A 2x1 texture: texel 0 (u < 0.5) and texel 1 (u > 0.5), RGBA8.
std::string twoTexelPng(std::array<std::uint8_t, 4> left, std::array<std::uint8_t, 4> right) {
  return "data:image/png;base64," +
         test::base64(test::encodePng(2, 1, {left[0], left[1], left[2], left[3], right[0], right[1], right[2], right[3]}));
}

// The filling quad of texturedQuad(), split at x = 0 into `materials.size()` (1 or 2) quads with
// uv = ((x + 1) / 2, (1 - y) / 2), lit by one point light in front.
Scene layeredQuads(test::GltfBuilder& b, const std::vector<json>& materials, glm::vec3 normal = {0, 0, 1}) {
  std::vector<int> roots;
  const float x0 = -1.f, step = 2.f / float(materials.size());
  for (std::size_t k = 0; k < materials.size(); ++k) {
    const float a = x0 + step * float(k), c = a + step;
    const int m = b.material(materials[k]);
    const std::vector<glm::vec3> p = {{a, -1, 0}, {c, -1, 0}, {c, 1, 0}, {a, 1, 0}};
    std::vector<glm::vec2> uv;
    for (const auto& q : p) uv.emplace_back((q.x + 1.f) / 2.f, (1.f - q.y) / 2.f);
    const int mesh = b.mesh(json::array({test::trianglePrimitive<std::uint16_t>(
        b, p, {0, 1, 2, 0, 2, 3}, {normal, normal, normal, normal}, uv, m)}));
    roots.push_back(b.node({{"name", "card" + std::to_string(k)}, {"mesh", mesh}}));
  }
  roots.push_back(b.node({{"name", "light"}, {"translation", {0.4, 0.3, 1.2}},
                          {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}}));
  b.doc["extensions"]["KHR_lights_punctual"] = {{"lights", json::array({{{"type", "point"}, {"intensity", 3.0}}})}};
  b.scene(roots);
  b.doc["extensionsUsed"] = json::array({"KHR_lights_punctual", "KHR_materials_clearcoat", "KHR_materials_sheen",
                                         "KHR_materials_specular", "KHR_texture_transform"});
  return loadSceneFromMemory(b.gltf());
}

TEST(LayerTextures, FactorTimesTexelAsTheSpecsWriteRasterAndReference) {
  // Textures of 2x1 texels (nearest, repeat): each half of the card reads one texel.
  const std::array<std::uint8_t, 4> dataL{255, 60, 0, 255}, dataR{100, 200, 0, 128};      // coat R, coat roughness G, sheen roughness A
  const std::array<std::uint8_t, 4> sheenL{230, 200, 120, 255}, sheenR{40, 90, 160, 255};  // sheen colour (sRGB)
  const std::array<std::uint8_t, 4> specL{0, 0, 0, 64}, specR{0, 0, 0, 255};                // specular weight A
  const std::array<std::uint8_t, 4> scolL{255, 180, 90, 255}, scolR{120, 255, 200, 255};    // specular colour (sRGB)
  json base = {{"pbrMetallicRoughness", {{"baseColorFactor", {0.3, 0.25, 0.2, 1.0}}, {"metallicFactor", 0.0},
                                         {"roughnessFactor", 0.5}}}};
  auto tex = [](int i) { return json{{"index", i}}; };
  json textured = base;
  // KHR_texture_transform on the specular colour: offset 0.5 in u (repeat) swaps the halves.
  json scol = tex(3);
  scol["extensions"] = {{"KHR_texture_transform", {{"offset", {0.5, 0.0}}}}};
  textured["extensions"] = {
      {"KHR_materials_clearcoat", {{"clearcoatFactor", 0.9}, {"clearcoatRoughnessFactor", 0.6},
                                   {"clearcoatTexture", tex(0)}, {"clearcoatRoughnessTexture", tex(0)}}},
      {"KHR_materials_sheen", {{"sheenColorFactor", {0.9, 1.0, 0.8}}, {"sheenRoughnessFactor", 0.7},
                               {"sheenColorTexture", tex(1)}, {"sheenRoughnessTexture", tex(0)}}},
      {"KHR_materials_specular", {{"specularFactor", 0.9}, {"specularColorFactor", {1.0, 0.8, 1.0}},
                                  {"specularTexture", tex(2)}, {"specularColorTexture", scol}}}};
  test::GltfBuilder tb;
  tb.doc["samplers"] = json::array({{{"magFilter", 9728}, {"minFilter", 9728}, {"wrapS", 10497}, {"wrapT", 10497}}});
  tb.doc["images"] = json::array({{{"uri", twoTexelPng(dataL, dataR)}}, {{"uri", twoTexelPng(sheenL, sheenR)}},
                                  {{"uri", twoTexelPng(specL, specR)}}, {{"uri", twoTexelPng(scolL, scolR)}}});
  tb.doc["textures"] = json::array();
  for (int i = 0; i < 4; ++i) tb.doc["textures"].push_back({{"source", i}, {"sampler", 0}});
  const Scene texturedScene = layeredQuads(tb, {textured});
  for (const std::string& w : texturedScene.warnings) EXPECT_EQ(w.find("ignored"), std::string::npos) << w;
  ASSERT_TRUE(texturedScene.materials[0].specularColorTexture.valid());

  // The same card as two factor-only materials: factor x texel (sRGB decoded for the colours), the
  // specular colour from the other half's texel (the transform).
  auto srgb = [](std::uint8_t v) { return io::srgbToLinear(v / 255.f); };
  auto half = [&](const std::array<std::uint8_t, 4>& d, const std::array<std::uint8_t, 4>& sh,
                  const std::array<std::uint8_t, 4>& sp, const std::array<std::uint8_t, 4>& sc) {
    json m = base;
    m["extensions"] = {
        {"KHR_materials_clearcoat", {{"clearcoatFactor", 0.9 * d[0] / 255.0}, {"clearcoatRoughnessFactor", 0.6 * d[1] / 255.0}}},
        {"KHR_materials_sheen", {{"sheenColorFactor", {0.9 * srgb(sh[0]), 1.0 * srgb(sh[1]), 0.8 * srgb(sh[2])}},
                                 {"sheenRoughnessFactor", 0.7 * d[3] / 255.0}}},
        {"KHR_materials_specular", {{"specularFactor", 0.9 * sp[3] / 255.0},
                                    {"specularColorFactor", {1.0 * srgb(sc[0]), 0.8 * srgb(sc[1]), 1.0 * srgb(sc[2])}}}}};
    return m;
  };
  test::GltfBuilder fb;
  const Scene factorScene = layeredQuads(fb, {half(dataL, sheenL, specL, scolR), half(dataR, sheenR, specR, scolL)});

  api::RenderRequest req = exrRequest(kSize);
  req.camera = kFillCamera;
  req.defaultLighting = false;
  req.disabledPasses.insert("photon_gi");  // one flat card: no indirect light
  api::RenderRequest withRef = req;
  withRef.compare = api::CompareSpec{"reference", "beauty", 256, 1};
  const RenderOutput texturedOut = renderer().render(texturedScene, withRef);
  const RenderOutput factorOut = renderer().render(factorScene, req);
  const Image& t = aov(texturedOut, "beauty");
  const Image& f = aov(factorOut, "beauty");
  const Image& r = aov(texturedOut, "reference");
  // Per pixel, away from the seam (x = 15, 16), textured == factors: the decoders multiply exactly
  // what the specs say. The only slack is llvmpipe's approximate sRGB decode (2e-3 of a colour,
  // measured in material_parity_test), times the light: 1% of the pixel.
  double worst = 0.0;
  glm::dvec3 tMean[2] = {}, rMean[2] = {};
  int n[2] = {0, 0};
  for (int y = 1; y < kSize - 1; ++y)
    for (int x = 1; x < kSize - 1; ++x) {
      if (x == kSize / 2 - 1 || x == kSize / 2) continue;
      const int h = x < kSize / 2 ? 0 : 1;
      for (int c = 0; c < 3; ++c) {
        worst = std::max(worst, double(std::abs(t.at(x, y)[c] - f.at(x, y)[c]) / std::max(f.at(x, y)[c], 1e-3f)));
        tMean[h][c] += t.at(x, y)[c];
        rMean[h][c] += r.at(x, y)[c];
      }
      ++n[h];
    }
  for (int h = 0; h < 2; ++h) tMean[h] /= double(n[h]), rMean[h] /= double(n[h]);
  std::cout << "layer textures: worst textured/factors pixel difference " << worst << "; half means raster "
            << tMean[0].r << " " << tMean[0].g << " " << tMean[0].b << " | " << tMean[1].r << " " << tMean[1].g << " "
            << tMean[1].b << ", reference " << rMean[0].r << " " << rMean[0].g << " " << rMean[0].b << " | "
            << rMean[1].r << " " << rMean[1].g << " " << rMean[1].b << "\n";
  EXPECT_LT(worst, 0.01);
  // The halves really differ (so the equality above is not two images ignoring the textures) ...
  EXPECT_GT(glm::length(tMean[0] - tMean[1]), 0.1 * glm::length(tMean[1]));
  // ... and the reference, reading the same file through the C++ decoder, agrees on each half's mean
  // within 1% per channel (measured 0.06%: a flat card under one point light has no silhouette and
  // no interreflection; the reference's 256-spp noise over ~450 pixels is below 0.5%).
  for (int h = 0; h < 2; ++h)
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(tMean[h][c], rMean[h][c], 0.01 * rMean[h][c]) << "half " << h << " channel " << c;
}

// sum |x - y| / sum y over a kSize x kSize frame (green).
double relativeL1(const Image& x, const Image& y) {
  double num = 0.0, den = 0.0;
  for (int j = 0; j < kSize; ++j)
    for (int i = 0; i < kSize; ++i) {
      num += std::abs(x.at(i, j)[1] - y.at(i, j)[1]);
      den += y.at(i, j)[1];
    }
  return num / den;
}

TEST(LayerTextures, CoatNormalMapMovesTheCoatsHighlightAsInTheReference) {
  // A black base with no specular (KHR_materials_specular 0) reflects nothing: the card shows its clear
  // coat alone. A constant clearcoatNormalTexture texel tilts the coat normal towards +x (the card's
  // tangent from u): the raster (gbuffer.frag's decodeCoatNormal, packed in gbuffer_layers) and the
  // reference (RayScene::shade) must agree, and the tilt must move the highlight (the untilted card
  // differs in both). Not the same image as vertex normals tilted alike: the BSDF's cosine is the
  // base's shading normal's, which the coat's map does not move.
  const std::array<std::uint8_t, 4> texel{190, 128, 220, 255};
  json coat = {{"pbrMetallicRoughness", {{"baseColorFactor", {0.0, 0.0, 0.0, 1.0}}, {"metallicFactor", 0.0}}},
               {"extensions", {{"KHR_materials_specular", {{"specularFactor", 0.0}}}}}};
  coat["extensions"]["KHR_materials_clearcoat"] = {{"clearcoatFactor", 1.0}, {"clearcoatRoughnessFactor", 0.3}};
  json mapped = coat;
  mapped["extensions"]["KHR_materials_clearcoat"]["clearcoatNormalTexture"] = {{"index", 0}};
  test::GltfBuilder mb, fb;
  mb.doc["samplers"] = json::array({{{"magFilter", 9728}, {"minFilter", 9728}}});
  mb.doc["images"] = json::array({{{"uri", twoTexelPng(texel, texel)}}});
  mb.doc["textures"] = json::array({{{"source", 0}, {"sampler", 0}}});
  const Scene mappedScene = layeredQuads(mb, {mapped});
  ASSERT_EQ(mappedScene.meshes[0].tangents.size(), 4u);  // generated for the coat's map alone
  const Scene flatScene = layeredQuads(fb, {coat});
  api::RenderRequest req = exrRequest(kSize);
  req.camera = kFillCamera;
  req.defaultLighting = false;
  req.disabledPasses.insert("photon_gi");
  req.compare = api::CompareSpec{"reference", "beauty", 128, 1};
  const RenderOutput a = renderer().render(mappedScene, req);
  const RenderOutput f = renderer().render(flatScene, req);
  const double mappedError = relativeL1(aov(a, "beauty"), aov(a, "reference"));
  const double flatError = relativeL1(aov(f, "beauty"), aov(f, "reference"));
  const double tiltRaster = relativeL1(aov(f, "beauty"), aov(a, "beauty"));
  const double tiltReference = relativeL1(aov(f, "reference"), aov(a, "reference"));
  std::cout << "coat normal map: raster/reference relative L1 " << mappedError << " (untilted " << flatError
            << "); the tilt changes the image by " << tiltRaster << " (raster), " << tiltReference << " (reference)\n";
  // Raster against reference: the coat's highlight point-sampled per pixel against 128 spp over the
  // pixel (Layers.Clearcoat... allows 5% on a sphere); the tilt changes the image far more than that.
  EXPECT_LT(mappedError, 0.05);
  EXPECT_GT(tiltRaster, 10.0 * mappedError);
  EXPECT_GT(tiltReference, 10.0 * mappedError);
}

// ---- shading normals: vertex normals against the winding --------------------------------------------

// Exported files sometimes carry vertex normals opposite to their triangles' winding. Both languages
// turn the interpolated normal to the winding's side before normal mapping (RayScene::shade,
// material.glsl's windingSideNormal): such a card shades as the same card with consistent normals, in
// the raster as in the reference. Before, only the reference flipped them and the raster lit the front
// as a back (black under a light in front).
TEST(ShadingNormals, VertexNormalsAgainstTheWindingShadeAsConsistentOnesRasterAndReference) {
  const json lambert = {{"pbrMetallicRoughness", {{"baseColorFactor", {0.8, 0.8, 0.8, 1.0}},
                                                  {"metallicFactor", 0.0}, {"roughnessFactor", 1.0}}}};
  test::GltfBuilder cb, rb;
  const Scene consistent = layeredQuads(cb, {lambert});
  const Scene reversed = layeredQuads(rb, {lambert}, {0, 0, -1});  // the winding's normal is +z
  api::RenderRequest req = exrRequest(kSize);
  req.camera = kFillCamera;
  req.defaultLighting = false;
  req.disabledPasses.insert("photon_gi");  // one card: no interreflection, direct light only
  req.compare = api::CompareSpec{"reference", "beauty", 64, 1};
  const RenderOutput c = renderer().render(consistent, req);
  const RenderOutput r = renderer().render(reversed, req);
  const double rasterFlip = relativeL1(aov(r, "beauty"), aov(c, "beauty"));
  const double referenceFlip = relativeL1(aov(r, "reference"), aov(c, "reference"));
  const double rasterVsReference = relativeL1(aov(r, "beauty"), aov(r, "reference"));
  std::cout << "reversed vertex normals: raster changes by " << rasterFlip << ", reference by " << referenceFlip
            << "; raster/reference " << rasterVsReference << " (relative L1)\n";
  // The same normals after the turn: the raster image is the consistent card's to float rounding, the
  // reference's within its noise (the same seed traces the same paths).
  EXPECT_LT(rasterFlip, 1e-4);
  EXPECT_LT(referenceFlip, 1e-4);
  // A Lambertian card under a point light: the raster's one sample per pixel against 64 spp over the
  // pixel (the point light's falloff is smooth: 2% covers the noise).
  EXPECT_LT(rasterVsReference, 0.02);
}

// ---- shadows of MASK and BLEND surfaces -------------------------------------------------------------

TEST(Transparency, BlendedSurfaceCastsAShadowOfItsAlphaAsTheReference) {
  // A white Lambertian floor lit by a point light low on the left; a wall of BLEND alpha 0.5 (or MASK
  // with the same alpha under a cutoff of 0.6: no shadow at all) stands between them, out of view. The
  // floor seen from above is wholly behind the wall as the light sees it (the wall is taller than the
  // light), so the wall's transmittance is the ratio of the floor's radiance with and without it:
  // 1 - alpha = 0.5 in the reference (stochastic pass-through) and in the raster (dithered shadow map).
  auto build = [](int wallMode) {
    testing::SceneBuilder b;
    b.quad({0, 0, 0}, {4, 0, 0}, {0, 0, -4}, b.material(testing::lambertian(glm::vec3(0.8f))), "floor");
    if (wallMode > 0) {
      Material wall = testing::lambertian(glm::vec3(0.5f));
      wall.baseColorFactor.a = 0.5f;
      wall.alphaMode = wallMode == 1 ? AlphaMode::Blend : AlphaMode::Mask;
      wall.alphaCutoff = 0.6f;
      wall.doubleSided = true;
      b.quad({-2.5f, 1.5f, 0}, {0, 1.5f, 0}, {0, 0, 4}, b.material(wall), "wall");
    }
    b.pointLight({-4.f, 2.f, 0.f}, 40.f);
    return b.build(wallMode == 0 ? "floor-open" : wallMode == 1 ? "floor-blend-wall" : "floor-mask-wall");
  };
  api::RenderRequest req = exrRequest(32);
  req.defaultLighting = false;
  req.camera = api::CameraOverride{{0, 5, 0}, {0, 0, 0}, {0, 0, -1}, 30.f};  // looks down; sees x, z in +-1.34
  req.compare = api::CompareSpec{"reference", "beauty", 64, 1};
  req.disabledPasses.insert("photon_gi");  // direct light only: the ratio is the wall's transmittance
  const RenderOutput open = renderer().render(build(0), req);
  const RenderOutput blend = renderer().render(build(1), req);
  const RenderOutput mask = renderer().render(build(2), req);
  auto mean = [](const Image& img) {
    double s = 0.0;
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 32; ++x) s += img.at(x, y)[1];
    return s / (32.0 * 32.0);
  };
  for (const char* which : {"beauty", "reference"}) {
    const double lit = mean(aov(open, which));
    ASSERT_GT(lit, 0.01) << which;
    const double blendRatio = mean(aov(blend, which)) / lit, maskRatio = mean(aov(mask, which)) / lit;
    std::cout << which << ": floor behind a BLEND wall of alpha 0.5 keeps " << blendRatio
              << " of its light, behind a MASK wall below its cutoff " << maskRatio << "\n";
    // Reference: 64 coin flips per pixel over 1024 pixels (standard error 0.002); raster: the 4x4
    // dither pattern keeps exactly half the wall's texels, and the PCF kernel averages them (1%).
    EXPECT_NEAR(blendRatio, 0.5, 0.02) << which;
    EXPECT_NEAR(maskRatio, 1.0, 0.01) << which;
  }
  // Locally: the raster's 3x3 PCF taps step in direction space, not along the cube face's texels, so
  // one pixel sees 3/9 to 7/9 of the checkerboard of kept texels (the dither's ripple, printed); the
  // mean over each 4x4 block of pixels is within 0.1 of 1/2.
  const Image& b = aov(blend, "beauty");
  const Image& o = aov(open, "beauty");
  double worstPixel = 0.0, worstBlock = 0.0;
  for (int by = 0; by < 32; by += 4)
    for (int bx = 0; bx < 32; bx += 4) {
      double sb = 0.0, so = 0.0;
      for (int y = by; y < by + 4; ++y)
        for (int x = bx; x < bx + 4; ++x) {
          sb += b.at(x, y)[1];
          so += o.at(x, y)[1];
          worstPixel = std::max(worstPixel, std::abs(b.at(x, y)[1] / o.at(x, y)[1] - 0.5));
        }
      worstBlock = std::max(worstBlock, std::abs(sb / so - 0.5));
    }
  std::cout << "dithered shadow: worst pixel |ratio - 0.5| " << worstPixel << ", worst 4x4 block " << worstBlock << "\n";
  EXPECT_LT(worstBlock, 0.1);
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
