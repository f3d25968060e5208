#pragma once
// The CPU side of hierarchical depth impostors (thesis ch. 8): particles grouped into blocks, and the
// light-space frame of the light slices. No GL here (the unit tests and the GL stages share it).
//
// Blocks are spatial clusters, not one instanced template (thesis 8.1 offers both): a render request
// brings arbitrary particles (generated clouds, explosions, glTF accessors) which repeat no template,
// and the volumetric reference must see the very particles the technique draws. So every particle is
// still drawn once per direction into its block's impostor (cost N at impostor resolution, not the
// template's b); what the hierarchy saves is per-particle work at screen resolution, the sort (N/b
// blocks instead of N particles) and the light pass (N/b block quads per slice set).
#include <vector>

#include <glm/glm.hpp>

#include "renderer/frame/GpuTypes.h"

namespace radiant::impostors {

// One block: the bounding sphere of its particles and their range in BlockSet::particles.
struct Block {
  glm::vec3 center{0.f};
  float radius = 0.f;  // contains every particle sphere of the block
  int first = 0, count = 0;
  glm::vec3 source{0.f};  // the particles' direction-independent source, weighted by tau r^3
  glm::vec3 albedo{0.f};  // their albedo, weighted likewise
  float g = 0.f;
  int phaseModel = 0;
  int tile = -1;  // its impostor tile; -1 = its index in BlockSet::blocks
};

struct BlockSet {
  std::vector<gpu::MediaParticle> particles;  // grouped by block; models.z = the block's index
  std::vector<Block> blocks;
};

// Spatial clusters of about b particles: each system's particles are split at the median of the
// longest axis of their centres' box, recursively, into ceil(n / b) blocks whose sizes differ by at
// most one (blocks never mix systems, so a block has one phase function). Deterministic.
BlockSet buildBlocks(const std::vector<gpu::MediaParticle>& particles, const std::vector<int>& systemOf, int b);

// The orthographic light frame fitted to the whole system (thesis 8.1.2): rays travel along `axis`,
// (u, v) span the slice image over [-halfSize, halfSize]^2 around `center`, and the depths of the
// block centres along the axis, [dmin, dmax], are cut into K groups of equal thickness (a block's
// opacity counts at its centre's depth, so every group holds centres). Slice k holds the transmittance
// behind the blocks of groups 0..k, so the knots of the depth interpolation are dmin (transmittance 1)
// and dmin + (k + 1) (dmax - dmin) / K for slice k: a point between two knots sees its own group's
// blocks in proportion to its depth among them.
struct SliceFrame {
  glm::vec3 axis{0.f, 0.f, -1.f}, u{1.f, 0.f, 0.f}, v{0.f, 1.f, 0.f}, center{0.f};
  float halfSize = 1.f, dmin = 0.f, dmax = 1.f;
  // The depths along the light of the blocks' bounding spheres' nearest and farthest points: the
  // cloud's near and far planes, the interval [0, 1] of the Fourier opacity maps' normalised depth.
  float zNear = -1.f, zFar = 1.f;
  int K = 1;
  // The group of a block centred at c (by its centre's depth along the light).
  int group(const glm::vec3& c) const;
  // Depth along the light in knot units: 0 at dmin, K at dmax.
  float knot(const glm::vec3& x) const;
  // Slice-image coordinates in [0, 1]^2.
  glm::vec2 uv(const glm::vec3& x) const;
  // The Fourier opacity maps' normalised depth: 0 at zNear, 1 at zFar, clamped.
  float fourierDepth(const glm::vec3& x) const;
};
SliceFrame fitSliceFrame(const std::vector<Block>& blocks, const glm::vec3& axis, int K);

// The transmittance at knot coordinate s in [0, K] from the K slice values at one texel (slice k =
// knot k + 1; knot 0 is 1), interpolated linearly between the enclosing knots.
float interpolateSlices(const float* slices, int K, float s);

// Fourier opacity maps (Jansen and Bavoil, I3D 2010) as the alternative light-transmittance source
// (`light_transmittance: fourier`). Per slice texel, the extinction along the light over the
// normalised depth d in [0, 1] between the cloud's near and far planes is stored as the 2M + 1
// coefficients of its truncated Fourier series,
//   sigma(d) ~ a_0 / 2 + sum_k a_k cos(2 pi k d) + b_k sin(2 pi k d),  k = 1..M,
//   a_k = 2 int sigma cos(2 pi k d) dd,  b_k = 2 int sigma sin(2 pi k d) dd,
// accumulated by additive blending (a sum commutes: no sorting). Channel c of the coefficient image
// (channel c % 4 of texture c / 4) holds a_0 (c = 0), a_k (c = 2k - 1), b_k (c = 2k). A block adds at a
// texel its light impostor's optical depth tau = -ln T spread uniformly over its [front, back] there
// (the uniform density the gather assumes), a box [d0, d1] whose coefficients are closed-form:
//   a_0 = 2 tau,  a_k = 2 tau (sin 2 pi k d1 - sin 2 pi k d0) / (2 pi k (d1 - d0)),
//   b_k = 2 tau (cos 2 pi k d0 - cos 2 pi k d1) / (2 pi k (d1 - d0)).
// The optical depth to d is the series' integral from 0 (closed form),
//   D(d) = a_0 d / 2 + sum_k g_k (a_k sin(2 pi k d) + b_k (1 - cos(2 pi k d))) / (2 pi k),
// and the transmittance exp(-D). Truncation rings (Gibbs): the undamped series (g_k = 1) has negative
// density lobes beside every sharp edge, so D decreases and the transmittance rises along the light.
// The damping g_k is the Jackson kernel's (Weisse et al., Rev. Mod. Phys. 78, 275 (2006), eq. 71 with
// N = M + 1 moments), whose kernel 1 + 2 sum g_k cos(2 pi k x) is non-negative: the reconstructed
// density is the true one convolved with it, never negative, so D is non-decreasing from D(0) = 0 to
// D(1) = a_0 / 2 (the exact total) and the transmittance non-increasing in [exp(-a_0/2), 1] by
// construction (clamped as well, against rounding).
constexpr int kMaxFourierTerms = 7;  // 2M + 1 <= 16 channels of the four RGBA textures
int fourierChannels(int M);          // 2M + 1
double fourierDamping(int k, int M, bool damped = true);  // g_k (1 when not damped)
// A box of optical depth tau over normalised depths [d0, d1] added to coefficients c[0 .. 2M].
void addFourierBox(float* c, int M, double tau, double d0, double d1);
// D(d) from coefficients c[0 .. 2M]; `damped` false gives the plain truncated series (tests).
double fourierOpticalDepth(const float* c, int M, double d, bool damped = true);
// exp(-D(d)), D clamped to [0, a_0 / 2]: what the gather reads.
double fourierTransmittance(const float* c, int M, double d);

// The impostor frame of an axis: the same orthonormal basis (Duff et al. 2017, rt::ShadingFrame)
// as shaders/depth_impostors/frame.glsl.
void impostorBasis(const glm::vec3& axis, glm::vec3& u, glm::vec3& v);

}  // namespace radiant::impostors
