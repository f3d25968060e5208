#pragma once
// SHA-256 (FIPS 180-4). Used for content digests: Scene::digest and the cache keys of derived data.

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace radiant {

// Incremental hasher: update() any number of times, then finish() once.
class Sha256 {
public:
  Sha256();
  void update(const void* data, std::size_t size);
  void update(std::string_view bytes) { update(bytes.data(), bytes.size()); }
  std::array<std::uint8_t, 32> finish();
  std::string finishHex();

private:
  void compress(const std::uint8_t* block);
  std::array<std::uint32_t, 8> h_;
  std::array<std::uint8_t, 64> block_{};
  std::size_t blockFill_ = 0;
  std::uint64_t totalBytes_ = 0;
  bool finished_ = false;
};

// Lower-case hex SHA-256 of `bytes` (64 characters).
std::string sha256Hex(std::string_view bytes);

}  // namespace radiant
