// The environment map: one mapping (renderer/scene/Environment.h) shared by the raster background,
// the ambient average and the reference path tracer.
#include <cmath>

#include <gtest/gtest.h>

#include "renderer/Renderer.h"
#include "renderer/scene/Environment.h"
#include "tests/support/RenderTestSupport.h"
#include "tests/support/SceneBuilder.h"

namespace radiant {
namespace {

using testing::aov;
using testing::renderer;

// Upper hemisphere red (1, 0, 0), lower hemisphere blue (0, 0, 2): rows split exactly at the horizon.
Image twoHemispheres() {
  Image env = Image::make("environment", 16, 8, 3);
  for (int y = 0; y < env.height; ++y)
    for (int x = 0; x < env.width; ++x) {
      float* p = env.at(x, y);
      p[0] = y < env.height / 2 ? 1.f : 0.f;
      p[2] = y < env.height / 2 ? 0.f : 2.f;
    }
  return env;
}

TEST(Environment, MappingMatchesTheConvention) {
  // Up is row 0, down the last row, -Z the image centre, +X a quarter turn right of it.
  const Image env = Image::make("e", 8, 4, 3);
  int x, y;
  equirectTexel(env, {0, 1, 0}, x, y);
  EXPECT_EQ(y, 0);
  equirectTexel(env, {0, -1, 0}, x, y);
  EXPECT_EQ(y, 3);
  EXPECT_NEAR(equirectUv({0, 0, -1}).x, 0.5f, 1e-6f);
  EXPECT_NEAR(equirectUv({1, 0, 0}).x, 0.75f, 1e-6f);
  EXPECT_NEAR(equirectUv({0, 0, -1}).y, 0.5f, 1e-6f);
}

TEST(Environment, AverageIsSolidAngleWeighted) {
  // Each hemisphere is half the sphere: the average is (0.5, 0, 1) whatever the row count.
  const glm::vec3 avg = environmentAverage(twoHemispheres());
  EXPECT_NEAR(avg.x, 0.5f, 1e-6f);
  EXPECT_NEAR(avg.y, 0.0f, 1e-6f);
  EXPECT_NEAR(avg.z, 1.0f, 1e-6f);
}

TEST(Environment, BackgroundShowsTheMapInTheViewDirection) {
  testing::SceneBuilder b;
  int white = b.material(testing::lambertian());
  b.quad({0, -10, -30}, {1, 0, 0}, {0, 0, -1}, white);  // something to render, out of view
  Scene scene = b.build("env-background");
  const Image env = twoHemispheres();
  api::RenderRequest req;
  req.width = req.height = 16;
  req.environment = "sha256:" + std::string(64, 'e');
  req.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"beauty"}, false}};
  for (float dy : {0.5f, -0.5f}) {
    // 40 degree field of view tilted 30 degrees up or down: every pixel sees one hemisphere.
    req.camera = api::CameraOverride{{0, 0, 0}, {0, dy, -1}, {0, 1, 0}, 40.f};
    RenderOutput out = renderer().render(scene, req, nullptr, FrameInputs{nullptr, &env});
    const Image& beauty = aov(out, "beauty");
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x) {
        EXPECT_EQ(beauty.at(x, y)[0], dy > 0 ? 1.f : 0.f);
        EXPECT_EQ(beauty.at(x, y)[2], dy > 0 ? 0.f : 2.f);
      }
  }
  // A request naming an environment the caller did not supply is refused, naming the field.
  try {
    renderer().render(scene, req);
    FAIL() << "accepted a missing environment";
  } catch (const api::ApiError& e) {
    EXPECT_EQ(e.pointer, "/environment");
  }
}

TEST(Environment, ReferenceAndRasterLightByTheMapNotItsAverage) {
  // An upward-facing white Lambertian plane under the two-hemisphere sky sees only the red half:
  // E = pi * 1, L = E / pi = (1, 0, 0) exactly (the reference importance-samples the map). The raster's
  // ambient_occlusion pass lights by the map's SH irradiance (l <= 2), which for a hemisphere step is
  // exact at the pole: pi (1/2 + 1/2) for the red half, 2 pi (1/2 - 1/2) = 0 for the blue one; not
  // the average (0.5, 0, 1) it used before image-based lighting.
  testing::SceneBuilder b;
  int white = b.material(testing::lambertian());
  b.quad({0, 0, 0}, {50, 0, 0}, {0, 0, -50}, white).topDownOrtho(5.f, 1.f);
  Scene scene = b.build("env-plane");
  const Image env = twoHemispheres();
  api::RenderRequest req;
  req.width = req.height = 8;
  req.environment = "sha256:" + std::string(64, 'f');
  req.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"beauty", "reference"}, false}};
  req.passes["reference"] = {{"spp", 1024}, {"max_bounces", 1}};
  req.disabledPasses.insert("photon_gi");  // the raster's image-based lighting alone (photon_gi owns L(sky)DE)
  RenderOutput out = renderer().render(scene, req, nullptr, FrameInputs{nullptr, &env});
  const Image& ref = aov(out, "reference");
  const Image& beauty = aov(out, "beauty");
  // 1024 spp per pixel, 16 pixels: the mean's Monte Carlo error is well under 1%.
  double red = 0;
  for (int y = 2; y < 6; ++y)
    for (int x = 2; x < 6; ++x) red += ref.at(x, y)[0] / 16.0;
  EXPECT_NEAR(red, 1.0, 0.01);
  for (int y = 2; y < 6; ++y)
    for (int x = 2; x < 6; ++x) {
      EXPECT_NEAR(ref.at(x, y)[2], 0.f, 1e-6f);
      // 1e-2: the SH projection of the 16 x 8 map (midpoint rule at 512 x 256) and the specular term.
      EXPECT_NEAR(beauty.at(x, y)[0], 1.0f, 1e-2f);
      EXPECT_NEAR(beauty.at(x, y)[2], 0.0f, 1e-2f);
    }
  // With photon_gi (on by default) the map's direct light comes from environment photons, which see
  // its directions: the upward-facing plane gets the red upper hemisphere only, like the reference.
  req.disabledPasses.clear();
  req.passes["photon_gi"] = {{"photons", 400000}, {"C", 20}};
  RenderOutput gi = renderer().render(scene, req, nullptr, FrameInputs{nullptr, &env});
  double giRed = 0, giBlue = 0;
  for (int y = 2; y < 6; ++y)
    for (int x = 2; x < 6; ++x) {
      giRed += aov(gi, "beauty").at(x, y)[0] / 16.0;
      giBlue += aov(gi, "beauty").at(x, y)[2] / 16.0;
    }
  // The 16 pixels share one kernel (h ~ 4 m on the 100 m plane), so their mean carries the estimate's
  // noise 0.757 / C = 3.8% (C = 20): 10% is 2.6 sigma.
  EXPECT_NEAR(giRed, red, 0.1);
  EXPECT_NEAR(giBlue, 0.0, 1e-6);
}

TEST(Environment, MirrorsReflectTheMapNotItsAverage) {
  // A perfect white mirror floor (metallic 1, roughness 0: Schlick F = 1 at any angle) seen straight
  // down reflects the zenith: the red upper hemisphere, (1, 0, 0), not the average (0.5, 0, 1).
  testing::SceneBuilder b;
  Material mirror;
  mirror.metallicFactor = 1.f;
  mirror.roughnessFactor = 0.f;
  int m = b.material(mirror);
  b.quad({0, 0, 0}, {50, 0, 0}, {0, 0, -50}, m, "mirror").topDownOrtho(5.f, 1.f);
  Scene scene = b.build("env-mirror");
  const Image env = twoHemispheres();
  api::RenderRequest req;
  req.width = req.height = 8;
  req.environment = "sha256:" + std::string(64, 'c');
  req.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"specular"}, false}};
  RenderOutput out = renderer().render(scene, req, nullptr, FrameInputs{nullptr, &env});
  const Image& spec = aov(out, "specular");
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) {
      EXPECT_NEAR(spec.at(x, y)[0], 1.f, 1e-3f);
      EXPECT_NEAR(spec.at(x, y)[2], 0.f, 1e-3f);
    }
}

}  // namespace
}  // namespace radiant
