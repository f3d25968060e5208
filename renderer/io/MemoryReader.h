#pragma once
// An OpenImageIO read proxy over bytes in memory whose reads never leave them. OpenImageIO 2.4's own
// IOMemReader copies from any offset it is given: an uploaded EXR whose line offset table points
// before the file made OpenEXR read before the upload's buffer (a heap over-read found by
// tests/fuzz/image_fuzzer.cpp, 2026-12-04; tests/data/crashers/images/exr_offset_before_the_file.exr).
// Here a read at a negative offset, or past the end, returns 0 bytes (the decoder then reports a read
// error), and one that reaches past the end returns what is left.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string_view>

#include <OpenImageIO/filesystem.h>

namespace radiant::io {

class MemoryReader final : public OIIO_NAMESPACE::Filesystem::IOProxy {
 public:
  explicit MemoryReader(std::string_view bytes) : IOProxy("", Read), bytes_(bytes) {}
  const char* proxytype() const override { return "memreader"; }
  bool seek(int64_t offset) override {
    if (offset < 0) return false;
    m_pos = offset;
    return true;
  }
  size_t read(void* buf, size_t size) override {
    const size_t n = pread(buf, size, m_pos);
    m_pos += int64_t(n);
    return n;
  }
  size_t pread(void* buf, size_t size, int64_t offset) override {
    if (offset < 0 || uint64_t(offset) >= bytes_.size() || size == 0) return 0;
    const size_t n = std::min(size, bytes_.size() - size_t(offset));
    std::memcpy(buf, bytes_.data() + offset, n);
    return n;
  }
  size_t size() const override { return bytes_.size(); }

 private:
  std::string_view bytes_;
};

}  // namespace radiant::io
