// The closed furnace (issue 32): a point light of intensity I at the centre of a closed sphere of
// radius R whose inside is a pure Lambertian of albedo rho (glTF dielectric with KHR_materials_specular
// specularFactor 0: no Fresnel layer). Every wall point receives the direct irradiance E0 = I / R^2
// (normal incidence) and, since a sphere's form factor from any point to any area is that area over
// 4 pi R^2, the same indirect irradiance everywhere: each bounce carries rho times the flux of the one
// before, so E = E0 (1 + rho + rho^2 + ...) = E0 / (1 - rho) and every wall pixel has
//   L = rho E / pi = rho E0 / ((1 - rho) pi).
// A path (or photon) truncated after N scattering events sees rho E0 / pi (1 - rho^N) / (1 - rho): at
// albedo 0.95 an 8-event cap loses 66% of the light. The default frame and the reference must reach
// the untruncated value within 2% at albedo 0.5, 0.8 and 0.95: Russian roulette, not a bounce cap,
// ends the paths (the cap is a safety net, counted in stats: paths_capped, photons_capped).
//
// The tessellated sphere is not quite a sphere: its facets are up to 1 - cos(pi / 96) = 0.05% closer to
// the light than R at their centres (0.1% more direct irradiance) and its area is 0.1% under 4 pi R^2;
// the expectation uses the mesh's area for the indirect flux and I / R^2 for the direct light, which
// leaves a model error under 0.2%.
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "renderer/Renderer.h"
#include "renderer/techniques/photon_gi/PhotonGi.h"
#include "tests/support/RenderTestSupport.h"
#include "tests/support/SceneBuilder.h"

namespace radiant {
namespace {

using testing::aov;
using testing::renderer;

constexpr float kRadius = 2.f;
constexpr float kIntensity = 4.f;

Scene furnace(float rho) {
  testing::SceneBuilder b;
  Material m = testing::lambertian(glm::vec3(rho));
  m.specularFactor = 0.f;  // KHR_materials_specular: no Fresnel layer, a pure Lambertian
  m.doubleSided = true;    // the camera and the light are inside
  const int mat = b.material(m);
  b.sphere(glm::vec3(0.f), kRadius, mat, 192, 96);
  b.pointLight(glm::vec3(0.f), kIntensity);
  char digest[64];
  std::snprintf(digest, sizeof digest, "closed-furnace-%.3f", rho);
  return b.build(digest);
}

// L of a wall pixel for paths of at most `bounces` scattering events (0 = untruncated).
double expectedRadiance(const Scene& scene, float rho, int bounces = 0) {
  const double e0 = kIntensity / (kRadius * kRadius);
  const double area = photon_gi::meshArea(scene.meshes[0]);
  // Indirect: the flux 4 pi I reflected once (rho) and then each further bounce (geometric series),
  // spread uniformly over the area; direct: E0.
  const double series = bounces == 0 ? 1.0 / (1.0 - rho) : (1.0 - std::pow(rho, bounces - 1)) / (1.0 - rho);
  const double indirect = bounces == 1 ? 0.0 : 4.0 * M_PI * kIntensity * rho * series / area;
  return rho / M_PI * (e0 + indirect);
}

double mean(const Image& img) {
  double s = 0;
  for (std::size_t i = 0; i < img.pixels.size(); i += img.channels) s += img.pixels[i];
  return s * img.channels / img.pixels.size();
}

api::RenderRequest furnaceRequest() {
  api::RenderRequest r;
  r.width = r.height = 32;
  r.camera = api::CameraOverride{{0.f, 0.f, 0.f}, {0.f, 0.f, -1.f}, {0.f, 1.f, 0.f}, 60.f};
  r.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"beauty"}, false}};
  return r;
}

TEST(Furnace, DefaultFrameAndReferenceReachTheClosedFormAtHighAlbedo) {
  for (float rho : {0.5f, 0.8f, 0.95f}) {
    const Scene scene = furnace(rho);
    api::RenderRequest r = furnaceRequest();  // the default passes with their default parameters
    r.compare = api::CompareSpec{"reference", "beauty", 64, 1024};
    const RenderOutput out = renderer().render(scene, r);
    const double expected = expectedRadiance(scene, rho);
    const double frame = mean(aov(out, "beauty")), truth = mean(aov(out, "reference"));
    std::string passes;
    for (const auto& p : out.stats.passes) passes += p.name + " ";
    std::printf("albedo %.2f: expected %.4f, default frame %.4f (%+.2f%%), reference %.4f (%+.2f%%); passes %s\n", rho,
                expected, frame, 100 * (frame / expected - 1), truth, 100 * (truth / expected - 1), passes.c_str());
    EXPECT_NEAR(frame / expected, 1.0, 0.02) << rho;
    EXPECT_NEAR(truth / expected, 1.0, 0.02) << rho;
    // Roulette ended every path: the safety cap ended none.
    EXPECT_EQ(out.stats.metrics["reference_paths_capped"].get<double>(), 0.0) << rho;
    const api::PassStats* gi = testing::pass(out, "photon_gi");
    ASSERT_NE(gi, nullptr) << "the furnace's indirect light comes from photon_gi by default";
    EXPECT_EQ(gi->counters.at("photons_capped"), 0.0) << rho;
  }
}

TEST(Furnace, ASmallBounceCapTruncatesExactlyAndIsCounted) {
  // max_bounces = N keeps the first N scattering events: L = rho E0 / pi (1 - rho^N) / (1 - rho), and
  // the paths the cap ended are counted (a truncation the user asked for, visible in the stats).
  const float rho = 0.8f;
  const Scene scene = furnace(rho);
  for (int cap : {2, 8}) {
    api::RenderRequest r = furnaceRequest();
    r.passes["reference"] = {{"spp", 64}, {"max_bounces", cap}};
    r.passes["photon_gi"] = {{"max_bounces", cap}};
    r.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"reference", "beauty"}, false}};
    const RenderOutput out = renderer().render(scene, r);
    const double expected = expectedRadiance(scene, rho, cap);
    const double ref = mean(aov(out, "reference")), frame = mean(aov(out, "beauty"));
    std::printf("cap %d: expected %.4f (untruncated %.4f), reference %.4f, frame %.4f\n", cap, expected,
                expectedRadiance(scene, rho), ref, frame);
    EXPECT_NEAR(ref / expected, 1.0, 0.02) << cap;
    EXPECT_NEAR(frame / expected, 1.0, 0.02) << cap;
    const api::PassStats* refPass = testing::pass(out, "reference");
    ASSERT_NE(refPass, nullptr);
    // Nothing escapes a closed furnace and cosine-sampled Lambert keeps the throughput at rho^k, so paths
    // end by roulette only: it plays from the fourth event on with survival min(0.95, throughput) = rho^3
    // at the first roulette, then rho (a survivor's throughput is renormalised to 1). Every path reaches
    // cap 2 (no roulette yet) and about rho^8 = 17% of the 65536 reach cap 8: far above 100 either way.
    EXPECT_GT(refPass->counters.at("paths_capped"), 100.0) << cap;
    EXPECT_GT(testing::pass(out, "photon_gi")->counters.at("photons_capped"), 100.0) << cap;
  }
}

}  // namespace
}  // namespace radiant
