#pragma once
// Spherical billboards (thesis ch. 7, Algorithm 5): particle systems rendered as spheres on
// camera-facing quads, the opacity of each fragment from the length its ray travels inside the sphere,
// clamped to the near plane and the opaque scene (eqs. 7.1-7.3), so particles neither clip against
// geometry nor pop at the near plane. Baselines in the same pass: planar billboards and soft
// particles (method). Writes the `media` AOV (RGB premultiplied radiance, A transmittance) and
// composes beauty = beauty * T + C (layer composition, 7.2.3, at resolution ratio 1 to 1/8 with
// depth-aware upsampling).
//
// The particles' source radiance: fire emits (1 - albedo) emission_scale * blackbody(T) (Planck x
// CIE 1931 -> linear sRGB, renderer/raytracing/Media.h, the reference's own function, per particle on
// the CPU); scatterers add albedo * ambient (per particle) and albedo * the punctual lights' phase(mu)
// * Li per fragment at the middle of its ray's segment, unshadowed as in the thesis (7.2.1). Its
// ground truth is the volumetric reference's single_scatter_unshadowed mode (emission_absorption for
// fire alone).
#include <vector>

#include "renderer/frame/GpuTypes.h"
#include "renderer/gl/Gl.h"
#include "renderer/frame/Technique.h"
#include "renderer/shading/MediaLayer.h"

namespace radiant {

class SphericalBillboardsPass final : public Technique {
public:
  const TechniqueInfo& info() const override;
  Requirements requirements(const Scene&, const api::RenderRequest&) const override;
  void prepare(const Scene&, const Params&, FrameResources&) override;
  void execute(PassContext&) override;

  // The particles of `media` as the shaders read them, with their direction-independent source
  // radiance, sorted back to front for the view from `eye` (forward: the view direction, the sort key
  // of orthographic cameras) when `sort` (else in the systems' order). `systemOf` (when given; the
  // particles are then unsorted) receives each particle's index in `media`.
  static std::vector<gpu::MediaParticle> gpuParticles(const std::vector<api::ParticleSystem>& media,
                                                      glm::vec3 ambient, glm::vec3 eye, glm::vec3 forward,
                                                      bool orthographic, bool sort,
                                                      std::vector<int>* systemOf = nullptr) {
    return mediaParticles(media, ambient, eye, forward, orthographic, sort, systemOf);  // renderer/shading/MediaLayer.h
  }

private:
  std::vector<gpu::MediaParticle> particles_;
  gl::VertexArray vao_;  // empty: the quads are generated from gl_VertexID (core profile needs one bound)
  int method_ = 0, chord_ = 0;
  float ratio_ = 1.f, softScale_ = 1.f;
  bool depthAware_ = true;
  int lowWidth_ = 0, lowHeight_ = 0;
  double overdraw_ = 0.0;
};

}  // namespace radiant
