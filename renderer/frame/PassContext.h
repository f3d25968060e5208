#pragma once
#include <functional>

#include "api/Types.h"
#include "renderer/frame/FrameResources.h"
#include "renderer/frame/FrameView.h"
#include "renderer/frame/GpuScene.h"
#include "renderer/frame/Technique.h"
#include "renderer/gl/ShaderLibrary.h"

namespace radiant {

// Everything execute() may use. Counters go into stats.counters; timing is the scheduler's job.
struct PassContext {
  const Scene& scene;
  const GpuScene& gpu;
  const FrameView& view;
  const Params& params;
  FrameResources& resources;
  gl::ShaderLibrary& shaders;
  api::PassStats& stats;
  // The pass's own progress in [0, 1] (optional to call; thread-safe; the Renderer maps it onto the frame).
  std::function<void(double)> progress = [](double) {};
  // Whether the request has been cancelled or has timed out (the Renderer polls it between passes; a
  // long pass may poll it inside and stop early, e.g. illumination_network between iteration batches).
  std::function<bool()> cancelled = [] { return false; };
};

}  // namespace radiant
