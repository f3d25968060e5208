// cmake/Embed.cmake: shaders under shaders/ are compiled into the binary, byte for byte.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <string>

#include "embedded/radiant_shaders.h"

namespace {

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(Embed, NamesContainCommonConstants) {
  const auto& names = radiant::shaders::names();
  EXPECT_NE(std::find(names.begin(), names.end(), "common/constants.glsl"), names.end());
  EXPECT_TRUE(std::is_sorted(names.begin(), names.end()));
}

TEST(Embed, ContentsMatchTheSourceFileExactly) {
  for (const char* name : {"common/constants.glsl", "tests/broken.frag", "tests/fill.comp"}) {
    const std::string onDisk = readFile(std::string(RADIANT_SOURCE_DIR) + "/shaders/" + name);
    ASSERT_FALSE(onDisk.empty()) << name;
    EXPECT_EQ(std::string(radiant::shaders::find(name)), onDisk) << name;
  }
}

TEST(Embed, UnknownNameIsNull) {
  EXPECT_EQ(radiant::shaders::find("common/does_not_exist.glsl").data(), nullptr);
  EXPECT_EQ(radiant::shaders::find("").data(), nullptr);
}

}  // namespace
