#pragma once
#include <functional>

#include "api/Types.h"
#include "renderer/frame/FrameResources.h"
#include "renderer/frame/FrameView.h"
#include "renderer/frame/GpuScene.h"
#include "renderer/frame/Technique.h"
#include "renderer/gl/ShaderLibrary.h"
#include "renderer/raytracing/Cancel.h"

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
  // The request's cancel flag (renderer/raytracing/Cancel.h): the Renderer polls it between passes, and
  // every loop of a pass that can run longer than a few milliseconds polls it too (per tile, row, block
  // of photons, stretch of GPU work) and throws rt::Cancelled, so that a cancelled, timed-out or
  // shut-down render stops within one second whatever pass it is in.
  rt::Cancel cancel{};
};

}  // namespace radiant
