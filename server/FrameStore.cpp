#include "server/FrameStore.h"

namespace radiant::server {

void FrameStore::put(const std::string& id, const std::string& name, std::string bytes, std::string contentType) {
  std::lock_guard lock(mutex_);
  const auto key = std::make_pair(id, name);
  if (auto it = frames_.find(key); it != frames_.end()) {
    total_ -= it->second.frame.bytes->size();
    frames_.erase(it);
  }
  total_ += bytes.size();
  frames_[key] = Entry{{std::make_shared<const std::string>(std::move(bytes)), std::move(contentType)}, Clock::now()};
  while (total_ > maxBytes_ && frames_.size() > 1) {
    auto oldest = frames_.end();
    for (auto it = frames_.begin(); it != frames_.end(); ++it)
      if (it->first != key && (oldest == frames_.end() || it->second.stored < oldest->second.stored)) oldest = it;
    if (oldest == frames_.end()) break;
    total_ -= oldest->second.frame.bytes->size();
    frames_.erase(oldest);
  }
}

std::optional<StoredFrame> FrameStore::get(const std::string& id, const std::string& name) {
  std::lock_guard lock(mutex_);
  auto it = frames_.find({id, name});
  if (it == frames_.end()) return std::nullopt;
  if (Clock::now() - it->second.stored > std::chrono::duration<double>(ttl_)) return std::nullopt;
  it->second.fetched = true;
  return it->second.frame;
}

std::size_t FrameStore::unfetched() {
  std::lock_guard lock(mutex_);
  std::size_t n = 0;
  for (const auto& [key, e] : frames_)
    n += !e.fetched && Clock::now() - e.stored <= std::chrono::duration<double>(ttl_);
  return n;
}

void FrameStore::eraseRender(const std::string& id) {
  std::lock_guard lock(mutex_);
  for (auto it = frames_.lower_bound({id, ""}); it != frames_.end() && it->first.first == id;) {
    total_ -= it->second.frame.bytes->size();
    it = frames_.erase(it);
  }
}

void FrameStore::purgeExpired() {
  std::lock_guard lock(mutex_);
  const auto now = Clock::now();
  for (auto it = frames_.begin(); it != frames_.end();) {
    if (now - it->second.stored > std::chrono::duration<double>(ttl_)) {
      total_ -= it->second.frame.bytes->size();
      it = frames_.erase(it);
    } else {
      ++it;
    }
  }
}

std::size_t FrameStore::totalBytes() {
  std::lock_guard lock(mutex_);
  return total_;
}

}  // namespace radiant::server
