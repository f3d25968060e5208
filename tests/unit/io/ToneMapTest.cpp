// The view transforms (renderer/io/ToneMap.h) against values computed by hand from the published
// formulas, and the PNG writer that applies them (renderer/io/ImageIO.h, encodePng).
//
// For a grey input g every matrix of these operators keeps grey (ACES: the rows of its input and
// output matrices sum to 1.00000 and 0.99999; AgX: the Rec.2020 and inset/outset rows sum to 1 within
// 1e-4), so grey values reduce to the operators' curves:
//   ACES(g)    = f(g / 0.6),  f(x) = (x (x + 0.0245786) - 0.000090537) / (x (0.983729 x + 0.4329510) + 0.238081)
//   Neutral(g) = g - 0.04 for 0.08 <= g < 0.8, g - (g - 6.25 g^2) = 6.25 g^2 below 0.08, and above 0.8
//                1 - 0.24^2 / (g - 0.04 + 0.24 - 0.76) (the grey desaturation mixes grey with grey)
//   AgX(g)     = max(p((log2 g + 12.47393) / 16.499999), 0)^2.2, p the 6th-order contrast polynomial.
#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <limits>
#include <vector>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include "renderer/io/ImageIO.h"
#include "renderer/io/ToneMap.h"

namespace radiant::io {
namespace {

using api::ToneMap;
constexpr ToneMap kAll[] = {ToneMap::Standard, ToneMap::Aces, ToneMap::KhronosPbrNeutral, ToneMap::Agx};

glm::vec3 grey(float g) { return glm::vec3(g); }

double acesCurve(double x) {
  return (x * (x + 0.0245786) - 0.000090537) / (x * (0.983729 * x + 0.4329510) + 0.238081);
}

TEST(ToneMap, EveryOperatorMapsZeroToZero) {
  for (ToneMap op : kAll) {
    SCOPED_TRACE(api::toString(op));
    EXPECT_EQ(toneMap(op, glm::vec3(0.f), 0.f), glm::vec3(0.f));
    EXPECT_EQ(toneMap(op, glm::vec3(0.f), 32.f), glm::vec3(0.f));  // whatever the exposure
  }
}

TEST(ToneMap, NeverNanOrInfAndAlwaysInUnitRange) {
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  const std::vector<glm::vec3> inputs = {{inf, inf, inf},    {-inf, 0.f, 1.f}, {nan, nan, nan},    {nan, 1.f, 2.f},
                                         {FLT_MAX, 0.f, 0.f}, {FLT_MAX, FLT_MAX, FLT_MAX},            {-1e30f, 1.f, 0.5f},
                                         {-1.f, -1.f, -1.f}, {1e-30f, 0.f, 0.f}, {1e20f, 1e-20f, 0.f}};
  for (ToneMap op : kAll)
    for (const glm::vec3& in : inputs)
      for (float ev : {-32.f, 0.f, 32.f}) {
        const glm::vec3 out = toneMap(op, in, ev);
        for (int c = 0; c < 3; ++c) {
          EXPECT_TRUE(std::isfinite(out[c])) << api::toString(op) << " at (" << in.x << ", " << in.y << ", " << in.z << ")";
          EXPECT_GE(out[c], 0.f) << api::toString(op);
          EXPECT_LE(out[c], 1.f) << api::toString(op);
        }
      }
  // NaN counts as 0, negative radiance as 0 and +Inf as the largest float: white under every operator
  // but AgX, whose curve ends at 0.997.
  for (ToneMap op : kAll) {
    EXPECT_EQ(toneMap(op, grey(std::numeric_limits<float>::quiet_NaN()), 0.f), glm::vec3(0.f)) << api::toString(op);
    EXPECT_EQ(toneMap(op, grey(-5.f), 0.f), glm::vec3(0.f)) << api::toString(op);
    EXPECT_EQ(toneMap(op, grey(inf), 0.f), toneMap(op, grey(FLT_MAX), 0.f)) << api::toString(op);
  }
}

TEST(ToneMap, MonotoneOnGreyAndPerChannel) {
  for (ToneMap op : kAll) {
    SCOPED_TRACE(api::toString(op));
    glm::vec3 previous = toneMap(op, grey(0.f), 0.f);
    glm::vec3 previousRed = toneMap(op, glm::vec3(0.f, 0.2f, 0.1f), 0.f);
    for (int i = 1; i <= 4000; ++i) {
      const float g = std::pow(10.f, -4.f + 7.f * i / 4000.f);  // 1e-4 .. 1e3
      const glm::vec3 out = toneMap(op, grey(g), 0.f);
      for (int c = 0; c < 3; ++c) ASSERT_GE(out[c], previous[c]) << "grey " << g;
      previous = out;
      // One channel rising: its own output never falls. Not AgX's property: its outset matrix's negative
      // off-diagonals take a little from a saturated channel as the others rise (three.js's own output
      // falls from 1 to 0.99998 for red near 130 here), so AgX is monotone on grey only.
      const glm::vec3 red = toneMap(op, glm::vec3(g, 0.2f, 0.1f), 0.f);
      if (op != ToneMap::Agx) { ASSERT_GE(red.r, previousRed.r) << "red " << g; }
      previousRed = red;
    }
  }
}

TEST(ToneMap, ExposureScalesTheInputBy2ToTheEv) {
  for (ToneMap op : kAll) {
    SCOPED_TRACE(api::toString(op));
    const glm::vec3 c(0.3f, 0.15f, 0.05f);
    const glm::vec3 a = toneMap(op, c, 1.f), b = toneMap(op, 2.f * c, 0.f);
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(a[i], b[i], 1e-6f);
  }
}

TEST(ToneMap, StandardIsTheClamp) {
  EXPECT_EQ(toneMap(ToneMap::Standard, glm::vec3(0.25f, 1.5f, -2.f), 0.f), glm::vec3(0.25f, 1.f, 0.f));
  EXPECT_EQ(toneMap(ToneMap::Standard, glm::vec3(0.25f, 0.5f, 0.125f), 1.f), glm::vec3(0.5f, 1.f, 0.25f));
}

TEST(ToneMap, AcesMatchesTheRrtOdtFitOnGrey) {
  // Middle grey 0.18: x = 0.3, f = (0.3 * 0.3245786 - 0.000090537) / (0.3 * 0.7280697 + 0.238081)
  // = 0.0972830 / 0.4565019 = 0.213105 (display-linear; sRGB 0.50).
  EXPECT_NEAR(toneMap(ToneMap::Aces, grey(0.18f), 0.f).g, 0.213105, 2e-6);
  // 0.6: x = 1, f = 1.0244881 / 1.654761 = 0.619115.
  EXPECT_NEAR(toneMap(ToneMap::Aces, grey(0.6f), 0.f).g, 0.619115, 2e-6);
  // 1: x = 1.6667, f = 0.763397; 2.5 (the Cornell box's mean radiance): x = 4.1667, f = 0.913327, not clipped.
  EXPECT_NEAR(toneMap(ToneMap::Aces, grey(1.f), 0.f).g, 0.763397, 2e-6);
  EXPECT_NEAR(toneMap(ToneMap::Aces, grey(2.5f), 0.f).g, 0.913327, 2e-6);
  // Over a range of greys the red and green channels are the curve (rows summing to exactly 1); blue
  // carries the output matrix's 0.99999.
  for (double g : {0.01, 0.05, 0.3, 3.0, 10.0}) {
    const glm::vec3 out = toneMap(ToneMap::Aces, grey(static_cast<float>(g)), 0.f);
    EXPECT_NEAR(out.r, acesCurve(g / 0.6), 1e-6) << g;
    EXPECT_NEAR(out.g, acesCurve(g / 0.6), 1e-6) << g;
    EXPECT_NEAR(out.b, 0.99999 * acesCurve(g / 0.6), 1e-6) << g;
  }
  // The fit tends to 1 / 0.983729 = 1.0165 and is clamped: white from about g = 20 on.
  EXPECT_EQ(toneMap(ToneMap::Aces, grey(100.f), 0.f), glm::vec3(1.f));
}

TEST(ToneMap, AcesMixesChannelsThroughTheAp1Matrices) {
  // Pure red 1: sRGB -> AP1 (input matrix column 0) / 0.6 = (0.995317, 0.126667, 0.047333);
  // f of each = (0.619838, 0.084330, 0.011530) (by hand from f above); the output matrix gives
  // R = 1.60475 * 0.619838 - 0.53108 * 0.084330 - 0.07367 * 0.011530 = 0.957333,
  // G = -0.10208 * 0.619838 + 1.10813 * 0.084330 - 0.00605 * 0.011530 = 0.005324,
  // B = -0.00327 * 0.619838 - 0.07276 * 0.084330 + 1.07602 * 0.011530 = 0.007158.
  const glm::vec3 red = toneMap(ToneMap::Aces, glm::vec3(1.f, 0.f, 0.f), 0.f);
  EXPECT_NEAR(red.r, 0.957333, 2e-6);
  EXPECT_NEAR(red.g, 0.005324, 2e-6);
  EXPECT_NEAR(red.b, 0.007158, 2e-6);
}

TEST(ToneMap, KhronosPbrNeutralKeepsBaseColoursAndCompressesHighlights) {
  // Below the compression start the colour passes through less the offset: 0.04 when the darkest
  // channel is at least 0.08, x - 6.25 x^2 below.
  EXPECT_NEAR(toneMap(ToneMap::KhronosPbrNeutral, grey(0.5f), 0.f).g, 0.46, 1e-7);
  EXPECT_NEAR(toneMap(ToneMap::KhronosPbrNeutral, grey(0.05f), 0.f).g, 6.25 * 0.05 * 0.05, 1e-7);
  const glm::vec3 c = toneMap(ToneMap::KhronosPbrNeutral, glm::vec3(0.6f, 0.3f, 0.1f), 0.f);
  EXPECT_NEAR(c.r, 0.56, 1e-7);
  EXPECT_NEAR(c.g, 0.26, 1e-7);
  EXPECT_NEAR(c.b, 0.06, 1e-7);
  // Grey 1: peak 0.96, newPeak = 1 - 0.0576 / (0.96 + 0.24 - 0.76) = 1 - 0.0576 / 0.44 = 0.869091.
  EXPECT_NEAR(toneMap(ToneMap::KhronosPbrNeutral, grey(1.f), 0.f).g, 0.869091, 1e-6);
  // Grey 2.5 (the Cornell box's mean): peak 2.46, newPeak = 1 - 0.0576 / 1.94 = 0.970309.
  EXPECT_NEAR(toneMap(ToneMap::KhronosPbrNeutral, grey(2.5f), 0.f).g, 0.970309, 1e-6);
  // A saturated highlight (0.9, 0.5, 0.02): offset 0.02 - 6.25 * 0.0004 = 0.0175, so (0.8825, 0.4825,
  // 0.0025), peak 0.8825; newPeak = 1 - 0.0576 / 0.3625 = 0.841103; scaled by newPeak / peak =
  // 0.953091: (0.841103, 0.459867, 0.002383); g = 1 - 1 / (0.15 * 0.041397 + 1) = 0.006171 mixes
  // towards newPeak: (0.841103, 0.462219, 0.007559).
  const glm::vec3 h = toneMap(ToneMap::KhronosPbrNeutral, glm::vec3(0.9f, 0.5f, 0.02f), 0.f);
  EXPECT_NEAR(h.r, 0.841103, 2e-6);
  EXPECT_NEAR(h.g, 0.462219, 2e-6);
  EXPECT_NEAR(h.b, 0.007559, 2e-6);
}

TEST(ToneMap, AgxFollowsItsLogEncodingAndContrastPolynomial) {
  auto p = [](double x) {
    const double x2 = x * x, x4 = x2 * x2;
    return 15.5 * x4 * x2 - 40.14 * x4 * x + 31.96 * x4 - 6.868 * x2 * x + 0.4298 * x2 + 0.1191 * x - 0.00232;
  };
  auto curve = [&](double g) {
    const double e = std::clamp((std::log2(g) + 12.47393) / (4.026069 + 12.47393), 0.0, 1.0);
    return std::pow(std::max(p(e), 0.0), 2.2);
  };
  // Middle grey 0.18 sits at e = 10 / 16.5 = 0.60606 of the log range: p = 0.49673, ^2.2 = 0.21452.
  EXPECT_NEAR(curve(0.18), 0.21452, 1e-5);
  // The matrices keep grey within their rows' 1e-4: the curve within 2e-4.
  for (double g : {0.01, 0.18, 1.0, 2.5, 16.0}) {
    const glm::vec3 out = toneMap(ToneMap::Agx, grey(static_cast<float>(g)), 0.f);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(out[c], curve(g), 2e-4) << g << " channel " << c;
  }
  // Below 2^-12.47 (e = 0), p(0) = -0.00232 < 0: black, not a negative lift.
  EXPECT_EQ(toneMap(ToneMap::Agx, grey(1e-5f), 0.f), glm::vec3(0.f));
}

// ---- the PNG writer ----

// The 8-bit codes of a PNG as written (alpha straight, not premultiplied on reading).
std::vector<unsigned char> pngCodes(const std::string& png, int* channels) {
  OIIO::Filesystem::IOMemReader reader(const_cast<char*>(png.data()), png.size());
  OIIO::ImageSpec config, spec;
  config.attribute("oiio:UnassociatedAlpha", 1);
  // OpenImageIO 2.4's ImageInput::open(name, config, proxy) drops the proxy when given a config.
  auto in = OIIO::ImageInput::create("frame.png", false, nullptr, &reader);
  EXPECT_TRUE(in && in->set_ioproxy(&reader) && in->open("frame.png", spec, config)) << OIIO::geterror();
  if (!in) return {};
  *channels = spec.nchannels;
  std::vector<unsigned char> codes(static_cast<std::size_t>(spec.width) * spec.height * spec.nchannels);
  EXPECT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::UINT8, codes.data()));
  return codes;
}

// The sRGB code of a linear value, rounded to nearest, in double (IEC 61966-2-1).
int srgbCode(double v) {
  v = std::clamp(v, 0.0, 1.0);
  const double e = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
  return static_cast<int>(std::floor(e * 255.0 + 0.5));
}

TEST(Png, StandardIsTodaysClampedSrgbByteForByte) {
  // A ramp through [0, 1.5] plus values that must saturate: every code equals round(255 sRGB(clamp(v))).
  Image img = Image::make("beauty", 512, 2, 3);
  for (std::size_t i = 0; i < img.pixels.size(); ++i) img.pixels[i] = 1.5f * static_cast<float>(i) / img.pixels.size();
  img.pixels[0] = -1.f;
  img.pixels[1] = std::numeric_limits<float>::quiet_NaN();
  img.pixels[2] = std::numeric_limits<float>::infinity();
  for (float ev : {0.f, -1.5f}) {
    PngOptions o;
    o.exposureEV = ev;
    o.toneMap = ToneMap::Standard;
    const std::string png = encodePng(img, o);
    EXPECT_EQ(png, encodePng(img, ev)) << "the (exposure, zlib) overload is the standard view transform";
    int channels = 0;
    const std::vector<unsigned char> codes = pngCodes(png, &channels);
    ASSERT_EQ(channels, 3);
    ASSERT_EQ(codes.size(), img.pixels.size());
    EXPECT_EQ(codes[0], 0);
    EXPECT_EQ(codes[1], 0);
    EXPECT_EQ(codes[2], 255);
    int mismatches = 0;
    for (std::size_t i = 3; i < codes.size(); ++i)
      mismatches += codes[i] != srgbCode(img.pixels[i] * std::exp2(static_cast<double>(ev)));
    EXPECT_EQ(mismatches, 0);
  }
}

TEST(Png, ToneMapAppliesToRadianceAndNotToData) {
  Image beauty = Image::make("beauty", 4, 1, 3), albedo = Image::make("albedo", 4, 1, 3);
  for (std::size_t i = 0; i < beauty.pixels.size(); ++i) beauty.pixels[i] = albedo.pixels[i] = 0.18f * (1 + i % 3);
  PngOptions aces;
  aces.toneMap = ToneMap::Aces;
  int channels = 0;
  const std::vector<unsigned char> b = pngCodes(encodePng(beauty, aces), &channels);
  for (int p = 0; p < 4; ++p) {
    const float* px = beauty.at(p, 0);
    const glm::vec3 display = toneMap(ToneMap::Aces, glm::vec3(px[0], px[1], px[2]), 0.f);
    for (int c = 0; c < 3; ++c) EXPECT_EQ(b[p * 3 + c], srgbCode(display[c])) << p << " " << c;
  }
  // The albedo AOV (data: api::AovInfo::radiance false) is written as stored whatever the view transform.
  EXPECT_EQ(encodePng(albedo, aces), encodePng(albedo, 0.f));
  EXPECT_NE(encodePng(beauty, aces), encodePng(beauty, 0.f));
}

TEST(Png, AlphaIsCoverageAndColourIsUnpremultiplied) {
  // A premultiplied beauty: pixel 0 uncovered (0, alpha 0), pixel 1 covered (alpha 1), pixel 2 half
  // covered by a surface of radiance 0.4 (beauty 0.2, alpha 0.5).
  Image beauty = Image::make("beauty", 3, 1, 3), alpha = Image::make("alpha", 3, 1, 1);
  const float b[9] = {0, 0, 0, 0.4f, 0.4f, 0.4f, 0.2f, 0.2f, 0.2f};
  std::copy(b, b + 9, beauty.pixels.begin());
  alpha.pixels = {0.f, 1.f, 0.5f};
  PngOptions o;
  o.toneMap = ToneMap::Standard;
  o.alpha = &alpha;
  int channels = 0;
  const std::vector<unsigned char> codes = pngCodes(encodePng(beauty, o), &channels);
  ASSERT_EQ(channels, 4);
  EXPECT_EQ(codes[3], 0);
  EXPECT_EQ(codes[7], 255);
  EXPECT_EQ(codes[11], 128);  // round(0.5 * 255)
  EXPECT_EQ(codes[0], 0);
  EXPECT_EQ(codes[4], srgbCode(0.4));
  EXPECT_EQ(codes[8], srgbCode(0.4)) << "straight colour: the surface's, not half of it";
  // Read back as the daemon's clients do: the A channel is the coverage.
  const std::string path = ::testing::TempDir() + "/alpha.png";
  writeFile(path, encodePng(beauty, o));
  const Image a = readImage(path, "alpha");
  ASSERT_EQ(a.channels, 1);
  EXPECT_EQ(a.pixels[0], 0.f);
  EXPECT_EQ(a.pixels[1], 1.f);
  // And in an EXR beside the beauty: R, G, B, A.
  writeFile(::testing::TempDir() + "/alpha.exr", encodeExr({beauty, alpha}, false));
  const Image ea = readImage(::testing::TempDir() + "/alpha.exr", "alpha");
  EXPECT_EQ(ea.pixels, alpha.pixels);
  Image wrongSize = Image::make("alpha", 2, 1, 1);
  o.alpha = &wrongSize;
  EXPECT_THROW(encodePng(beauty, o), std::invalid_argument);
}

TEST(ToneMap, NamesRoundTrip) {
  for (ToneMap op : kAll) EXPECT_EQ(api::toneMapFromString(api::toString(op)), op);
  EXPECT_EQ(api::toneMapFromString("filmic"), std::nullopt);
  EXPECT_STREQ(api::toString(ToneMap::KhronosPbrNeutral), "khronos_pbr_neutral");
}

}  // namespace
}  // namespace radiant::io
