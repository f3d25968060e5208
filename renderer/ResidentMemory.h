#pragma once
// The process's resident set, the one measure of memory the daemon's limits are held to
// (radiantd --memory-target-bytes, --memory-limit-bytes): the renderer's accountant
// (FrameResources::makeRoom/admit) and the server's decode and body admission read the same number.
// Header only and GL-free, so the server core and its tests use it without a renderer.

#include <cstddef>
#include <cstdio>
#include <mutex>

#include <unistd.h>

namespace radiant {

// Bytes resident now (Linux /proc/self/statm); 0 where unavailable, which callers read as "unknown".
inline std::size_t residentBytes() {
  std::FILE* f = std::fopen("/proc/self/statm", "r");
  if (!f) return 0;
  unsigned long long size = 0, resident = 0;
  const int n = std::fscanf(f, "%llu %llu", &size, &resident);
  std::fclose(f);
  const long page = sysconf(_SC_PAGESIZE);
  return n == 2 && page > 0 ? static_cast<std::size_t>(resident) * static_cast<std::size_t>(page) : 0;
}

// Bytes admitted under the memory limit that may not be resident yet, process-wide: a decode's or a
// request body's reservation (the server) and the next large allocation of the frame being rendered
// (FrameResources::admit). Every admission compares the resident set plus these claims plus its own
// bytes with the limit, in one step under one lock, so concurrent admissions cannot each see room that
// only one of them has. A claim stays until its owner lets it go, also once its bytes are resident
// (then counted twice, on the safe side).
class MemoryClaims {
public:
  static MemoryClaims& process() {
    static MemoryClaims claims;
    return claims;
  }
  // Replaces the caller's claim `held` by `bytes` when resident + (claimed - held) + bytes <= limit, and
  // returns true; false leaves everything as it was. `resident` is read under the lock.
  template <class Resident>
  bool tryReplace(std::size_t held, std::size_t bytes, std::size_t limit, Resident&& resident, std::size_t* read = nullptr) {
    std::lock_guard lock(mutex_);
    const std::size_t r = resident();
    if (read) *read = r;
    const std::size_t others = claimed_ - held;
    if (r != 0 && (bytes > limit || r + others > limit - bytes)) return false;
    claimed_ = others + bytes;
    return true;
  }
  void release(std::size_t bytes) {
    std::lock_guard lock(mutex_);
    claimed_ -= bytes;
  }
  std::size_t claimed() {
    std::lock_guard lock(mutex_);
    return claimed_;
  }

private:
  std::mutex mutex_;
  std::size_t claimed_ = 0;
};

}  // namespace radiant
