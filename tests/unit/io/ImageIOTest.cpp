// Image encoding without GL: a half-float EXR holds only |v| <= 65504, and OpenImageIO writes a float
// beyond that as Inf. radiantd's default EXR is half float and radiance within the API's ranges exceeds
// it (ambient 1e6, a 1e15 light: issue 30), so encodeExr writes the largest finite half and counts.
#include <cfloat>
#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>

#include <gtest/gtest.h>

#include "renderer/io/ImageIO.h"
#include "renderer/io/MemoryReader.h"

namespace radiant {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// decodeImage refuses `bytes` with a message holding `fragment`.
void expectRefused(const std::string& bytes, const std::string& fragment) {
  try {
    io::decodeImage(bytes, "beauty");
    ADD_FAILURE() << "accepted; expected a refusal naming: " << fragment;
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

// A file of tests/data/crashers/images (fuzzer finds, kept as regression inputs).
std::string crasherImage(const std::string& name) {
  std::ifstream in(std::string(RADIANT_SOURCE_DIR) + "/tests/data/crashers/images/" + name, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

Image row(const std::string& aov, int channels, const std::vector<float>& values) {
  Image img = Image::make(aov, int(values.size()) / channels, 1, channels);
  img.pixels = values;
  return img;
}

TEST(ImageIO, HalfExrWritesValuesBeyondItsRangeAsTheLargestFiniteHalfAndCountsThem) {
  // 12 beauty values: 6 beyond +-65504 (1e6, -1e6, FLT_MAX, 65505, -70000, +Inf), the rest kept.
  const Image beauty = row("beauty", 3, {1e6f, -1e6f, FLT_MAX, 1.5f, 65504.f, -65504.f, 65505.f, -70000.f, kInf, 0.f, 1e-3f, 2.f});
  const Image ao = row("ao", 1, {FLT_MAX, 3.f, -FLT_MAX, 0.25f});
  EXPECT_EQ(io::valuesBeyondHalf(beauty), 6u);
  EXPECT_EQ(io::valuesBeyondHalf(ao), 2u);
  std::vector<std::size_t> clamped;
  const std::string exr = io::encodeExr({beauty, ao}, true, &clamped);
  EXPECT_EQ(clamped, (std::vector<std::size_t>{6, 2}));

  const Image b = io::decodeImage(exr, "beauty");
  ASSERT_EQ(b.pixels.size(), 12u);
  const std::vector<float> want = {65504.f, -65504.f, 65504.f, 1.5f, 65504.f, -65504.f,
                                   65504.f, -65504.f, 65504.f, 0.f, 0.f, 2.f};
  for (std::size_t i = 0; i < want.size(); ++i) {
    EXPECT_TRUE(std::isfinite(b.pixels[i])) << i << ": " << b.pixels[i];
    if (i == 10) EXPECT_NEAR(b.pixels[i], 1e-3f, 1e-6f);  // a half's precision at 1e-3
    else EXPECT_EQ(b.pixels[i], want[i]) << i;
  }
  const Image d = io::decodeImage(exr, "ao");
  EXPECT_EQ(d.pixels, (std::vector<float>{65504.f, 3.f, -65504.f, 0.25f}));
}

TEST(ImageIO, FloatExrKeepsEveryValueAndClampsNothing) {
  const Image beauty = row("beauty", 3, {1e6f, -1e6f, FLT_MAX, 1.5f, 65505.f, 1e15f});
  std::vector<std::size_t> clamped = {99};
  const std::string exr = io::encodeExr({beauty}, false, &clamped);
  EXPECT_EQ(clamped, (std::vector<std::size_t>{0}));
  EXPECT_EQ(io::decodeImage(exr, "beauty").pixels, beauty.pixels);
}

TEST(ImageIO, HalfExrWithinRangeIsUnchangedAndCountsNothing) {
  const Image beauty = row("beauty", 3, {0.f, 0.5f, 1.f, 65504.f, -2.f, 1024.f});
  std::vector<std::size_t> clamped;
  const std::string exr = io::encodeExr({beauty}, true, &clamped);
  EXPECT_EQ(clamped, (std::vector<std::size_t>{0}));
  EXPECT_EQ(io::decodeImage(exr, "beauty").pixels, beauty.pixels);  // each exactly representable
}

// The render-fidelity metric scores a PNG's codes as stored: straight alpha, no transfer decoded.
TEST(ImageIO, Rgba8PngRoundTripKeepsStraightCodesAndAnRgbFileReadsOpaque) {
  ImageRgba8 img = ImageRgba8::make(3, 1);
  img.pixels = {255, 0, 0, 255, 200, 100, 50, 128, 7, 8, 9, 0};
  const ImageRgba8 back = io::decodePngRgba8(io::encodePngRgba8(img));
  EXPECT_EQ(back.width, 3);
  EXPECT_EQ(back.pixels, img.pixels);  // 200, 100, 50 at alpha 128 is not premultiplied on reading
  const ImageRgba8 rgb = io::decodePngRgba8(io::encodePngRgba8(img, false));
  EXPECT_EQ(rgb.pixels, (std::vector<std::uint8_t>{255, 0, 0, 255, 200, 100, 50, 255, 7, 8, 9, 255}));
  // A transparent frame's PNG (encodePng with coverage): colour = sRGB(beauty / alpha), alpha = coverage.
  Image beauty = row("beauty", 3, {0.5f, 0.5f, 0.5f});  // premultiplied by coverage 0.5: linear 1 = code 255
  const Image alpha = row("alpha", 1, {0.5f});
  io::PngOptions o;
  o.alpha = &alpha;
  const ImageRgba8 frame = io::decodePngRgba8(io::encodePng(beauty, o));
  EXPECT_EQ(frame.pixels, (std::vector<std::uint8_t>{255, 255, 255, 128}));
  EXPECT_THROW(io::decodePngRgba8("not a png"), std::runtime_error);
}

}  // namespace
}  // namespace radiant

namespace radiant {
namespace {

// Issue 30: an uploaded EXR whose header declares an attribute larger than the file is refused before
// OpenEXR allocates it (a 508-byte upload declaring a 1.6 GB "Software" string took 2 GB,
// tests/fuzz/image_fuzzer.cpp); a header that does not end inside the file likewise. Our own EXRs pass.
TEST(ImageIO, ExrHeadersDeclaringMoreThanTheFileHoldsAreRefusedBeforeTheyAreRead) {
  Image beauty = Image::make("beauty", 4, 2, 3);
  for (std::size_t i = 0; i < beauty.pixels.size(); ++i) beauty.pixels[i] = float(i);
  const std::string exr = io::encodeExr({beauty}, false);
  EXPECT_EQ(io::decodeImage(exr, "beauty").pixels, beauty.pixels);
  // The first attribute's size field follows its name and type.
  const std::size_t name = exr.find('\0', 8), type = exr.find('\0', name + 1);
  std::string huge = exr;
  huge[type + 1] = '\x53', huge[type + 2] = '\x00', huge[type + 3] = '\x00', huge[type + 4] = '\x63';  // 1.66e9
  expectRefused(huge, "more than the file holds");
  try {
    io::decodeImage(exr.substr(0, type + 3), "beauty");
    ADD_FAILURE() << "accepted a truncated header";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("invalid"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace radiant

namespace radiant {
namespace {

// The same for a PNG chunk declaring more than the file holds (a 304-byte tEXt of 1.7 GB took 2 GB,
// tests/data/crashers/images/png_8x4_takes_2gb.png).
TEST(ImageIO, PngChunksDeclaringMoreThanTheFileHoldsAreRefusedBeforeTheyAreRead) {
  Image beauty = Image::make("beauty", 4, 2, 3);
  for (std::size_t i = 0; i < beauty.pixels.size(); ++i) beauty.pixels[i] = 0.125f * float(i % 8);
  const std::string png = io::encodePng(beauty, 0.f);
  EXPECT_EQ(io::decodeImage(png, "beauty").width, 4);
  std::string huge = png;
  huge[8] = '\x67', huge[9] = '\x00', huge[10] = '\x00', huge[11] = '\x0d';  // IHDR's length: 1.7e9
  expectRefused(huge, "more than the file holds");
}

}  // namespace
}  // namespace radiant

namespace radiant {
namespace {

// Uploaded images are read through io::MemoryReader, whose reads never leave the bytes: OpenImageIO
// 2.4's IOMemReader copied from any offset, and an EXR whose line offset table pointed before the
// file made OpenEXR read before the upload's buffer (tests/data/crashers/images/exr_offset_before_the_file.exr,
// found by the image fuzzer; its ASan run keeps it as a regression test).
TEST(ImageIO, MemoryReadsNeverLeaveTheBytes) {
  const std::string bytes = "0123456789";
  io::MemoryReader r(bytes);
  char buf[16] = {};
  EXPECT_EQ(r.pread(buf, 4, -1), 0u);
  EXPECT_EQ(r.pread(buf, 4, 10), 0u);
  EXPECT_EQ(r.pread(buf, 4, int64_t(1) << 62), 0u);
  EXPECT_EQ(r.pread(buf, 16, 7), 3u);
  EXPECT_EQ(std::string(buf, 3), "789");
  EXPECT_FALSE(r.seek(-1));
  EXPECT_TRUE(r.seek(8));
  EXPECT_EQ(r.read(buf, 16), 2u);
  EXPECT_EQ(std::string(buf, 2), "89");
  EXPECT_EQ(r.read(buf, 16), 0u);
  EXPECT_EQ(r.size(), 10u);
  // The fuzzer's file is refused (its offset table points outside it), not read around.
  const std::string exr = crasherImage("exr_offset_before_the_file.exr");
  ASSERT_GT(exr.size(), 100u);
  EXPECT_THROW(io::decodeImage(exr, "beauty"), std::runtime_error);
}

// An EXR channel list is read by OpenEXR until its terminator, whatever its attribute's size: an
// 884-byte upload whose last channel name ran one byte past the attribute took 1.5 GB and 8 s to open
// (image fuzzer). The list must end exactly at its attribute's end, with valid pixel types and
// sampling, and a header must name its channels and data window.
TEST(ImageIO, ExrChannelListsMustEndInsideTheirAttribute) {
  const std::string bad = crasherImage("exr_channel_list_past_its_attribute_takes_1_5gb.exr");
  ASSERT_GT(bad.size(), 800u);
  expectRefused(bad, "channel list");
  // A valid file passes, and a pixel type out of range is refused.
  Image beauty = Image::make("beauty", 4, 2, 3);
  const std::string exr = io::encodeExr({beauty}, false);
  EXPECT_NO_THROW(io::decodeImage(exr, "beauty"));
  const std::size_t list = exr.find("chlist");
  ASSERT_NE(list, std::string::npos);
  std::string typed = exr;
  const std::size_t firstType = typed.find('\0', list + 7 + 4) + 1;  // after the first channel's name
  typed[firstType] = '\x07';
  expectRefused(typed, "pixel type 7");
}

}  // namespace
}  // namespace radiant

namespace radiant {
namespace {

// OpenImageIO reads up to 256 scanlines into its own buffer whatever the image's height: a 95-byte
// Radiance HDR declaring one row of 2,222,222 pixels made it allocate 6.8 GB (image fuzzer). The decode
// budget charges that buffer from the header, so the upload is refused before the read.
TEST(ImageIO, OneVeryWideRowIsChargedForTheReadersBuffer) {
  const std::string wide = crasherImage("hdr_one_wide_row_takes_6_8gb.hdr");
  ASSERT_EQ(wide.size(), 95u);
  try {
    io::decodeImage(wide, "beauty", 512u << 20);
    ADD_FAILURE() << "accepted";
  } catch (const io::DecodeLimitExceeded& e) {
    EXPECT_NE(std::string(e.what()).find("--max-decode-bytes"), std::string::npos) << e.what();
  } catch (const std::runtime_error& e) {
    ADD_FAILURE() << "refused, but not by the decode budget: " << e.what();
  }
  // A 64 x 1 row is charged 64 x 256 x 3 x 4 bytes for the buffer, and decodes within a budget of that.
  Image row = Image::make("beauty", 64, 1, 3);
  const std::string exr = io::encodeExr({row}, false);
  EXPECT_NO_THROW(io::decodeImage(exr, "beauty", 64 * 256 * 3 * 4 + 64 * 6 * 4 + 64 * 3 * 4));
  EXPECT_THROW(io::decodeImage(exr, "beauty", 64 * 256 * 3 * 4), io::DecodeLimitExceeded);
}

}  // namespace
}  // namespace radiant

namespace radiant {
namespace {

// An EXR's declared size is charged from its header before OpenEXR reads it, as HDR and PNG are: a
// 100000 x 100000 header was refused as "Unexpected end of file" (issue 30's 4xx wording).
TEST(ImageIO, ExrDeclaredSizeIsChargedFromTheHeader) {
  Image beauty = Image::make("beauty", 4, 2, 3);
  std::string exr = io::encodeExr({beauty}, false);
  const std::size_t at = exr.find(std::string("dataWindow\0box2i\0", 17));
  ASSERT_NE(at, std::string::npos);
  const std::size_t box = at + 17 + 4;  // xMin, yMin, xMax, yMax
  for (std::size_t k : {box + 8, box + 12}) {
    const std::uint32_t v = 99999;
    for (int i = 0; i < 4; ++i) exr[k + i] = char((v >> (8 * i)) & 255);
  }
  try {
    io::decodeImage(exr, "beauty", 512u << 20);
    ADD_FAILURE() << "accepted";
  } catch (const io::DecodeLimitExceeded& e) {
    EXPECT_NE(std::string(e.what()).find("100000x100000"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("--max-decode-bytes"), std::string::npos) << e.what();
  } catch (const std::runtime_error& e) {
    ADD_FAILURE() << "refused, but not by the decode budget: " << e.what();
  }
}

}  // namespace
}  // namespace radiant

namespace radiant {
namespace {

// The daemon's shared decode memory (radiantd --decode-memory-bytes): decodeImage reserves, before reading
// pixels, what the header says the decode allocates (the float channels, the RGB copy and OpenImageIO's
// buffer of up to 256 scanlines), and what the reservation throws passes through.
TEST(ImageIO, DecodeReservesTheHeadersBytesFirstAndItsRefusalPassesThrough) {
  const Image beauty = row("beauty", 3, {1.f, 2.f, 3.f, 4.f, 5.f, 6.f});  // 2 x 1, 3 channels
  const std::string exr = io::encodeExr({beauty}, false, nullptr);
  std::vector<std::size_t> reserved;
  const Image b = io::decodeImage(exr, "beauty", 0, [&](std::size_t n) { reserved.push_back(n); });
  EXPECT_EQ(b.pixels, beauty.pixels);
  // 2 pixels x 3 channels x 4 bytes + 2 x 12 (the RGB copy) + 2 x 256 x 3 x 4 (the read buffer).
  EXPECT_EQ(reserved, (std::vector<std::size_t>{24 + 24 + 6144}));
  struct Busy : std::runtime_error {
    using std::runtime_error::runtime_error;
  };
  EXPECT_THROW(io::decodeImage(exr, "beauty", 0, [](std::size_t) { throw Busy("busy"); }), Busy);
}

}  // namespace
}  // namespace radiant
