#include "server/ContentStore.h"

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <iostream>
#include <system_error>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "api/Sha256.h"
#include "api/Types.h"

namespace radiant::server {

namespace fs = std::filesystem;

std::string ContentStore::formatOf(const std::string& bytes) {
  auto starts = [&](std::string_view magic) { return bytes.size() >= magic.size() && bytes.compare(0, magic.size(), magic) == 0; };
  if (starts("glTF")) return "glb";
  if (starts(std::string_view("\x76\x2f\x31\x01", 4))) return "exr";
  if (starts("#?RADIANCE") || starts("#?RGBE")) return "hdr";
  if (starts("\x89PNG")) return "png";
  return "gltf";
}

ContentStore::ContentStore(fs::path cacheDir, std::size_t maxBytes, const std::string& kind) : maxBytes_(maxBytes) {
  if (cacheDir.empty()) return;
  dir_ = cacheDir / kind;
  fs::create_directories(dir_);
  struct Found {
    StoredBlobInfo info;
    fs::file_time_type mtime;
  };
  std::vector<Found> found;
  for (const auto& f : fs::directory_iterator(dir_)) {
    // A symlink could make the store serve (and evict: remove) a file outside the cache dir.
    if (f.is_symlink() || !f.is_regular_file()) {
      if (f.is_symlink())
        std::cerr << "{\"event\":\"cache_file_refused\",\"reason\":\"symlink\",\"file\":"
                  << nlohmann::json(f.path().string()).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) << "}\n";
      continue;
    }
    const std::string ext = f.path().extension().string();
    const std::string digest = "sha256:" + f.path().stem().string();
    // Each store holds its own formats: a glTF under images/ (or an image under scenes/) is not its file.
    const bool known = kind == "images" ? ext == ".exr" || ext == ".hdr" || ext == ".png" : ext == ".glb" || ext == ".gltf";
    if (!known || !api::isSceneDigest(digest)) {
      if (f.path().filename().string().rfind(".tmp-", 0) == 0) fs::remove(f.path());  // an interrupted write
      continue;
    }
    found.push_back({{digest, static_cast<std::size_t>(f.file_size()), ext.substr(1)}, f.last_write_time()});
  }
  std::sort(found.begin(), found.end(), [](const Found& a, const Found& b) { return a.mtime > b.mtime; });
  for (auto& f : found) lru_.put(f.info.digest, Entry{f.info, nullptr}, f.info.bytes, /*leastRecent=*/true);
  evictLocked("");
}

fs::path ContentStore::fileFor(const Entry& e) const {
  return dir_ / (e.info.digest.substr(7) + "." + e.info.format);
}

void ContentStore::touch(Lru::iterator it) {
  lru_.touch(it);
  if (!dir_.empty()) {
    std::error_code ec;  // best effort: the order survives a restart
    fs::last_write_time(fileFor(it->value), fs::file_time_type::clock::now(), ec);
  }
}

void ContentStore::evictLocked(const std::string& keep) {
  lru_.evict([&](const Lru& l) { return l.bytes() > maxBytes_; },
             [&](const Lru::Entry& e) { return e.key == keep; },
             [&](Lru::Entry&& e) {
               if (dir_.empty()) return;
               std::error_code ec;
               fs::remove(fileFor(e.value), ec);
             });
}

bool ContentStore::put(const std::string& digest, std::string bytes) {
  if (bytes.size() > maxBytes_)
    throw api::ApiError(413, "payload-too-large", "Payload too large",
                        "the scene is " + std::to_string(bytes.size()) + " bytes, the scene store holds " +
                            std::to_string(maxBytes_));
  std::lock_guard lock(mutex_);
  // Already there, unless its file (found at start-up, not yet verified) is refused: then stored anew.
  if (auto it = lru_.find(digest);
      it != lru_.end() && (it->value.bytes || it->value.verified || readVerifiedLocked(it))) {
    touch(it);
    return false;
  }
  Entry e{{digest, bytes.size(), formatOf(bytes)}, nullptr};
  if (!dir_.empty()) {
    // Write then rename, so a crash never leaves a truncated file under a digest name.
    const fs::path tmp = dir_ / (".tmp-" + digest.substr(7));
    {
      std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
      out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
      if (!out) throw std::runtime_error("ContentStore::put(): cannot write " + tmp.string());
    }
    fs::rename(tmp, fileFor(e));
  } else {
    e.bytes = std::make_shared<const std::string>(std::move(bytes));
  }
  e.verified = true;
  const std::size_t size = e.info.bytes;
  lru_.put(digest, std::move(e), size);
  evictLocked(digest);
  return true;
}

bool ContentStore::contains(const std::string& digest) {
  std::lock_guard lock(mutex_);
  auto it = lru_.find(digest);
  if (it == lru_.end()) return false;
  // A file found at start-up is hashed on its first use, a HEAD too: a truncated or swapped file is a
  // miss, so a client uploads the scene again instead of rendering a 404.
  if (!it->value.bytes && !it->value.verified && !readVerifiedLocked(it)) return false;
  touch(it);
  return true;
}

std::optional<std::string> ContentStore::get(const std::string& digest) {
  std::lock_guard lock(mutex_);
  auto it = lru_.find(digest);
  if (it == lru_.end()) return std::nullopt;
  if (it->value.bytes) {
    touch(it);
    return *it->value.bytes;
  }
  std::optional<std::string> bytes = readVerifiedLocked(it);
  if (bytes) touch(it);
  return bytes;
}

std::optional<std::string> ContentStore::readVerifiedLocked(Lru::iterator it) {
  const Entry& entry = it->value;
  const std::string path = fileFor(entry).string();
  const std::string digest = entry.info.digest;
  std::optional<std::string> bytes;
  const char* reason = "unreadable";
  bool regular = false;
  // O_NOFOLLOW: a symlink put in place after start-up is not followed. O_NONBLOCK: opening a FIFO
  // returns at once (a blocking open would wait for a writer, holding the store's lock).
  if (const int fd = ::open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC); fd >= 0) {
    struct stat st {};
    if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
      reason = "not a regular file";
    } else if (static_cast<std::uint64_t>(st.st_size) != entry.info.bytes) {
      regular = true;
      reason = "size changed";
    } else {
      regular = true;
      std::string data;
      data.reserve(entry.info.bytes);
      char buf[1 << 16];
      ssize_t n;
      // At most the recorded size (+1 to see growth during the read).
      while (data.size() <= entry.info.bytes && (n = ::read(fd, buf, sizeof buf)) > 0) data.append(buf, std::size_t(n));
      if (data.size() != entry.info.bytes || api::sceneDigest(data) != digest) reason = "digest mismatch";
      else if (formatOf(data) != entry.info.format) reason = "format mismatch";  // e.g. JSON named <its digest>.png
      else bytes = std::move(data);
    }
    ::close(fd);
  }
  if (bytes) {
    it->value.verified = true;
    return bytes;
  }
  // Anything else (edited, truncated, grown, swapped, replaced by a FIFO) is forgotten rather than
  // served or decoded; a regular file is removed.
  std::cerr << "{\"event\":\"cache_file_refused\",\"reason\":\"" << reason << "\",\"digest\":\"" << digest << "\"}\n";
  if (regular) {
    std::error_code ec;
    fs::remove(path, ec);
  }
  lru_.erase(it);
  return std::nullopt;
}

std::vector<StoredBlobInfo> ContentStore::list() {
  std::lock_guard lock(mutex_);
  std::vector<StoredBlobInfo> out;
  for (const auto& e : lru_) out.push_back(e.value.info);
  return out;
}

std::size_t ContentStore::totalBytes() {
  std::lock_guard lock(mutex_);
  return lru_.bytes();
}

}  // namespace radiant::server
