#pragma once
// The media layer every media technique writes and composes (spherical_billboards, depth_impostors;
// illumination_network; one of them per frame, FramePlanner): the "media" target (RGBA32F: RGB premultiplied radiance,
// A transmittance) and its composition into beauty, beauty = beauty * T + C (thesis 7.2.3).
#include "renderer/frame/FrameResources.h"
#include "renderer/frame/PassContext.h"
#include "renderer/frame/Technique.h"

namespace radiant {

struct FrameView;

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
