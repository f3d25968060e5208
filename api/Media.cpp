#include "api/Media.h"

#include <algorithm>
#include <cmath>

#include "api/Sha256.h"
#include "api/Types.h"
#include "api/Validate.h"

namespace radiant::api {

using nlohmann::json;

const char* toString(MediumKind k) {
  switch (k) {
    case MediumKind::Dust: return "dust";
    case MediumKind::Fire: return "fire";
    case MediumKind::Cloud: return "cloud";
    default: return "smoke";
  }
}
const char* toString(PhaseModel p) {
  switch (p) {
    case PhaseModel::HenyeyGreenstein: return "hg";
    case PhaseModel::CornetteShanks: return "cornette_shanks";
    default: return "isotropic";
  }
}
const char* toString(DensityProfile p) {
  switch (p) {
    case DensityProfile::Thesis: return "thesis";
    case DensityProfile::LinearExact: return "linear_exact";
    default: return "constant";
  }
}

const json& gltfMediaSchema() {
  static const json s = renderRequestSchema().at("x-gltf-media");
  return s;
}

namespace {

std::uint64_t mix(std::uint64_t z) {  // SplitMix64's finaliser (the same hash as rt::Sampler)
  z += 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}
// u in [0, 1) for (seed, particle, dimension).
float uniform(std::uint64_t seed, std::uint64_t i, std::uint64_t dim) {
  return static_cast<float>(mix(mix(mix(seed) ^ i) ^ (dim * 0xA0761D6478BD642Full)) >> 40) * 0x1p-24f;
}

glm::vec3 vec3(const json& a) { return {a[0].get<float>(), a[1].get<float>(), a[2].get<float>()}; }

[[noreturn]] void invalid(const std::string& pointer, const std::string& detail) {
  throw ApiError(422, "invalid-value", "Invalid value", pointer + ": " + detail, pointer);
}

void checkCount(std::size_t n, std::size_t maxParticles, const std::string& pointer) {
  if (n > maxParticles)
    throw ApiError(422, "limit-exceeded", "Server limit exceeded",
                   pointer + ": " + std::to_string(n) + " particles exceed the " + std::to_string(maxParticles) +
                       " this server has left for them (its particle limit, radiantd --max-particles, counts "
                       "every system of the request together)",
                   pointer);
}

MediumKind kindOf(const std::string& s) {
  if (s == "dust") return MediumKind::Dust;
  if (s == "fire") return MediumKind::Fire;
  if (s == "cloud") return MediumKind::Cloud;
  return MediumKind::Smoke;
}

// Thesis 7.2.1 (smoke 0.2, dust 0.9), 7.2.2 (fire 0), ch. 9 (clouds 0.9).
float defaultAlbedo(MediumKind k) {
  switch (k) {
    case MediumKind::Smoke: return 0.2f;
    case MediumKind::Fire: return 0.f;
    default: return 0.9f;
  }
}

}  // namespace

ParticleSystem makeParticleSystem(const json& s, const ParticleColumns* columns, const std::string& pointer,
                                  std::size_t maxParticles) {
  ParticleSystem out;
  out.name = s.value("name", "");
  out.kind = kindOf(s.at("kind").get<std::string>());
  const std::string profile = s.at("profile");
  out.profile = profile == "thesis" ? DensityProfile::Thesis
                : profile == "linear_exact" ? DensityProfile::LinearExact
                                            : DensityProfile::Constant;
  const std::string phase = s.at("phase").at("model");
  out.phase = phase == "hg" ? PhaseModel::HenyeyGreenstein
              : phase == "cornette_shanks" ? PhaseModel::CornetteShanks
                                           : PhaseModel::Isotropic;
  out.g = s.at("phase").at("g").get<float>();
  out.emissionScale = s.at("emission_scale").get<float>();
  out.time = s.at("time").get<float>();
  const float tau = s.at("tau").get<float>();
  const glm::vec3 albedo = s.contains("albedo") ? vec3(s["albedo"]) : glm::vec3(defaultAlbedo(out.kind));
  const float tBias = s.at("temperature").at("bias").get<float>();
  const float tScale = s.at("temperature").at("scale").get<float>();
  const std::uint64_t seed = s.at("seed").get<std::uint64_t>();
  auto temperature = [&](std::size_t i) { return out.emits() ? tBias + tScale * uniform(seed, i, 7) : 0.f; };

  const bool hasGenerator = s.contains("generator");
  if (hasGenerator == (columns != nullptr))
    invalid(pointer, hasGenerator ? "gives both particles and generator; give one"
                                  : "gives neither particles nor generator; give one");
  if (columns) {
    const std::size_t n = columns->positions.size();
    checkCount(n, maxParticles, pointerAppend(pointer, "particles"));
    out.particles.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      Particle& p = out.particles[i];
      p.position = columns->positions[i];
      p.radius = columns->radii[i];
      p.tau = columns->tau.empty() ? tau : columns->tau[i];
      p.albedo = columns->albedo.empty() ? albedo : columns->albedo[i];
      p.temperature = columns->temperature.empty() ? temperature(i) : columns->temperature[i];
      // The glTF accessors are not bounded by the schema: the same rules as the request's items.
      const std::string at = pointerAppend(pointerAppend(pointer, "particles"), i);
      if (!(p.radius > 0.f) || !std::isfinite(p.radius)) invalid(at + "/r", "a particle radius must be above 0");
      if (!(p.tau >= 0.f) || !std::isfinite(p.tau)) invalid(at + "/tau", "tau must be finite and >= 0");
      if (!(p.temperature >= 0.f) || !std::isfinite(p.temperature))
        invalid(at + "/temperature", "a temperature must be finite and >= 0 K");
      for (int c = 0; c < 3; ++c) {
        if (!(p.albedo[c] >= 0.f && p.albedo[c] <= 1.f)) invalid(at + "/albedo", "albedo must lie in [0, 1]");
        if (!std::isfinite(p.position[c]) || std::abs(p.position[c]) > 1e9f)
          invalid(at + "/p", "a position must be finite and within [-1e9, 1e9]");
      }
    }
    return out;
  }
  const json& g = s["generator"];
  const std::size_t n = g.at("count").get<std::size_t>();
  checkCount(n, maxParticles, pointerAppend(pointerAppend(pointer, "generator"), "count"));
  const glm::vec3 center = vec3(g.at("center")), extent = vec3(g.at("extent"));
  const bool box = g.at("shape") == "box";
  const float radius = g.at("radius").get<float>(), jitter = g.at("radius_jitter").get<float>();
  const float travel = g.at("speed").get<float>() * out.time;
  out.particles.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    Particle& p = out.particles[i];
    glm::vec3 q;
    if (box) {
      q = glm::vec3(uniform(seed, i, 0), uniform(seed, i, 1), uniform(seed, i, 2)) * 2.f - 1.f;
    } else {  // uniform in the unit ball: direction from two numbers, radius as the cube root
      const float z = 1.f - 2.f * uniform(seed, i, 0), phi = 6.28318530718f * uniform(seed, i, 1);
      const float rr = std::sqrt(std::max(0.f, 1.f - z * z));
      q = std::cbrt(uniform(seed, i, 2)) * glm::vec3(rr * std::cos(phi), rr * std::sin(phi), z);
    }
    const float z = 1.f - 2.f * uniform(seed, i, 3), phi = 6.28318530718f * uniform(seed, i, 4);
    const float rr = std::sqrt(std::max(0.f, 1.f - z * z));
    const glm::vec3 dir(rr * std::cos(phi), rr * std::sin(phi), z);
    p.position = center + q * extent + travel * dir;
    p.radius = radius * (1.f + jitter * (2.f * uniform(seed, i, 5) - 1.f));
    p.tau = tau;
    p.albedo = albedo;
    p.temperature = temperature(i);
  }
  return out;
}

ParticleSystem particleSystemFromRequest(const json& s, const std::string& pointer, std::size_t maxParticles) {
  if (!s.contains("particles")) return makeParticleSystem(s, nullptr, pointer, maxParticles);
  const json& items = s["particles"];
  checkCount(items.size(), maxParticles, pointerAppend(pointer, "particles"));
  ParticleColumns c;
  const bool anyTau = std::any_of(items.begin(), items.end(), [](const json& p) { return p.contains("tau"); });
  const bool anyAlbedo = std::any_of(items.begin(), items.end(), [](const json& p) { return p.contains("albedo"); });
  const bool anyT = std::any_of(items.begin(), items.end(), [](const json& p) { return p.contains("temperature"); });
  // Per-particle values that some particles leave out take the system's value: fill the columns
  // with it by making the system once without them.
  const ParticleSystem defaults = [&] {
    ParticleColumns d;
    for (const json& p : items) d.positions.push_back(vec3(p["p"])), d.radii.push_back(p["r"].get<float>());
    return makeParticleSystem(s, &d, pointer, maxParticles);
  }();
  for (std::size_t i = 0; i < items.size(); ++i) {
    const json& p = items[i];
    c.positions.push_back(vec3(p["p"]));
    c.radii.push_back(p["r"].get<float>());
    if (anyTau) c.tau.push_back(p.contains("tau") ? p["tau"].get<float>() : defaults.particles[i].tau);
    if (anyAlbedo) c.albedo.push_back(p.contains("albedo") ? vec3(p["albedo"]) : defaults.particles[i].albedo);
    if (anyT)
      c.temperature.push_back(p.contains("temperature") ? p["temperature"].get<float>()
                                                        : defaults.particles[i].temperature);
  }
  if (!anyTau && !anyAlbedo && !anyT) return defaults;
  return makeParticleSystem(s, &c, pointer, maxParticles);
}

std::string mediaDigest(const std::vector<ParticleSystem>& systems) {
  Sha256 h;
  for (const ParticleSystem& s : systems) {
    const int header[4] = {static_cast<int>(s.kind), static_cast<int>(s.profile), static_cast<int>(s.phase),
                           static_cast<int>(s.particles.size())};
    const float values[3] = {s.g, s.emissionScale, s.time};
    h.update(header, sizeof header);
    h.update(values, sizeof values);
    for (const Particle& p : s.particles) {
      const float v[9] = {p.position.x, p.position.y, p.position.z, p.radius, p.tau,
                          p.albedo.x,   p.albedo.y,   p.albedo.z,   p.temperature};
      h.update(v, sizeof v);
    }
  }
  return "sha256:" + h.finishHex();
}

}  // namespace radiant::api
