#pragma once
// A request's cancel flag as long-running work sees it (docs/API.md, "Jobs, queue, timeouts"): a
// timed-out, DELETEd or shut-down render stops within one second, whatever it is doing. Every loop that
// can run longer than a few milliseconds polls it: CPU tracers per tile, row or block of photons, GPU
// passes between stretches of draws or dispatches. Polling is one relaxed atomic load, so a poll every
// millisecond costs nothing measurable.
//
// The one token type of the renderer: PassContext::cancel in execute(), FrameResources::cancel() in
// prepare() and the derived-data builders, and the options of the CPU tracers (reference/, raytracing/)
// all carry a Cancel. It holds no flag by default (never cancelled), so tests and tools need not set it.
//
// Work that sees the flag throws rt::Cancelled. Nothing half-built may be stored as complete on the way
// out: builders throw before they publish (FrameResources::cached() stores only what build() returned),
// and TBB joins every worker of a parallel_for before the exception reaches the caller. The Renderer
// turns Cancelled into the 409 "canceled" ApiError.
#include <atomic>
#include <stdexcept>
#include <string>
#include <string_view>

namespace radiant::rt {

struct Cancelled : std::runtime_error {
  explicit Cancelled(const std::string& where) : std::runtime_error("the render was cancelled during " + where) {}
};

class Cancel {
public:
  Cancel() = default;
  explicit Cancel(const std::atomic<bool>* flag) : flag_(flag) {}
  // Whether the request was cancelled or timed out (a relaxed load: the flag only ever turns true).
  bool requested() const { return flag_ && flag_->load(std::memory_order_relaxed); }
  // Throws Cancelled naming `where` (a pass and the loop in it) when requested().
  void check(std::string_view where) const {
    if (requested()) throw Cancelled(std::string(where));
  }
  const std::atomic<bool>* flag() const { return flag_; }

private:
  const std::atomic<bool>* flag_ = nullptr;
};

}  // namespace radiant::rt
