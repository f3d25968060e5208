#pragma once
// Encoded frames, addressed by render id and file name, kept for a TTL and bounded in bytes
// (oldest dropped first). Thread-safe.

#include <chrono>
#include <cstddef>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>

namespace radiant::server {

struct StoredFrame {
  std::shared_ptr<const std::string> bytes;
  std::string contentType;
};

class FrameStore {
public:
  using Clock = std::chrono::steady_clock;
  FrameStore(std::size_t maxBytes, double ttlSeconds) : maxBytes_(maxBytes), ttl_(ttlSeconds) {}
  void put(const std::string& id, const std::string& name, std::string bytes, std::string contentType);
  std::optional<StoredFrame> get(const std::string& id, const std::string& name);
  void eraseRender(const std::string& id);
  void purgeExpired();
  std::size_t totalBytes();
  // Frames stored and not yet expired that no GET has fetched (the shutdown grace waits for them).
  std::size_t unfetched();

private:
  struct Entry {
    StoredFrame frame;
    Clock::time_point stored;
    bool fetched = false;
  };
  std::mutex mutex_;
  std::map<std::pair<std::string, std::string>, Entry> frames_;
  std::size_t maxBytes_, total_ = 0;
  double ttl_;
};

}  // namespace radiant::server
