#pragma once
// A CPU-side float image: what readback produces, what encoders and metrics consume.
#include <cstdint>
#include <string>
#include <vector>

namespace radiant {

struct Image {
  std::string aov;  // "beauty", "albedo", "normal", "depth", "direct", ...
  int width = 0, height = 0, channels = 0;
  std::vector<float> pixels;  // row-major, row 0 is the TOP row, channels interleaved
  float* at(int x, int y) { return &pixels[(static_cast<size_t>(y) * width + x) * channels]; }
  const float* at(int x, int y) const { return &pixels[(static_cast<size_t>(y) * width + x) * channels]; }
  static Image make(std::string aov, int w, int h, int c) {
    Image i; i.aov = std::move(aov); i.width = w; i.height = h; i.channels = c;
    i.pixels.assign(static_cast<size_t>(w) * h * c, 0.f);
    return i;
  }
};

// An 8-bit RGBA image as a PNG stores it: sRGB-encoded codes, straight (unassociated) alpha, row 0 at
// the top. An RGB file reads with alpha 255. What the render-fidelity metric scores (metrics/Metrics.h).
struct ImageRgba8 {
  int width = 0, height = 0;
  std::vector<std::uint8_t> pixels;  // width x height x 4
  std::uint8_t* at(int x, int y) { return &pixels[(static_cast<size_t>(y) * width + x) * 4]; }
  const std::uint8_t* at(int x, int y) const { return &pixels[(static_cast<size_t>(y) * width + x) * 4]; }
  static ImageRgba8 make(int w, int h) {
    ImageRgba8 i; i.width = w; i.height = h;
    i.pixels.assign(static_cast<size_t>(w) * h * 4, 0);
    return i;
  }
};

}  // namespace radiant
