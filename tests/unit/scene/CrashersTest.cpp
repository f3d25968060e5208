// Every input that ever crashed radiantd, gave a 500 or exhausted its memory (tests/data/crashers,
// written by make_crashers.py; fuzzer finds are added there): each is refused with a 4xx-class
// error whose message and pointer are valid UTF-8, in the normal suite, without a fuzzer build.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "api/JsonLimits.h"
#include "api/Validate.h"
#include "renderer/scene/GltfLoader.h"

namespace fs = std::filesystem;

namespace {

const fs::path kCrashers = fs::path(RADIANT_SOURCE_DIR) / "tests/data/crashers";

std::vector<fs::path> filesIn(const std::string& sub) {
  std::vector<fs::path> out;
  for (const auto& f : fs::directory_iterator(kCrashers / sub))
    if (f.is_regular_file()) out.push_back(f.path());
  std::sort(out.begin(), out.end());
  return out;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), {});
}

}  // namespace

TEST(Crashers, EveryRequestIsRefusedWithA4xx) {
  const auto files = filesIn("requests");
  ASSERT_GE(files.size(), 10u);
  radiant::api::RequestLimits limits;
  limits.maxOutputBytes = 512u << 20;  // radiantd's default --max-frame-bytes
  for (const auto& f : files) {
    SCOPED_TRACE(f.filename().string());
    try {
      radiant::api::parseRenderRequest(std::string_view(slurp(f)), limits);
      ADD_FAILURE() << "accepted";
    } catch (const radiant::api::ApiError& e) {
      EXPECT_GE(e.status, 400);
      EXPECT_LT(e.status, 500);
      EXPECT_TRUE(radiant::api::isValidUtf8(e.detail()));
      EXPECT_TRUE(radiant::api::isValidUtf8(e.pointer));
      EXPECT_NO_THROW(nlohmann::json({{"detail", e.detail()}, {"pointer", e.pointer}}).dump());
    }
  }
}

TEST(Crashers, EveryGltfIsASceneError) {
  const auto files = filesIn("gltf");
  ASSERT_GE(files.size(), 18u);
  for (const auto& f : files) {
    SCOPED_TRACE(f.filename().string());
    try {
      radiant::loadSceneFromMemory(slurp(f));
      ADD_FAILURE() << "loaded";
    } catch (const radiant::SceneError& e) {
      EXPECT_TRUE(radiant::api::isValidUtf8(e.pointer));
      EXPECT_FALSE(std::string(e.what()).empty());
    }
  }
}
