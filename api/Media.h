#pragma once
// Participating media as particle systems (thesis ch. 7-9): the shared data model of the volumetric
// reference and of every media technique (spherical billboards now; depth impostors and illumination
// networks reuse it). A system arrives in the render request (media: [...]) or in a glTF node
// (extension RADIANT_particle_system); both are validated against api/schema/media.json and become
// the same typed ParticleSystem, with generators expanded into explicit particles and every
// per-particle value resolved (tau, albedo, temperature), so consumers never see defaults.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

namespace radiant::api {

enum class MediumKind { Smoke, Dust, Fire, Cloud };
enum class PhaseModel { Isotropic, HenyeyGreenstein, CornetteShanks };
// Constant: tau inside the sphere. LinearExact: tau (1 - |x - c| / r). Thesis: eq. 7.4's heuristic
// opacity for billboards; its density (for the reference) is LinearExact's.
enum class DensityProfile { Constant, Thesis, LinearExact };

struct Particle {
  glm::vec3 position{0.f};  // world metres
  float radius = 1.f;       // metres, > 0
  float tau = 0.4f;         // extinction per metre at the centre
  glm::vec3 albedo{0.f};    // single-scattering albedo
  float temperature = 0.f;  // kelvin (fire; 0 elsewhere)
};

struct ParticleSystem {
  std::string name;
  MediumKind kind = MediumKind::Smoke;
  DensityProfile profile = DensityProfile::Constant;
  PhaseModel phase = PhaseModel::Isotropic;
  float g = 0.f;
  // Fire radiance = emissionScale * blackbody(T) normalised to Y(3000 K) = 1 (renderer/raytracing/Media.h).
  float emissionScale = 1.f;
  float time = 0.f;
  std::vector<Particle> particles;
  bool emits() const { return kind == MediumKind::Fire; }
};

const char* toString(MediumKind k);      // "smoke" | "dust" | "fire" | "cloud"
const char* toString(PhaseModel p);      // "isotropic" | "hg" | "cornette_shanks"
const char* toString(DensityProfile p);  // "constant" | "thesis" | "linear_exact"

// The schema of one system as the glTF node extension carries it (particles as accessor indices).
const nlohmann::json& gltfMediaSchema();

// Per-particle columns of a system given explicitly (request "particles" or glTF accessors); the
// optional columns are empty or have one entry per particle.
struct ParticleColumns {
  std::vector<glm::vec3> positions;
  std::vector<float> radii, tau, temperature;
  std::vector<glm::vec3> albedo;
};

// A system from its validated JSON (defaults filled in by api::validate) and its particles: either
// `columns` (explicit) or the JSON's generator (expanded here, deterministically from seed and
// time). `pointer` locates the system for errors (ApiError 422 with a pointer): a system with both or
// neither of particles and generator, a non-positive radius or negative tau in the columns, or more
// than `maxParticles` particles (limit-exceeded).
ParticleSystem makeParticleSystem(const nlohmann::json& system, const ParticleColumns* columns,
                                  const std::string& pointer, std::size_t maxParticles);

// The request form: "particles" as JSON objects.
ParticleSystem particleSystemFromRequest(const nlohmann::json& system, const std::string& pointer,
                                         std::size_t maxParticles);

// Content digest of systems (positions, radii, values, models): the cache key of derived media data.
std::string mediaDigest(const std::vector<ParticleSystem>& systems);

}  // namespace radiant::api
