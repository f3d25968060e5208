#pragma once
// What the Renderer allocates for a frame before any pass runs (ARCHITECTURE.md, "Resources are named
// and declared"): the declared outputs that are AOVs, in the AOV table's format at the frame's size,
// and the frame resources (beauty, the environment map). Passes look these up (FrameResources::
// texture(name)); a pass that declared one with another spec would throw rather than silently
// reallocate it (and lose, for beauty, what earlier passes accumulated).
#include <vector>

#include "renderer/frame/FrameResources.h"
#include "renderer/frame/FrameView.h"
#include "renderer/frame/Technique.h"

namespace radiant {

// Every accumulate AOV (beauty) and every AOV-table resource among the planned passes' outputs, as
// GL_TEXTURE_2D of the table's format and view.width x view.height. The accumulate AOVs are cleared to
// zero: every pass composes into beauty (BeautyBlend), none initialises it, so the passes that add to
// it commute and the frame graph orders them freely (a frame without the direct pass once added onto
// the previous frame's beauty).
void allocateDeclaredOutputs(FrameResources& resources, const std::vector<Technique*>& passes);

// The frame resource "environment_map" (kEnvironmentMap): view.environment as an RGBA32F equirect
// texture (nearest filtering; rows in image order, row 0 = up), uploaded when the texture does not hold
// this map (digest and size; FrameResources::refill, logged as "environment_map" in the stats); a
// 1x1 placeholder keeps the samplers complete in frames without a map. The map's importance-sampling
// distribution for the CPU core is cached beside it per digest (environmentDistribution() in
// renderer/frame/RayScenes.h).
void declareEnvironmentMap(FrameResources& resources, const FrameView& view);

}  // namespace radiant
