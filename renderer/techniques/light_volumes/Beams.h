#pragma once
// Light volumes, the CPU side: beam set-up from every scatterer triangle facing a punctual light
// (Duvenhage et al. §3.1, §4.3), the beams' culling bounds, and a CPU reading of the per-fragment
// gathering (the same code as the shader: shaders/light_volumes/beam.glsl) for the tests.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "renderer/raytracing/Cancel.h"
#include "renderer/scene/Scene.h"

namespace radiant::light_volumes {

namespace glsl {
using glm::vec2;
using glm::vec3;
using glm::vec4;
using glm::ivec4;
using glm::abs;
using glm::atan;
using glm::clamp;
using glm::cross;
using glm::dot;
using glm::exp;
using glm::length;
using glm::max;
using glm::min;
using glm::normalize;
#include "shaders/light_volumes/beam.glsl"
}  // namespace glsl

using Beam = glsl::Beam;
using BeamCone = glsl::BeamCone;
static_assert(sizeof(Beam) == 128, "std430 Beam is 8 x vec4");
static_assert(sizeof(BeamCone) == 32, "std430 BeamCone is 2 x vec4");
using BeamBvhNode = glsl::BeamBvhNode;
static_assert(sizeof(BeamBvhNode) == 48, "std430 BeamBvhNode is 3 x vec4");

enum class Split { Paper = glsl::kLvSplitPaper, TwoD = glsl::kLvSplit2d };

// The roughness fit sigma = kSigmaScaleFit alpha sqrt(cos theta_i) (notes A8), calibrated against the
// reference BSDF's GGX lobe: the scale that minimises the L1 distance between the normalised lobe
// D V cos(theta_o) and the Gaussian, summed over roughness 0.1..0.5 and theta_i 0..60 degrees
// (tests/unit/light_volumes: SigmaFitIsTheL1BestGaussianOfTheReferenceLobe; docs/TECHNIQUES.md).
constexpr float kSigmaScaleFit = 1.58f;

struct BeamOptions {
  float sigmaScale = kSigmaScaleFit;  // sigma = sigmaScale * alpha * sqrt(cos theta_i), alpha = roughness^2
  bool negativeBeams = false;     // build a shadow beam of -Phi per scatterer triangle (§3.1)
  float maxConcentration = 1e4f;  // irradiance clamp: Phi / A_perp <= maxConcentration * Phi / A_0
  float maxTriangleSigma = 0.5f;  // tessellation condition: triangle edge / receiver distance <= this * sigma
  bool specularFallback = true;   // a scatterer failing the condition gets specular beams
  float cullSigmas = 4.f;         // glossy culling bounds are padded by this many sigma
  // Subdivision of glossy scatterer triangles that fail the tessellation condition (1-to-4 midpoint
  // splits until every child meets it), up to this many beams added over the whole beam set (children
  // minus the beams they replace). A scatterer whose subdivision would exceed what is left of it is not
  // subdivided and falls back (specularFallback) as before. 0: never subdivide.
  std::size_t maxSubdivisionBeams = 65536;
  // Polled per batch of triangles and of tessellation checks (which trace rays) and per subdivided
  // triangle: buildBeams() then throws rt::Cancelled.
  rt::Cancel cancel;
  // > 0: every scattered beam gets this sigma (a Gaussian-lobe debug BSDF, notes A6: it separates the
  // algorithm's error from the GGX fit's). Tests only; not a request knob.
  float sigmaOverride = 0.f;
};

// Distance from `origin` along the unit `dir` to the first receiver (negative: none). The technique
// traces it with Embree; tests may pass none (the tessellation condition is then not checked).
using ReceiverDistance = std::function<float(const glm::vec3& origin, const glm::vec3& dir)>;

struct BeamSet {
  std::vector<Beam> beams;
  std::vector<BeamCone> cones;  // one per beam
  std::size_t scattered = 0, shadow = 0, glossy = 0;
  std::size_t backfacing = 0;   // triangles facing away from a light (not scattering)
  std::size_t tirDropped = 0;   // refracted beams dropped for total internal reflection at a vertex
  std::size_t degenerate = 0;   // zero-area triangles or zero solid angle
  std::size_t volumeAttenuated = 0;  // beams travelling inside a KHR_materials_volume medium (Beer-Lambert)
  // The tessellation condition (notes A5: a glossy beam conserves energy when its triangle subtends
  // at most about sigma / 2 from the receiver): glossy beams checked, those that fail it, the worst
  // (edge / distance) / sigma, and the scatterers (mesh x light) that fell back to specular beams.
  std::size_t tessellationChecked = 0, tessellationFailed = 0, specularFallbacks = 0;
  float worstTriangleSigma = 0.f;
  // Subdivision (BeamOptions::maxSubdivisionBeams): scatterers subdivided, beams added (children minus
  // the beams they replaced), glossy beams split, children that still fail at kMaxSubdivisionLevel,
  // and scatterers that were not subdivided because the budget would have been exceeded.
  std::size_t subdividedScatterers = 0, subdivisionBeamsAdded = 0, subdividedBeams = 0;
  std::size_t subdivisionStillFailing = 0, subdivisionBudgetExhausted = 0;
  // The same per scatterer (mesh x light) with glossy beams checked, in scene order. checked, failed and
  // worstTriangleSigma describe the scatterer's own triangles (before any subdivision).
  struct Scatterer {
    std::size_t mesh = 0, light = 0;
    std::string meshName;
    std::size_t checked = 0, failed = 0;
    float worstTriangleSigma = 0.f;
    bool specularFallback = false;
    std::size_t subdividedBeams = 0, beamsAdded = 0, stillFailing = 0;
    bool budgetExhausted = false;
  };
  std::vector<Scatterer> scatterers;
  glm::dvec3 flux{0.0};  // sum of the scattered beams' flux (W)
};

// Van Oosterom & Strackee 1983: the solid angle of the triangle (a, b, c) seen from the origin,
// tan(Omega / 2) = |a.(b x c)| / (|a||b||c| + (a.b)|c| + (a.c)|b| + (b.c)|a|).
float solidAngle(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c);

// The Gaussian's sigma (rad, scattered-angle standard deviation) for glTF roughness at incidence
// cos theta_i (notes A8): sigma = scale * alpha * sqrt(cos theta_i), alpha = roughness^2; 0 for
// roughness 0 (a Dirac lobe).
float sigmaFromRoughness(float roughness, float cosIncidence, float scale);

// The directional albedo of the reference's GGX reflection lobe (Bsdf.h: D V, height-correlated Smith)
// at cos theta_i = mu, split for Schlick's Fresnel: albedo(f0) = f0 (A - B) + B, with
// A = integral of D V cos(theta_o) and B = the same weighted by (1 - v.h)^5 (as in split-sum tables).
// A glossy beam carries flux x albedo: the Gaussian lobe integrates to 1, so the Smith masking
// loss (1 - A, 1% at roughness 0.3, 9% at 0.5 under normal incidence) must be in the flux. For
// alpha -> 0 it is (1, (1 - mu)^5): Schlick at the mirror direction. Tabulated in mu per alpha on
// first use (jittered stratified VNDF sampling, 64 x 64 samples at 33 values of mu, fixed seed), linear in between.
glm::vec2 ggxReflectionAlbedo(float mu, float alpha);

// Children of one glossy beam split 1-to-4 at its edges' midpoints, level after level, stop at this level
// (4^8 = 65536 children of one triangle).
constexpr int kMaxSubdivisionLevel = 8;

// An upper bound of buildBeams' scattered beams known before it runs (the cost model's `beams`): per
// light, one per triangle of each scatterer, two on a transmissive one (reflected and refracted). The
// set itself leaves out the triangles facing away from the light and total internal reflection, and
// adds the negative shadow beams (1570 of 1920 on cornell_glass).
double beamCountBound(const Scene& scene);

// Beams of every scatterer (Material::scattersNarrowLobe()) for every light of the scene.
BeamSet buildBeams(const Scene& scene, const BeamOptions& options, const ReceiverDistance& receiverDistance = {});

// One beam from a triangle and a light, for tests and for buildBeams: the scattered beam (reflected
// or, when `refract`, refracted with the material's ior) and optionally the shadow beam. Appends to
// `out`; returns false when the triangle does not scatter (back-facing, degenerate, TIR).
struct TriangleInput {
  glm::vec3 p[3];
  glm::vec3 n[3];
  Material material;
  bool refract = false;
};
bool appendTriangleBeams(const Light& light, const TriangleInput& t, const BeamOptions& options, BeamSet& out);

// The beams of one scatterer (the triangles of one mesh, `refract` unset: glass gets both beams) under
// one light, as buildBeams makes them: with `receiverDistance`, the tessellation condition checked per
// glossy beam, failing triangles subdivided within the budget, else the specular fallback; the
// scatterer's record is appended to out.scatterers under (mesh, lightIndex, name).
void appendScattererBeams(const Light& light, const std::vector<TriangleInput>& triangles, const BeamOptions& options,
                          const ReceiverDistance& receiverDistance, BeamSet& out, std::size_t mesh = 0,
                          std::size_t lightIndex = 0, const std::string& name = {});

// The tessellation condition's ratio of a glossy beam: its longest edge over the nearest receiver
// distance, in units of its sigma; the distance is the nearest hit of four rays (the centroid's along
// the mean direction N and each vertex's along its d_k); negative when none hits a receiver.
float tessellationRatio(const Beam& beam, const ReceiverDistance& receiverDistance);

// The culling bound of a beam (see BeamCone), padded by cullSigmas * sigma for glossy beams.
BeamCone beamCone(const Beam& beam, float cullSigmas);

// The irradiance at F (receiver normal n) summed over every beam: the shader's gathering, on the CPU.
glm::vec3 gatherIrradiance(const std::vector<Beam>& beams, const glm::vec3& F, const glm::vec3& n, Split split);

}  // namespace radiant::light_volumes
