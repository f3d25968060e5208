#pragma once
// The one least-recently-used container (issue 33: "one LRU used by every cache in the daemon"): the
// scene and image stores (server/ContentStore), the decoded scenes and images (server/HttpServer.cpp),
// the renderer's GPU scenes and its derived-data cache (renderer/frame/FrameResources.h) each keep
// their entries in one. It holds values by key in recency order with each entry's size in bytes, and
// evicts from the least recently used end under a caller's rule: what to keep (an entry in use), when
// to stop (a count, a byte budget), what to do with each evicted value (remove its file). Not
// thread-safe: each cache holds it under its own lock. Header-only, no dependencies.
#include <cstddef>
#include <iterator>
#include <list>
#include <map>
#include <utility>

namespace radiant::api {

template <class Key, class Value>
class Lru {
public:
  struct Entry {
    Key key;
    Value value;
    std::size_t bytes = 0;
  };
  using iterator = typename std::list<Entry>::iterator;
  using const_iterator = typename std::list<Entry>::const_iterator;

  // Most recently used first.
  iterator begin() { return list_.begin(); }
  iterator end() { return list_.end(); }
  const_iterator begin() const { return list_.begin(); }
  const_iterator end() const { return list_.end(); }
  std::size_t size() const { return list_.size(); }
  bool empty() const { return list_.empty(); }
  std::size_t bytes() const { return bytes_; }

  // The entry under `key`, or end(); the order is not changed.
  iterator find(const Key& key) {
    auto it = index_.find(key);
    return it == index_.end() ? list_.end() : it->second;
  }
  // Makes `it` the most recently used.
  void touch(iterator it) { list_.splice(list_.begin(), list_, it); }
  // The value under `key` made the most recently used, or nullptr.
  Value* use(const Key& key) {
    auto it = find(key);
    if (it == list_.end()) return nullptr;
    touch(it);
    return &it->value;
  }
  // Stores `value` under `key` as the most recently used (replacing an entry under the same key), or
  // as the least recently used with `leastRecent` (entries found on disk, oldest last).
  Entry& put(const Key& key, Value value, std::size_t bytes = 0, bool leastRecent = false) {
    erase(key);
    const iterator it = list_.insert(leastRecent ? list_.end() : list_.begin(), Entry{key, std::move(value), bytes});
    index_.emplace(key, it);
    bytes_ += bytes;
    return *it;
  }
  // Removes the entry `it` points to; returns the next one.
  iterator erase(iterator it) {
    bytes_ -= it->bytes;
    index_.erase(it->key);
    return list_.erase(it);
  }
  bool erase(const Key& key) {
    auto it = find(key);
    if (it == list_.end()) return false;
    erase(it);
    return true;
  }
  // Sets an entry's size (a value that grew); keeps the total in step.
  void resize(iterator it, std::size_t bytes) {
    bytes_ = bytes_ - it->bytes + bytes;
    it->bytes = bytes;
  }
  // Evicts from the least recently used end while over(*this) holds: entries keep(entry) spares are
  // stepped over, the others are removed and handed to evicted(Entry&&). Returns the number removed.
  template <class Over, class Keep, class Evicted>
  std::size_t evict(Over over, Keep keep, Evicted evicted) {
    std::size_t removed = 0;
    for (auto it = list_.end(); it != list_.begin() && over(*this);) {
      --it;
      if (keep(static_cast<const Entry&>(*it))) continue;
      bytes_ -= it->bytes;
      index_.erase(it->key);
      Entry e = std::move(*it);
      it = list_.erase(it);
      ++removed;
      evicted(std::move(e));
    }
    return removed;
  }
  template <class Over>
  std::size_t evict(Over over) {
    return evict(over, [](const Entry&) { return false; }, [](Entry&&) {});
  }
  void clear() {
    list_.clear();
    index_.clear();
    bytes_ = 0;
  }

private:
  std::list<Entry> list_;  // front = most recently used
  std::map<Key, iterator> index_;
  std::size_t bytes_ = 0;
};

}  // namespace radiant::api
