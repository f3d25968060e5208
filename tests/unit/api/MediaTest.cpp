// Particle systems in the request (api/schema/media.json -> api::ParticleSystem): defaults by kind,
// generators expanded deterministically, and every bad value a 422 whose pointer names the field.
#include <cmath>

#include <gtest/gtest.h>

#include "api/Validate.h"

using nlohmann::json;
using radiant::api::ApiError;
using radiant::api::parseRenderRequest;
using radiant::api::RequestLimits;

namespace {

json request(const json& media) { return json{{"scene", {{"builtin", "cornell_box"}}}, {"media", media}}; }

ApiError errorOf(const json& body, const RequestLimits& limits = {}) {
  try {
    parseRenderRequest(body, limits);
  } catch (const ApiError& e) {
    return e;
  }
  ADD_FAILURE() << "no error for " << body.dump();
  return ApiError(0, "", "", "");
}

json smoke() { return json{{"kind", "smoke"}, {"particles", json::array({{{"p", {0, 1, 0}}, {"r", 0.5}}})}}; }

}  // namespace

TEST(MediaRequest, ExplicitParticlesTakeTheKindsThesisDefaults) {
  json fire = {{"kind", "fire"},
               {"temperature", {{"bias", 2500}, {"scale", 0}}},
               {"particles", json::array({{{"p", {1, 2, 3}}, {"r", 0.25}, {"tau", 2.0}}, {{"p", {0, 0, 0}}, {"r", 1}}})}};
  const auto r = parseRenderRequest(request(json::array({smoke(), fire})));
  ASSERT_EQ(r.media.size(), 2u);
  const auto& s = r.media[0];
  EXPECT_EQ(s.kind, radiant::api::MediumKind::Smoke);
  ASSERT_EQ(s.particles.size(), 1u);
  EXPECT_FLOAT_EQ(s.particles[0].tau, 0.4f);        // thesis 7.2.1
  EXPECT_FLOAT_EQ(s.particles[0].albedo.x, 0.2f);   // smoke
  EXPECT_EQ(s.profile, radiant::api::DensityProfile::Constant);
  const auto& f = r.media[1];
  EXPECT_FLOAT_EQ(f.particles[0].tau, 2.0f);   // its own
  EXPECT_FLOAT_EQ(f.particles[1].tau, 0.4f);   // the system's
  EXPECT_FLOAT_EQ(f.particles[0].albedo.y, 0.f);  // fire absorbs only
  EXPECT_FLOAT_EQ(f.particles[1].temperature, 2500.f);  // bias + 0 * u
  EXPECT_FLOAT_EQ(f.particles[0].position.z, 3.f);
}

TEST(MediaRequest, GeneratorIsDeterministicAndStaysInItsShape) {
  json g = {{"kind", "dust"}, {"seed", 7},
            {"generator", {{"shape", "sphere"}, {"center", {1, 2, 3}}, {"extent", {2, 1, 0.5}}, {"count", 500},
                           {"radius", 0.1}, {"radius_jitter", 0.5}}}};
  const auto a = parseRenderRequest(request(json::array({g})));
  const auto b = parseRenderRequest(request(json::array({g})));
  ASSERT_EQ(a.media[0].particles.size(), 500u);
  EXPECT_EQ(radiant::api::mediaDigest(a.media), radiant::api::mediaDigest(b.media));
  for (const auto& p : a.media[0].particles) {
    const glm::vec3 q = (p.position - glm::vec3(1, 2, 3)) / glm::vec3(2, 1, 0.5);
    EXPECT_LE(glm::dot(q, q), 1.f + 1e-5f);  // inside the ellipsoid
    EXPECT_GE(p.radius, 0.05f - 1e-6f);
    EXPECT_LE(p.radius, 0.15f + 1e-6f);
  }
  g["seed"] = 8;
  EXPECT_NE(radiant::api::mediaDigest(parseRenderRequest(request(json::array({g}))).media),
            radiant::api::mediaDigest(a.media));
  // time moves generated particles by speed * time: every one exactly speed * time away.
  json moving = g;
  moving["generator"]["speed"] = 2.0;
  moving["time"] = 0.5;
  const auto m = parseRenderRequest(request(json::array({moving})));
  const auto still = parseRenderRequest(request(json::array({g})));
  for (std::size_t i = 0; i < 500; ++i)
    EXPECT_NEAR(glm::length(m.media[0].particles[i].position - still.media[0].particles[i].position), 1.0, 1e-5);
}

TEST(MediaRequest, BadValuesAre422WithAPointer) {
  json neg = smoke();
  neg["particles"][0]["tau"] = -1;
  ApiError e = errorOf(request(json::array({neg})));
  EXPECT_EQ(e.status, 422);
  EXPECT_EQ(e.pointer, "/media/0/particles/0/tau");

  json zeroRadius = smoke();
  zeroRadius["particles"][0]["r"] = 0;
  e = errorOf(request(json::array({smoke(), zeroRadius})));
  EXPECT_EQ(e.status, 422);
  EXPECT_EQ(e.pointer, "/media/1/particles/0/r");

  json both = smoke();
  both["generator"] = {{"count", 3}};
  e = errorOf(request(json::array({both})));
  EXPECT_EQ(e.status, 422);
  EXPECT_EQ(e.pointer, "/media/0");

  json neither = {{"kind", "smoke"}};
  EXPECT_EQ(errorOf(request(json::array({neither}))).pointer, "/media/0");

  json badKind = smoke();
  badKind["kind"] = "plasma";
  EXPECT_EQ(errorOf(request(json::array({badKind}))).pointer, "/media/0/kind");

  json badG = smoke();
  badG["phase"] = {{"model", "hg"}, {"g", 1.0}};  // g = 1 is a delta: bounded to 0.99
  EXPECT_EQ(errorOf(request(json::array({badG}))).pointer, "/media/0/phase/g");

  json typo = smoke();
  typo["albdo"] = {1, 1, 1};
  e = errorOf(request(json::array({typo})));
  EXPECT_EQ(e.type, "unknown-field");
  EXPECT_EQ(e.pointer, "/media/0/albdo");

  json albedo = smoke();
  albedo["albedo"] = {0.5, 1.5, 0.5};
  EXPECT_EQ(errorOf(request(json::array({albedo}))).pointer, "/media/0/albedo/1");
}

TEST(MediaRequest, ParticleCountIsBoundedByTheServerLimit) {
  RequestLimits limits;
  limits.maxParticles = 1000;
  json g = {{"kind", "smoke"}, {"generator", {{"count", 600}}}};
  EXPECT_NO_THROW(parseRenderRequest(request(json::array({g})), limits));
  // Two systems of 600 together exceed 1000: the second one's count is named.
  const ApiError e = errorOf(request(json::array({g, g})), limits);
  EXPECT_EQ(e.status, 422);
  EXPECT_EQ(e.type, "limit-exceeded");
  EXPECT_EQ(e.pointer, "/media/1/generator/count");
}
