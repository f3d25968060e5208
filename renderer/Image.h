#pragma once
// A CPU-side float image: what readback produces, what encoders and metrics consume.
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

}  // namespace radiant
