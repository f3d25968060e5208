#pragma once
// Illumination networks (thesis ch. 9, Algorithm 7), the CPU side: the N network nodes sampled from
// a particle medium in proportion to its extinction, the D shared directions, the normalised phase
// quadrature, the visibility network V (N x D: upstream node and link opacity) and the iteration of
// the discretised volumetric rendering equation (eq. 9.1) in double precision. The GPU pass
// (IlluminationNetwork.h) builds V by per-direction projection and binning and iterates in fp32;
// this file is its oracle and the source of every table it uploads.
//
// Conventions. Directions are directions of propagation. I[p * D + i] is the radiance arriving at
// node p travelling along w_i; V[p, i] is the node q upstream of p along w_i (the nearest node before
// p in p's bin of the window perpendicular to w_i), or -1 when p is the first of its bin: the link
// then runs back to the bounding sphere, where the sky radiance enters. The link opacity is
// alpha = 1 - exp(-tau_link * length) with tau_link the mean of the two nodes' extinctions (the
// node's own extinction for the boundary link).
//
// The iteration (eq. 9.1 in the array form of §9.1.2, with the per-link opacity):
//   I'[p,i] = (1 - alpha) I[q,i] + alpha (e_q(w_i) + a_q S[q,i]),   S[q,i] = sum_d W[d,i] I[q,d],
// or, with Problem::linearSource, the link's source taken linear between q's and p's (see there),
// where W[d,i] = P(w_d . w_i) / sum_d' P(w_d' . w_i) (each column normalised, so a uniform field
// scatters into itself exactly: the furnace), e_q = emission (1 - a) L_e + the single-scattered
// directional lights a P(w_l . w_i) E_l T_l(q) at their exact directions (T_l from the network's
// chains along w_l), and for a boundary link q = p and I[q,i] = L_sky. The map is a contraction with
// factor max(1 - alpha (1 - a)) in the max norm (the thesis' convergence claim, L1566).
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

#include "api/Media.h"

namespace radiant::rt {
class ParticleMedium;
}

namespace radiant::network {

struct Node {
  glm::vec3 position{0.f};
  float tau = 0.f;           // extinction at the node (sum of the particles' densities there)
  glm::vec3 albedo{0.f};     // extinction-weighted albedo of the particles there
  glm::vec3 emission{0.f};   // source radiance per unit opacity: (1 - a) L_e, extinction-weighted
};

struct NodeSet {
  std::vector<Node> nodes;
  glm::vec3 center{0.f};  // bounding sphere of the medium
  float radius = 0.f;
  double mass = 0.0;      // integral of the extinction over the medium (optical volume, m^2)
  api::PhaseModel phase = api::PhaseModel::Isotropic;  // of the first scattering system (one per network)
  float g = 0.f;
};

// N nodes distributed as the medium's extinction (particle chosen by mass, then a point by its
// density profile), deterministic in seed.
NodeSet sampleNodes(const rt::ParticleMedium& medium, int count, std::uint64_t seed);

// Every direction of the window: the propagation direction and two unit vectors spanning the
// window's plane. Computed once here so that the GPU bins with the very same basis.
struct Direction {
  glm::vec3 w, u, v;
};
// D directions, uniform on the sphere: a Fibonacci lattice rotated by a seeded random rotation
// ("fibonacci"), or independent uniform samples ("random", as in the thesis).
std::vector<Direction> makeDirections(int count, bool fibonacci, std::uint64_t seed);
Direction directionBasis(glm::vec3 w);

// W[d * D + i]: normalised phase quadrature weights, sum_d W[d, i] = 1 for every i.
std::vector<float> phaseWeights(const std::vector<Direction>& dirs, api::PhaseModel phase, float g);
// The same column for one outgoing direction (the camera's).
std::vector<double> phaseColumn(const std::vector<Direction>& dirs, api::PhaseModel phase, float g, glm::vec3 out);
// The largest deviation of an unnormalised column sum (4 pi / D) sum_d P from 1 (oracle 4 of the notes).
double quadratureDeviation(const std::vector<Direction>& dirs, api::PhaseModel phase, float g);

// The window bin of a node (the GPU's formula, in float).
int binOf(const Direction& d, glm::vec3 center, float radius, int window, glm::vec3 x);
// Depth along w (float, as on the GPU).
inline float depthAlong(const Direction& d, glm::vec3 center, glm::vec3 x) { return glm::dot(x - center, d.w); }
// Distance from x back along -w to the bounding sphere.
float boundaryDistance(const Direction& d, glm::vec3 center, float radius, glm::vec3 x);

struct Visibility {
  int nodes = 0, directions = 0;
  std::vector<int> upstream;   // [p * D + i], -1 = the bounding sphere (sky)
  std::vector<float> alpha;    // link opacity
  double occupancy() const;    // fraction of links that see the sky
  int longestChain() const;    // nodes on the longest chain (iterations needed for exactness)
};
// The CPU build (binning as on the GPU; within a bin the upstream node is the one with the largest
// (depth, index) below p's).
Visibility buildVisibility(const NodeSet& nodes, const std::vector<Direction>& dirs, int window);

// The link opacities from the medium itself: alpha = 1 - exp(-optical depth of the medium along w_i over
// the link's length before p) (the boundary link: from the bounding sphere), instead of the nodes' mean
// extinction times the length. The same for a homogeneous medium; in a lumpy one the nodes, sampled in
// proportion to the extinction, sit in denser spots than the mean and make the links too opaque.
std::vector<float> exactLinkOpacity(const NodeSet& nodes, const std::vector<Direction>& dirs, const Visibility& V,
                                    const rt::ParticleMedium& medium);

// T0[p * D + i]: the transmittance of the unscattered sky along p's chain in direction i, the product
// of (1 - alpha) over the links up to and including the boundary link: the fixed point of the iteration
// with every source and albedo 0 and sky 1. I - sky T0 is the radiance scattered at least once.
std::vector<float> skyTransmittance(const Visibility& V);

struct DirectionalLight {
  glm::vec3 w;         // propagation direction (unit)
  glm::vec3 irradiance;
};

// T_l(p), [p * L + l]: the transmittance from the bounding sphere to each node along each light.
// Network: from the network's chains along the light direction (a one-direction network with a = 0,
// binned like the others, so as coarse laterally as the window). Exact: the medium's optical depth
// along the ray towards the light (rt::ParticleMedium, one ray per node and light).
std::vector<double> lightTransmittance(const NodeSet& nodes, const std::vector<DirectionalLight>& lights, int window);
std::vector<double> lightTransmittance(const NodeSet& nodes, const std::vector<DirectionalLight>& lights,
                                       const rt::ParticleMedium& medium);

struct Problem {
  const NodeSet* nodes = nullptr;
  const std::vector<Direction>* dirs = nullptr;
  const Visibility* visibility = nullptr;
  const std::vector<float>* weights = nullptr;  // phaseWeights
  std::vector<DirectionalLight> lights;
  std::vector<double> transmittance;  // lightTransmittance
  glm::dvec3 sky{0.0};
  // The source along a link: false = the upstream node's, constant over the link (Algorithm 7, eq. 9.1);
  // true = linear from q's to p's, integrated exactly: I' = (1 - alpha) I_q + alpha S_q + (S_p - S_q)
  // linearSourceWeight(alpha). Every coefficient stays in [0, 1] and a row still sums
  // to 1 - alpha (1 - a) for a uniform albedo, so the furnace, the pure absorber and the contraction
  // factor are unchanged; the scheme is second order along the link instead of first.
  bool linearSource = false;
};

// 1 - alpha / u with u = -ln(1 - alpha) the link's optical thickness: the weight of S_p - S_q in the
// exact transport of a source linear along the link, int_0^1 u t e^(-u (1 - t)) dt (u/2 for thin links,
// 1 for opaque ones).
double linearSourceWeight(double alpha);

// e_p(w): the node's source per unit opacity towards w (emission and single-scattered lights).
glm::dvec3 nodeSource(const Problem& pb, int p, glm::vec3 w);
// One iteration in double: out = F(in). Returns max |out - in| over nodes, directions and channels.
double iterate(const Problem& pb, const std::vector<glm::dvec3>& in, std::vector<glm::dvec3>& out);
// max over links of 1 - alpha (1 - a_q): the contraction factor.
double contractionFactor(const Problem& pb);
// The radiance the node sends towards w per unit opacity (the splat's source): e_p(w) + a_p sum_d
// W_d(w) I[p, d].
glm::dvec3 cameraSource(const Problem& pb, const std::vector<glm::dvec3>& I, int p, glm::vec3 w);

// Loop iterations one invocation of the marched final render (march.frag) may run in one draw, for the
// driver GL_RENDERER names (read once per context). Mesa's software rasterisers end every loop of a
// shader invocation after 65535 iterations in all, silently (gallivm's LP_MAX_TGSI_LOOP_ITERATIONS:
// llvmpipe; softpipe is treated alike, conservatively): kSoftwareLoopBudget leaves a margin under it.
// Other drivers have no such limit; there kHardwareLoopBudget only bounds one draw's work per pixel,
// so that a long march is split into stretches (each a cancel point) instead of one draw. The march
// falls back to splats only when one piece exceeds the budget, which on hardware the request limits
// rule out (IlluminationNetwork.cpp: kSkyExactMax).
inline constexpr long long kSoftwareLoopBudget = 60000;
inline constexpr long long kHardwareLoopBudget = 1 << 20;
long long shaderLoopBudget(std::string_view glRenderer);

// Loop iterations of one piece of the march: the particles met by the ray (all of them when more than
// 128 meet it), the nodes, per light the particles towards it, and per direction of the exact sky the
// same (march.frag).
long long marchPieceLoops(long long particles, long long nodes, long long lights, long long directions, bool skyExact);

}  // namespace radiant::network
