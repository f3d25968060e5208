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
  int K = 1;
  // The group of a block centred at c (by its centre's depth along the light).
  int group(const glm::vec3& c) const;
  // Depth along the light in knot units: 0 at dmin, K at dmax.
  float knot(const glm::vec3& x) const;
  // Slice-image coordinates in [0, 1]^2.
  glm::vec2 uv(const glm::vec3& x) const;
};
SliceFrame fitSliceFrame(const std::vector<Block>& blocks, const glm::vec3& axis, int K);

// The transmittance at knot coordinate s in [0, K] from the K slice values at one texel (slice k =
// knot k + 1; knot 0 is 1), interpolated linearly between the enclosing knots.
float interpolateSlices(const float* slices, int K, float s);

// The impostor frame of an axis: the same orthonormal basis (Duff et al. 2017, rt::ShadingFrame)
// as shaders/depth_impostors/frame.glsl.
void impostorBasis(const glm::vec3& axis, glm::vec3& u, glm::vec3& v);

}  // namespace radiant::impostors
