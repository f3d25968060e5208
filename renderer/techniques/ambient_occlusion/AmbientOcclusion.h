#pragma once
// Screen-space ambient occlusion (Umenhoffer's thesis, ch. 4) with its baselines and the modern anchor:
//   volumetric   thesis eqs. 4.6-4.8 + Algorithm 2: unoccluded fraction of the tangent sphere (radius
//                R/2) summed over depth-buffer "pipes", normalised by weighted importance sampling.
//   containment  thesis eq. 4.5: cosine-distributed directions, distances from the falloff's inverse,
//                binary containment tests against the depth buffer.
//   crytek       whole-sphere depth-comparison SSAO (the thesis' Fig. 4.8 baseline; 1/2 on open planes).
//   gtao         Jimenez et al. 2016, cosine-weighted horizon-based ground-truth AO.
// Writes the `ao` AOV (R32F, [0,1]) and adds L^a * ao * diffuseAlbedo to `beauty` (thesis eq. 4.1 and
// L^r = a L^a O below it). The method is documented in docs/TECHNIQUES.md, the knobs in
// renderer/techniques/ambient_occlusion/ambient_occlusion.json.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "params/ambient_occlusion_params.h"
#include "renderer/frame/Technique.h"

namespace radiant {

namespace ao {

using Method = AmbientOcclusionParams::Method;    // the schema's "method": volumetric, containment, crytek, gtao
using Falloff = AmbientOcclusionParams::Falloff;  // containment's fuzzy membership mu(r): [r >= R] or (r/R)^3

constexpr int kMaxSamples = 64;
constexpr int kPatternCells = 16;  // 4x4 interleaved-sampling pattern (thesis 4.1.3)

// std140 uniform block shared with shaders/ambient_occlusion/ao.frag (binding kSampleBinding).
struct SampleBlock {
  glm::vec4 samples[kMaxSamples];     // method-specific kernel, see buildSampleBlock()
  glm::vec4 rotations[kPatternCells];  // per pattern cell: (cos a, sin a, gtao slice offset, gtao step jitter)
};
static_assert(sizeof(SampleBlock) == (kMaxSamples + kPatternCells) * 16, "std140 layout of AoSamples");

// n points on the unit disk with a Poisson-disk (blue-noise) distribution, uniform in area (each point
// stands for 1/n of the disk, as eq. 4.7 assumes): Mitchell's best candidate on the torus [0,1)^2 mapped
// by the area-preserving concentric map.
// Deterministic (fixed seed), identical on every machine.
std::vector<glm::vec2> poissonDisk(int n, std::uint32_t seed = 0x5eedu);
// n points uniform in the unit ball (Crytek's sphere kernel): Poisson-disk directions on the sphere,
// stratified radii cbrt((k + 1/2) / n) shuffled against them.
std::vector<glm::vec3> poissonBall(int n, std::uint32_t seed = 0x5eedu);

// The kernel uploaded to the shader:
//   volumetric:  (x_i, y_i, sqrt(1 - x_i^2 - y_i^2), 0), Poisson disk on the unit disk (eq. 4.7).
//   containment: (X_i, Y_i, Z_i, 0) / R = omega_i r_i / R in the tangent frame (eq. 4.5): omega_i is
//                cosine distributed (Malley: the Poisson-disk point lifted to the hemisphere) and
//                r_i = mu^-1(xi_i), xi_i stratified in (0,1): step -> r = R, cubic -> r = R xi^(1/3).
//   crytek:      points uniform in the unit ball (scaled by R in the shader), in antithetic pairs
//                (p, -p) so that every plane through x halves the kernel.
//   gtao:        unused (horizon marching), zeros.
// rotations: cell j of the 4x4 pattern rotates the kernel by alpha_j = 2 pi (rank_j + u_j) / 16, rank
// from a 4x4 Bayer matrix so that neighbouring pixels get distant angles, u_j random (fixed seed).
SampleBlock buildSampleBlock(Method method, Falloff falloff, int samples);

// GTAO: "samples" depth fetches split into slices x 2 sides x steps.
struct GtaoLayout {
  int slices, steps;
};
GtaoLayout gtaoLayout(int samples);


}  // namespace ao

class AmbientOcclusionPass final : public Technique {
public:
  const TechniqueInfo& info() const override;
  // The AO the frame estimated: same radius, and the definition its method estimates (volumetric:
  // the tangent-sphere fraction, thesis eq. 4.6; the others: the cosine-weighted step).
  GroundTruth groundTruth(const Params& params, const std::string& aov) const override;
  Requirements requirements(const Scene&, const api::RenderRequest&) const override;
  void prepare(const Scene&, const Params&, FrameResources&) override;
  void execute(PassContext&) override;

private:
  ao::Method method_ = ao::Method::kVolumetric;
  ao::Falloff falloff_ = ao::Falloff::kStep;
  int samples_ = 16;
  float radius_ = 0.5f;
  bool interleave_ = true;
  bool blur_ = true;
  int scale_ = 1;  // 1 = full resolution, 2 = half
  const ao::SampleBlock* block_ = nullptr;  // cached in FrameResources
};

}  // namespace radiant
