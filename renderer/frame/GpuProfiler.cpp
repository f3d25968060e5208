#include "renderer/frame/GpuProfiler.h"

#include <string>

namespace radiant {

namespace {
double msSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}
}  // namespace

GpuProfiler::Scope::Scope(GpuProfiler& p, api::PassStats& stats) : profiler_(p), slot_(0), stats_(stats) {
  if (p.method_ == Method::Finish) {
    glFinish();  // the earlier passes' work is theirs
  } else {
    if (p.used_ == p.pool_.size()) p.pool_.emplace_back("pass timer " + std::to_string(p.used_));
    slot_ = p.used_++;
    p.pool_[slot_].begin();
  }
  start_ = std::chrono::steady_clock::now();
}

GpuProfiler::Scope::~Scope() {
  if (profiler_.method_ == Method::Finish) {
    stats_.cpuMs = msSince(start_);
    glFinish();
    stats_.gpuMs = msSince(start_);
    return;
  }
  profiler_.pool_[slot_].end();
  stats_.cpuMs = msSince(start_);
  profiler_.pending_.emplace_back(slot_, &stats_);
}

void GpuProfiler::resolve() {
  for (auto& [slot, stats] : pending_) stats->gpuMs = static_cast<double>(pool_[slot].resultNs()) * 1e-6;
  pending_.clear();
}

}  // namespace radiant
