#include "renderer/frame/GpuProfiler.h"

#include <string>

namespace radiant {

GpuProfiler::Scope::Scope(GpuProfiler& p, api::PassStats& stats) : profiler_(p), stats_(stats) {
  if (p.used_ == p.pool_.size()) p.pool_.emplace_back("pass timer " + std::to_string(p.used_));
  slot_ = p.used_++;
  p.pool_[slot_].begin();
  start_ = std::chrono::steady_clock::now();
}

GpuProfiler::Scope::~Scope() {
  profiler_.pool_[slot_].end();
  stats_.cpuMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_).count();
  profiler_.pending_.emplace_back(slot_, &stats_);
}

void GpuProfiler::resolve() {
  for (auto& [slot, stats] : pending_) stats->gpuMs = static_cast<double>(pool_[slot].resultNs()) * 1e-6;
  pending_.clear();
}

}  // namespace radiant
