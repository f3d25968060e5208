#pragma once
// GPU and CPU time per pass. Every execute() runs inside a Scope with a steady-clock timer (cpu_ms: the
// time in execute(), issuing the pass's commands) and, by Method (stats.pass_timing):
//
// - TimerQuery (hardware devices): a GL_TIME_ELAPSED query (64-bit result) per pass. Query objects come
//   from a pool that grows to the largest pass count seen, so steady-state frames create none. Results
//   are collected after readback, when the GPU has finished the frame, so reading them never stalls
//   the pipeline.
// - Finish (software devices: llvmpipe): glFinish() before and after the pass, and gpu_ms is the wall
//   time between the two (its commands issued and executed). llvmpipe's timer queries cannot be trusted
//   per pass: its rasteriser threads run one pass's work while the next pass's CPU code runs, and a
//   query spans both, so most of a frame showed up under `direct` (issue 31). On a CPU "GPU" the
//   serialisation costs nothing that was not already CPU time.
#include <chrono>
#include <vector>

#include "api/Types.h"
#include "renderer/gl/Gl.h"

namespace radiant {

class GpuProfiler {
public:
  enum class Method { TimerQuery, Finish };
  explicit GpuProfiler(Method method = Method::TimerQuery) : method_(method) {}
  Method method() const { return method_; }
  // The stats' name of the method: "timer_query" or "finish_bracketed".
  const char* methodName() const { return method_ == Method::Finish ? "finish_bracketed" : "timer_query"; }

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
  Method method_;
  std::vector<gl::TimerQuery> pool_;
  std::size_t used_ = 0;
  std::vector<std::pair<std::size_t, api::PassStats*>> pending_;
};

}  // namespace radiant
