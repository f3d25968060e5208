#include <gtest/gtest.h>

#include "api/Base64.h"

using radiant::api::base64Decode;
using radiant::api::base64Encode;

// RFC 4648 §10 test vectors, both ways.
TEST(Base64, Rfc4648Vectors) {
  const std::pair<const char*, const char*> vectors[] = {{"", ""},         {"f", "Zg=="},         {"fo", "Zm8="},
                                                         {"foo", "Zm9v"},  {"foob", "Zm9vYg=="},  {"fooba", "Zm9vYmE="},
                                                         {"foobar", "Zm9vYmFy"}};
  for (const auto& [plain, encoded] : vectors) {
    EXPECT_EQ(base64Encode(plain), encoded);
    EXPECT_EQ(base64Decode(encoded).value(), plain);
  }
}

TEST(Base64, EveryByteRoundTripsAndLineBreaksAreSkipped) {
  std::string all;
  for (int i = 0; i < 256; ++i) all.push_back(static_cast<char>(i));
  const std::string encoded = base64Encode(all);
  EXPECT_EQ(encoded.size(), 344u);  // 4 * ceil(256 / 3)
  EXPECT_EQ(base64Decode(encoded).value(), all);
  EXPECT_EQ(base64Decode(encoded.substr(0, 76) + "\r\n" + encoded.substr(76)).value(), all);
}

TEST(Base64, ACharacterOutsideTheAlphabetIsNamedByItsOffset) {
  std::size_t bad = 0;
  EXPECT_FALSE(base64Decode("Zm9v*mFy", &bad).has_value());
  EXPECT_EQ(bad, 4u);
  EXPECT_FALSE(base64Decode("Zm9v YmFy", &bad).has_value());
  EXPECT_EQ(bad, 4u);
}
