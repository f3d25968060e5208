#pragma once
// Content-addressed store: bytes keyed by "sha256:<hex>" of exactly those bytes. The daemon keeps
// one for scenes (glTF/GLB) and one for comparison images (EXR/HDR/PNG).
// Bounded in bytes with least-recently-used eviction. With a cache directory the bytes live in
// <dir>/<kind>/<hex>.<format> (written atomically, mtime = last use) and survive restarts;
// without one they live in memory. Thread-safe.
//
// A cache file is read only when it is still the regular file of the size the store recorded (opened
// without following symlinks and without blocking, so a FIFO or device planted under a digest's name
// neither blocks the store nor is read; a file grown to any size is refused before a byte is read), and
// served only when its bytes hash to its name. A file found at start-up is verified on its first use,
// HEAD (contains) included; a refused file is a miss: forgotten, and removed when it is a regular file.

#include <cstddef>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "api/Lru.h"

namespace radiant::server {

struct StoredBlobInfo {
  std::string digest;
  std::size_t bytes = 0;
  std::string format;  // file extension from the magic bytes: glb | gltf | exr | hdr | png
};

class ContentStore {
public:
  // kind: the subdirectory of cacheDir ("scenes", "images").
  ContentStore(std::filesystem::path cacheDir, std::size_t maxBytes, const std::string& kind = "scenes");
  // Stores `bytes` under its digest; returns false when it was already there (idempotent).
  // Throws api::ApiError 413 when the scene alone exceeds the store.
  bool put(const std::string& digest, std::string bytes);
  bool contains(const std::string& digest);  // counts as a use
  std::optional<std::string> get(const std::string& digest);
  std::vector<StoredBlobInfo> list();  // most recently used first
  std::size_t totalBytes();
  // From the magic bytes: glb, exr, hdr, png; anything else is taken for glTF JSON ("gltf").
  static std::string formatOf(const std::string& bytes);

private:
  struct Entry {
    StoredBlobInfo info;
    std::shared_ptr<const std::string> bytes;  // in memory (no cache dir)
    bool verified = false;                     // its file was written or hashed by this process
  };
  using Lru = api::Lru<std::string, Entry>;  // by digest, each entry's size its info.bytes
  std::filesystem::path fileFor(const Entry& e) const;
  void touch(Lru::iterator it);
  void evictLocked(const std::string& keep);
  // The entry's file, checked as above; nullopt (and the entry forgotten) when it is refused.
  std::optional<std::string> readVerifiedLocked(Lru::iterator it);

  std::filesystem::path dir_;  // "" = memory only
  std::size_t maxBytes_;
  std::mutex mutex_;
  Lru lru_;
};

}  // namespace radiant::server
