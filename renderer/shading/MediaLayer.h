#pragma once
// The media layer every media technique writes and composes (spherical_billboards, depth_impostors;
// illumination_network; one of them per frame, FramePlanner): the "media" target (RGBA32F: RGB premultiplied radiance,
// A transmittance) and its composition into beauty, beauty = beauty * T + C (thesis 7.2.3).
#include <cstddef>
#include <vector>

#include "renderer/frame/FrameResources.h"
#include "renderer/frame/GpuTypes.h"
#include "renderer/frame/PassContext.h"
#include "renderer/frame/Technique.h"

namespace radiant {

struct FrameView;

// The frame's particles as the media shaders read them (std430 gpu::MediaParticle): position and
// radius, the source term (1 - albedo) L_e + albedo L_ambient and optical depth, albedo and phase
// parameter, density profile and phase model; sorted back to front for the view from `eye` (forward:
// the view direction, the sort key of orthographic cameras) when `sort` (else in the systems' order).
// `systemOf` (when given; the particles are then unsorted) receives each particle's index in `media`.
std::vector<gpu::MediaParticle> mediaParticles(const std::vector<api::ParticleSystem>& media, glm::vec3 ambient,
                                               glm::vec3 eye, glm::vec3 forward, bool orthographic, bool sort,
                                               std::vector<int>* systemOf = nullptr);
// How many particles mediaParticles() returns (those with an optical depth above 0), without building
// them: of every system, or of one.
std::size_t mediaParticleCount(const std::vector<api::ParticleSystem>& media);
std::size_t mediaParticleCount(const api::ParticleSystem& system);

// Run when the frame has particles (the scene's or the request's), else skip with the reason.
Requirements mediaRequirements(const Scene& scene, const api::RenderRequest& request);
// Binds `target` (w x h), clears it to no light and transmittance 1, and sets the premultiplied
// blending of the media layer: C = alpha L + (1 - alpha) C, T = (1 - alpha) T. Depth test and writes off.
void beginMediaLayer(const gl::Framebuffer& target, int w, int h);
// The camera uniforms every media shader reads (common/media camera block): view, projection and its
// inverse, near plane, projection type, whether the G-buffer position is bound (u_hasDepth), the
// target's size (targetW x targetH, a lower-resolution layer or the frame) and the frame's size.
void setMediaCameraUniforms(const gl::Program& prog, const FrameView& view, bool hasDepth, int targetW, int targetH);
// Declares the media texture and framebuffer (w x h) and the composition framebuffer over beauty.
void declareMediaLayer(FrameResources& res, int w, int h);
// Composes the written media target into beauty (a frame without opaque passes starts from the sky)
// and marks beauty written.
void composeMediaIntoBeauty(PassContext& ctx);

}  // namespace radiant
