#pragma once
// Binds what shaders/common/direct_lighting.glsl reads: lights and shadow-map infos (SSBO 1, 2), the
// shadow maps (units 6, 7) and the materials (SSBO 0), and sets its uniforms on `program`.
// Any pass that shades surfaces by direct light (the direct pass per pixel, environment cube maps
// per texel) calls this instead of repeating the bindings.
#include "renderer/frame/FrameResources.h"
#include "renderer/frame/GpuScene.h"
#include "renderer/gl/Gl.h"

namespace radiant {

// Declares 1x1 placeholders for the shadow resources when the shadow_maps pass did not run, so the
// samplers are complete. Call from prepare().
void declareDirectLightingResources(FrameResources& resources);
void bindDirectLighting(const gl::Program& program, FrameResources& resources, const GpuScene& gpu,
                        int lightCount, int pcfRadius);

}  // namespace radiant
