#pragma once
// Test support: the largest per-channel difference of two images (a failed expectation when their
// sizes or channel counts differ, and then infinity).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "renderer/Image.h"

namespace radiant::testing {

inline double maxAbsDifference(const Image& a, const Image& b) {
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  EXPECT_EQ(a.channels, b.channels);
  if (a.pixels.size() != b.pixels.size()) return INFINITY;
  double d = 0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i) d = std::max(d, double(std::fabs(a.pixels[i] - b.pixels[i])));
  return d;
}

}  // namespace radiant::testing
