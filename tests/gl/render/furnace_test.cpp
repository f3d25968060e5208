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
#include <vector>

#include <gtest/gtest.h>

#include "renderer/Renderer.h"
#include "renderer/raytracing/Bsdf.h"
#include "renderer/scene/MaterialDecode.h"
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

// ---- The glTF BRDF in the furnace, by quadrature -------------------------------------------------
// With a glossy BRDF the wall's radiance is no longer the same in every direction, but by symmetry it
// depends only on the angle theta from the wall's normal: the point light hits every wall point along
// its normal, and a chord of a sphere makes the same angle with the normals at both ends, so the
// radiance arriving at y from x at incidence theta is the radiance leaving x at exitance theta. The
// exitant radiance L(theta_o) therefore solves
//   L(theta_o) = E0 f(theta_o, 0) + int_H f(w_o, w_i) L(theta_i) cos(theta_i) dw_i,
// a one-dimensional integral equation: discretised by the midpoint rule in cos(theta) (kCosNodes) and
// in azimuth (kAzimuths), iterated to its fixed point (the BRDF's albedo is below 1). The camera at the
// centre sees every wall point along its normal: a pixel is L(0). The BRDF is rt::GltfBsdf, the
// reference's, so the reference must agree with the quadrature to its noise; the default frame's
// passes evaluate the GLSL twin (parity_test checks the two agree).
constexpr int kCosNodes = 192, kAzimuths = 96;

double quadratureRadiance(const rt::GltfBsdf& f, double e0) {
  const double dmu = 1.0 / kCosNodes, dphi = 2.0 * M_PI / kAzimuths;
  auto dir = [](double mu, double phi) {
    const double s = std::sqrt(std::max(0.0, 1.0 - mu * mu));
    return glm::vec3(float(s * std::cos(phi)), float(s * std::sin(phi)), float(mu));
  };
  // K(wo, mu_k) = sum over azimuths of f(wo, wi) cos(theta_i) dmu dphi (first channel: grey materials).
  auto row = [&](glm::vec3 wo) {
    std::vector<double> k(kCosNodes);
    for (int j = 0; j < kCosNodes; ++j) {
      const double mu = (j + 0.5) * dmu;
      double sum = 0;
      for (int a = 0; a < kAzimuths; ++a) sum += f.eval(wo, dir(mu, (a + 0.5) * dphi)).x;
      k[std::size_t(j)] = sum * mu * dmu * dphi;
    }
    return k;
  };
  const glm::vec3 normal(0.f, 0.f, 1.f);
  std::vector<std::vector<double>> K;
  std::vector<double> source;
  for (int i = 0; i < kCosNodes; ++i) {
    const glm::vec3 wo = dir((i + 0.5) * dmu, 0.0);
    K.push_back(row(wo));
    source.push_back(e0 * f.eval(wo, normal).x);
  }
  std::vector<double> L = source, next(kCosNodes);
  for (int it = 0; it < 5000; ++it) {
    double change = 0;
    for (int i = 0; i < kCosNodes; ++i) {
      double v = source[std::size_t(i)];
      for (int j = 0; j < kCosNodes; ++j) v += K[std::size_t(i)][std::size_t(j)] * L[std::size_t(j)];
      change = std::max(change, std::abs(v - L[std::size_t(i)]));
      next[std::size_t(i)] = v;
    }
    std::swap(L, next);
    if (change < 1e-12) break;
  }
  const std::vector<double> k0 = row(normal);
  double l0 = e0 * f.eval(normal, normal).x;
  for (int j = 0; j < kCosNodes; ++j) l0 += k0[std::size_t(j)] * L[std::size_t(j)];
  return l0;
}

// The reference's BSDF of the material: its one decoder, no textures.
rt::GltfBsdf bsdfOf(const Material& m) {
  return rt::GltfBsdf::fromParams(decodeBsdfInputs(m, [](const TextureRef&, bool) { return glm::vec4(1.f); }));
}

Scene furnaceOf(const Material& m, const char* digest) {
  testing::SceneBuilder b;
  Material two = m;
  two.doubleSided = true;  // the camera and the light are inside
  b.sphere(glm::vec3(0.f), kRadius, b.material(two), 192, 96);
  b.pointLight(glm::vec3(0.f), kIntensity);
  return b.build(digest);
}

// The quadrature itself, on the closed form: a Lambertian BRDF gives rho E0 / ((1 - rho) pi).
TEST(GltfFurnace, QuadratureReachesTheLambertianClosedForm) {
  for (float rho : {0.5f, 0.95f}) {
    Material m = testing::lambertian(glm::vec3(rho));
    m.specularFactor = 0.f;
    const double e0 = kIntensity / (kRadius * kRadius);
    const double closed = rho * e0 / ((1.0 - rho) * M_PI);
    EXPECT_NEAR(quadratureRadiance(bsdfOf(m), e0) / closed, 1.0, 1e-4) << rho;
  }
}

// The glTF metallic-roughness BRDF (Fresnel-weighted diffuse under GGX) in the furnace at base colours
// 0.5, 0.8 and 0.95, dielectric and metal. The reference and the default frame against the quadrature:
// measured 2026-12-04 (llvmpipe) within 1.6% (default frame) and 0.9% (reference, 256 spp). This test
// found the direct pass shading with the G-buffer's RGBA16F normal unnormalised (length 0.9995-0.9999):
// at the GGX peak that cost the rough metal (0.5, roughness 0.3) 12% of its direct light (-9.4% of the
// frame), 21% in some pixels; direct.frag now renormalises it.
TEST(GltfFurnace, DefaultFrameAndReferenceReachTheQuadratureOfTheGltfBrdf) {
  struct Case { const char* name; glm::vec3 base; float metallic, roughness; };
  for (const Case& c : {Case{"dielectric 0.95 r0.5", glm::vec3(0.95f), 0.f, 0.5f},
                        Case{"metal 0.95 r0.5", glm::vec3(0.95f), 1.f, 0.5f},
                        Case{"dielectric 0.8 r1", glm::vec3(0.8f), 0.f, 1.f},
                        Case{"metal 0.5 r0.3", glm::vec3(0.5f), 1.f, 0.3f}}) {
    Material m;
    m.name = c.name;
    m.baseColorFactor = glm::vec4(c.base, 1.f);
    m.metallicFactor = c.metallic;
    m.roughnessFactor = c.roughness;
    m.ior = 1.5f;
    const Scene scene = furnaceOf(m, (std::string("gltf-furnace-") + c.name).c_str());
    const double expected = quadratureRadiance(bsdfOf(m), kIntensity / (kRadius * kRadius));
    api::RenderRequest r = furnaceRequest();
    // 256 spp: the reference's noise at these albedos is about 1.5% at 64 spp (measured: -1.49% for the
    // white dielectric at 64 spp, +0.38% at 512).
    r.compare = api::CompareSpec{"reference", "beauty", 256, 1024};
    const RenderOutput out = renderer().render(scene, r);
    const double frame = mean(aov(out, "beauty")), truth = mean(aov(out, "reference"));
    std::string passes;
    for (const auto& p : out.stats.passes) passes += p.name + " ";
    std::printf("%s: quadrature %.4f, default frame %.4f (%+.2f%%), reference %.4f (%+.2f%%); passes %s\n", c.name,
                expected, frame, 100 * (frame / expected - 1), truth, 100 * (truth / expected - 1), passes.c_str());
    EXPECT_NEAR(truth / expected, 1.0, 0.02) << c.name;
    EXPECT_NEAR(frame / expected, 1.0, 0.02) << c.name;
  }
}

}  // namespace
}  // namespace radiant
