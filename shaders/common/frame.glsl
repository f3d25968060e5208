// The frame's camera (common/shared.h FrameConstants), uploaded once per frame by
// FrameResources::beginFrame: u_frame.eye.xyz, u_frame.viewForward.xyz, u_frame.viewProj, ...
// Included by every program that looks through the frame's camera.
#ifndef RADIANT_COMMON_FRAME
#define RADIANT_COMMON_FRAME
#include "common/shared.h"
layout(std140, binding = kBindingFrameConstants) uniform FrameConstantsBlock { FrameConstants u_frame; };
#endif
