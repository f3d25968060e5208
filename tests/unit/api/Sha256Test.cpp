#include <gtest/gtest.h>

#include "api/Sha256.h"

using radiant::api::sha256Hex;

// FIPS 180-4 / NIST example vectors.
TEST(Sha256, KnownVectors) {
  EXPECT_EQ(sha256Hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(sha256Hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(sha256Hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(sha256Hex(std::string(1000000, 'a')), "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

TEST(Sha256, IncrementalEqualsOneShotAcrossBlockBoundaries) {
  std::string data;
  for (int i = 0; i < 300; ++i) data.push_back(static_cast<char>(i * 7));
  for (std::size_t split : {0u, 1u, 55u, 56u, 63u, 64u, 65u, 128u, 299u}) {
    radiant::api::Sha256 s;
    s.update(std::string_view(data).substr(0, split));
    s.update(std::string_view(data).substr(split));
    EXPECT_EQ(s.finishHex(), sha256Hex(data)) << split;
  }
}

TEST(Sha256, SceneDigestForm) {
  EXPECT_EQ(radiant::api::sceneDigest("abc").substr(0, 7), "sha256:");
  EXPECT_TRUE(radiant::api::isSceneDigest(radiant::api::sceneDigest("abc")));
  EXPECT_FALSE(radiant::api::isSceneDigest("sha256:ABC"));
  EXPECT_FALSE(radiant::api::isSceneDigest("sha256:" + std::string(64, 'g')));
  EXPECT_FALSE(radiant::api::isSceneDigest("md5:" + std::string(64, 'a')));
}
