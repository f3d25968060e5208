#pragma once
// SHA-256 (FIPS 180-4), used for content-addressed scenes ("sha256:<64 hex>"). The client computes
// the digest locally to skip uploads the server already has, so this lives in api/, with no GL.
#include <array>
#include <cstdint>
#include <string>
#include <string_view>

namespace radiant::api {

class Sha256 {
public:
  Sha256();
  void update(const void* data, std::size_t size);
  void update(std::string_view s) { update(s.data(), s.size()); }
  std::array<std::uint8_t, 32> finish();  // the object must not be used afterwards
  std::string finishHex();                 // finish() as 64 lowercase hex digits

private:
  void block(const std::uint8_t* p);
  std::uint32_t h_[8];
  std::uint8_t buf_[64];
  std::size_t bufLen_ = 0;
  std::uint64_t total_ = 0;
};

std::string sha256Hex(std::string_view bytes);        // 64 lowercase hex digits
std::string sceneDigest(std::string_view bytes);      // "sha256:" + sha256Hex
bool isSceneDigest(std::string_view s);               // "sha256:" followed by 64 lowercase hex

}  // namespace radiant::api
