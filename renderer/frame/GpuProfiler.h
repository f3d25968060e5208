#pragma once
// GPU and CPU time per pass. Every execute() runs inside a Scope: a GL_TIME_ELAPSED query (64-bit
// result) and a steady-clock timer. Query objects come from a pool that grows to the largest pass
// count seen, so steady-state frames create none. Results are collected after readback, when the GPU
// has finished the frame, so reading them never stalls the pipeline.
#include <chrono>
#include <vector>

#include "api/Types.h"
#include "renderer/gl/Gl.h"

namespace radiant {

class GpuProfiler {
public:
  class Scope {
  public:
    Scope(GpuProfiler& p, api::PassStats& stats);
    ~Scope();
    Scope(const Scope&) = delete;
    Scope& operator=(const Scope&) = delete;
  private:
    GpuProfiler& profiler_;
    std::size_t slot_;
    std::chrono::steady_clock::time_point start_;
    api::PassStats& stats_;
  };

  void beginFrame() { used_ = 0; pending_.clear(); }
  // Fills gpuMs of every pass timed this frame. Call once the frame's work is complete.
  void resolve();

private:
  std::vector<gl::TimerQuery> pool_;
  std::size_t used_ = 0;
  std::vector<std::pair<std::size_t, api::PassStats*>> pending_;
};

}  // namespace radiant
