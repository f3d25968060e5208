#include <gtest/gtest.h>

#include "api/Types.h"

TEST(Types, FrameStatsJson) {
  radiant::api::FrameStats s;
  s.passes.push_back({"direct", 1.5, 0.25, {{"lights", 2}}, {}, 0.125});
  s.skipped["shadow_maps"] = "the scene has no punctual lights";
  s.cache.push_back({"shadow_map:light0", true});
  s.renderMs = 12;
  s.encodeMs = 3;
  s.triangles = 36;
  s.lights = 1;
  s.device["renderer"] = "llvmpipe";
  nlohmann::json j = s;
  EXPECT_EQ(j["passes"][0]["name"], "direct");
  EXPECT_DOUBLE_EQ(j["passes"][0]["gpu_ms"].get<double>(), 1.5);
  EXPECT_DOUBLE_EQ(j["passes"][0]["cpu_ms"].get<double>(), 0.25);
  EXPECT_DOUBLE_EQ(j["passes"][0]["prepare_ms"].get<double>(), 0.125);
  EXPECT_EQ(j["passes"][0]["counters"]["lights"], 2);
  EXPECT_EQ(j["skipped"]["shadow_maps"], "the scene has no punctual lights");
  EXPECT_EQ(j["cache"][0]["what"], "shadow_map:light0");
  EXPECT_EQ(j["cache"][0]["hit"], true);
  EXPECT_EQ(j["render_ms"], 12);
  EXPECT_EQ(j["encode_ms"], 3);
  EXPECT_EQ(j["triangles"], 36);
  EXPECT_EQ(j["lights"], 1);
  EXPECT_EQ(j["device"]["renderer"], "llvmpipe");
  EXPECT_TRUE(j["metrics"].is_null());
}
