#pragma once
// Binds what shaders/common/direct_lighting.glsl reads: lights and shadow-map infos (SSBO 1, 2), the
// shadow maps (units 6, 7) and the materials (SSBO 0), and sets its uniforms on `program`.
// Any pass that shades surfaces by direct light (the direct pass per pixel, environment cube maps
// per texel) calls this instead of repeating the bindings.
#include "renderer/frame/FrameResources.h"
#include "renderer/frame/GpuScene.h"
#include "renderer/gl/Gl.h"

namespace radiant {

// What the shadow_maps pass publishes on the frame's blackboard under its output "shadow_maps"
// (FrameResources::publish): the point lights' cube-map array, the spot and directional lights' 2D
// array and their infos (gpu::ShadowInfo), which bindDirectLighting binds for every pass that declares
// "shadow_maps" an input, so none of them opens the shadow pass's resources by name.
struct ShadowMapSet {
  gl::Texture* cube = nullptr;
  gl::Texture* flat = nullptr;
  gl::Buffer* info = nullptr;
};

// Declares 1x1 placeholders (its own resources) that stand in for the shadow maps when the shadow_maps
// pass did not run, so the samplers are complete. Call from prepare().
void declareDirectLightingResources(FrameResources& resources);
// The frame's lights as the GPU reads them ("frame_lights": the scene's, then the environment's,
// FrameView::lights); the Renderer uploads it before the passes, bindDirectLighting binds it.
void declareFrameLights(FrameResources& resources, const FrameView& view);
// Binds the published ShadowMapSet (u_hasShadows 1), or the placeholders (u_hasShadows 0).
// `lightCount`: how many of the frame's lights to shade with (the scene's alone, ctx.scene.lights.size(),
// or with the environment's, ctx.view.lights.size()).
void bindDirectLighting(const gl::Program& program, FrameResources& resources, const GpuScene& gpu,
                        int lightCount, int pcfRadius);

}  // namespace radiant
