#include "renderer/io/ImageIO.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <functional>
#include <limits>
#include <stdexcept>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include "api/Aovs.h"
#include "renderer/io/MemoryReader.h"
#include "renderer/io/ToneMap.h"

namespace radiant::io {
namespace OIIO = OIIO_NAMESPACE;

float linearToSrgb(float v) {
  v = std::clamp(v, 0.f, 1.f);
  return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.f / 2.4f) - 0.055f;
}

float srgbToLinear(float v) {
  return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

namespace {

std::string writeToMemory(const char* nameHint, const OIIO::ImageSpec& spec, OIIO::TypeDesc type, const void* data) {
  std::vector<unsigned char> bytes;
  OIIO::Filesystem::IOVecOutput proxy(bytes);
  auto out = OIIO::ImageOutput::create(nameHint, &proxy);
  if (!out) throw std::runtime_error(std::string("io: no image writer for ") + nameHint + ": " + OIIO::geterror());
  if (!out->open(nameHint, spec)) throw std::runtime_error("io: open " + std::string(nameHint) + ": " + out->geterror());
  if (!out->write_image(type, data)) throw std::runtime_error("io: write " + std::string(nameHint) + ": " + out->geterror());
  if (!out->close()) throw std::runtime_error("io: close " + std::string(nameHint) + ": " + out->geterror());
  return std::string(bytes.begin(), bytes.end());
}

// EXR channel names of one AOV: the AOV table's (api/Aovs.cpp; beauty is the default layer R,G,B so
// viewers show it first). An image the table does not name (an upload) gets "<name>.R/G/B/A" or ".Y".
std::vector<std::string> channelNames(const Image& img) {
  if (const api::AovInfo* a = api::findAov(img.aov); a && static_cast<int>(a->exr.size()) == img.channels)
    return a->exr;
  static const char* rgb[] = {"R", "G", "B", "A"};
  std::vector<std::string> names;
  const std::string prefix = img.aov == "beauty" ? "" : img.aov + ".";
  if (img.channels == 1) {
    names.push_back(prefix + (img.aov == "depth" ? "Z" : "Y"));
  } else {
    for (int c = 0; c < img.channels; ++c) names.push_back(prefix + rgb[std::min(c, 3)]);
  }
  return names;
}

}  // namespace

std::size_t valuesBeyondHalf(const Image& image) {
  return static_cast<std::size_t>(
      std::count_if(image.pixels.begin(), image.pixels.end(), [](float v) { return std::fabs(v) > kHalfMax; }));
}

std::string encodeExr(const std::vector<Image>& aovs, bool halfFloat, std::vector<std::size_t>* clampedPerAov) {
  if (aovs.empty()) throw std::invalid_argument("encodeExr: no AOVs");
  const int w = aovs[0].width, h = aovs[0].height;
  int channels = 0;
  std::vector<std::string> names;
  for (const Image& a : aovs) {
    if (a.width != w || a.height != h) throw std::invalid_argument("encodeExr: AOV sizes differ: " + a.aov);
    for (auto& n : channelNames(a)) names.push_back(n);
    channels += a.channels;
  }
  OIIO::ImageSpec spec(w, h, channels, halfFloat ? OIIO::TypeDesc::HALF : OIIO::TypeDesc::FLOAT);
  spec.channelnames = names;
  spec.attribute("compression", "zip");
  // Interleave every AOV's channels into one pixel. OpenImageIO converts a float beyond the half range
  // to +-Inf (radiance above 65504 is within the API's ranges: ambient 1e6, a 1e15 light), so a half
  // file gets the largest finite half instead, and the clamps are counted.
  std::vector<float> data(static_cast<std::size_t>(w) * h * channels);
  std::vector<std::size_t> clamped(aovs.size(), 0);
  for (std::size_t p = 0; p < static_cast<std::size_t>(w) * h; ++p) {
    int off = 0;
    for (std::size_t i = 0; i < aovs.size(); ++i) {
      const Image& a = aovs[i];
      for (int c = 0; c < a.channels; ++c) {
        float v = a.pixels[p * a.channels + c];
        if (halfFloat && std::fabs(v) > kHalfMax) {
          v = std::copysign(kHalfMax, v);
          ++clamped[i];
        }
        data[p * channels + off + c] = v;
      }
      off += a.channels;
    }
  }
  if (clampedPerAov) *clampedPerAov = std::move(clamped);
  return writeToMemory("frame.exr", spec, OIIO::TypeDesc::FLOAT, data.data());
}

namespace {

// 8-bit sRGB without a pow per channel. Threshold k is the linear value at which sRGB(v) * 255 crosses
// k + 0.5, so the rounded code of v is the number of thresholds at or below it. A table over 65536
// cells of [0, 1] holds the code at each cell's lower edge; codes are at least 3e-4 apart in linear
// units (the transfer's steepest part), wider than a cell, so one comparison with the next threshold
// finishes the exact rounding. Values below 0 or above 1 saturate (never wrap).
struct SrgbTable {
  std::array<float, 256> threshold{};
  std::vector<unsigned char> lowerCode = std::vector<unsigned char>(65536);
  SrgbTable() {
    for (int k = 0; k < 255; ++k) threshold[k] = srgbToLinear((k + 0.5f) / 255.f);
    threshold[255] = std::numeric_limits<float>::infinity();
    int code = 0;
    for (int i = 0; i < 65536; ++i) {
      while (code < 255 && threshold[code] <= i / 65535.f) ++code;
      lowerCode[i] = static_cast<unsigned char>(code);
    }
  }
  unsigned char operator()(float v) const {
    if (!(v > 0.f)) return 0;  // also NaN
    if (v >= 1.f) return 255;
    unsigned code = lowerCode[static_cast<std::size_t>(v * 65535.f)];
    code += v >= threshold[code];
    return static_cast<unsigned char>(code);
  }
};

}  // namespace

std::string encodePng(const Image& image, const PngOptions& options) {
  static const SrgbTable toSrgb8;
  const Image* alpha = options.alpha;
  if (alpha && (alpha->width != image.width || alpha->height != image.height || alpha->channels != 1))
    throw std::invalid_argument("encodePng: the alpha image is not one channel of the image's size");
  const int colourChannels = image.channels == 1 ? 1 : 3;
  const int outChannels = colourChannels + (alpha ? 1 : 0);
  OIIO::ImageSpec spec(image.width, image.height, outChannels, OIIO::TypeDesc::UINT8);
  // Data AOVs and scalars are shown as stored; the view transform is for radiance.
  const api::AovInfo* info = api::findAov(image.aov);
  const api::ToneMap op = colourChannels == 1 || (info && !info->radiance) ? api::ToneMap::Standard : options.toneMap;
  const float scale = std::exp2(options.exposureEV);
  std::vector<unsigned char> data(static_cast<std::size_t>(image.width) * image.height * outChannels);
  for (std::size_t p = 0; p < static_cast<std::size_t>(image.width) * image.height; ++p) {
    const float* in = &image.pixels[p * image.channels];
    unsigned char* out = &data[p * outChannels];
    // Straight colour from the premultiplied image (alpha 0: nothing was hit, and the colour is 0).
    const float a = alpha ? std::clamp(alpha->pixels[p], 0.f, 1.f) : 1.f;
    const float unpremultiply = a > 0.f ? 1.f / a : 0.f;
    if (op == api::ToneMap::Standard) {
      for (int c = 0; c < colourChannels; ++c) out[c] = toSrgb8(in[c] * unpremultiply * scale);
    } else {
      const glm::vec3 display = toneMap(op, glm::vec3(in[0], in[1], in[2]) * unpremultiply, options.exposureEV);
      for (int c = 0; c < 3; ++c) out[c] = toSrgb8(display[c]);
    }
    if (alpha) out[colourChannels] = static_cast<unsigned char>(std::lround(a * 255.f));
  }
  // zlib level 1 by default: about 3x faster than zlib's default 6 for a few per cent larger files,
  // the right trade for a render service (the encode dominated the service overhead).
  spec.attribute("png:compressionLevel", std::clamp(options.zlibLevel, 0, 9));
  // Stored (level 0): libpng's per-row filter search only prepares data for a compressor that does
  // not run; PNG_FILTER_NONE (8) makes the same bytes ~5x faster (0.5 ms instead of 3 at 256x256).
  if (options.zlibLevel <= 0) spec.attribute("png:filter", 8);
  // Straight (unassociated) alpha: PNG's own convention; OIIO would otherwise unpremultiply again.
  if (alpha) spec.attribute("oiio:UnassociatedAlpha", 1);
  return writeToMemory("frame.png", spec, OIIO::TypeDesc::UINT8, data.data());
}

std::string encodePng(const Image& image, float exposureEV, int zlibLevel) {
  PngOptions options;
  options.exposureEV = exposureEV;
  options.zlibLevel = zlibLevel;
  return encodePng(image, options);
}

void writeFile(const std::string& path, const std::string& bytes) {
  std::ofstream f(path, std::ios::binary);
  if (!f) throw std::runtime_error("io: cannot open " + path + " for writing");
  f.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!f) throw std::runtime_error("io: short write to " + path);
}

namespace {

// What decoding an image of this size costs, from its header, before allocating: the float copy of
// every channel plus the RGB image kept, and OpenImageIO's own buffer while reading, which holds up to
// 256 scanlines whatever the image's height: a 95-byte Radiance HDR declaring one row of 2,222,222
// pixels had it allocate 6.8 GB (image fuzzer, 2026-12-04; tests/data/crashers/images/hdr_one_wide_row_takes_6_8gb.hdr).
// Over `maxDecodedBytes` (0: no limit) it is refused, naming the flag.
std::uint64_t chargeDecode(const std::string& what, std::int64_t width, std::int64_t height, std::int64_t channels,
                           std::size_t maxDecodedBytes) {
  const std::uint64_t pixels = std::uint64_t(width) * std::uint64_t(height);
  const std::uint64_t readBuffer = std::uint64_t(width) * 256u * std::uint64_t(channels) * 4;
  const std::uint64_t need = pixels * std::uint64_t(channels) * 4 + pixels * 3 * 4 + readBuffer;
  if (maxDecodedBytes > 0 && need > maxDecodedBytes)
    throw DecodeLimitExceeded("io: " + what + " is " + std::to_string(width) + "x" + std::to_string(height) + " with " +
                              std::to_string(channels) + " channels: decoding needs " + std::to_string(need) +
                              " bytes, above this server's decode budget of " + std::to_string(maxDecodedBytes) +
                              " bytes (radiantd --max-decode-bytes)");
  return need;
}

Image readFrom(OIIO::ImageInput* in, const std::string& what, const std::string& aov, std::size_t maxDecodedBytes = 0,
               const std::function<void(std::size_t)>& reserve = {}) {
  if (!in) throw std::runtime_error("io: cannot read " + what + ": " + OIIO::geterror());
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0) throw std::runtime_error("io: " + what + " is empty");
  const std::uint64_t need = chargeDecode(what, spec.width, spec.height, spec.nchannels, maxDecodedBytes);
  if (reserve) reserve(std::size_t(need));
  // Which channels: the layer `aov` by name (aov.R/G/B, or aov.Y); for "beauty" also unprefixed R/G/B
  // (or Y), a file's only layer, and at last the first three channels or the first one. EXR stores channels
  // in alphabetical order (B before G before R), so names, not positions, decide.
  auto find = [&](const std::string& name) {
    for (int c = 0; c < spec.nchannels; ++c)
      if (c < static_cast<int>(spec.channelnames.size()) && spec.channelnames[c] == name) return c;
    return -1;
  };
  std::vector<int> pick;
  // A transparent frame's coverage: the A channel beside the beauty (EXR and PNG alike).
  if (aov == "alpha") {
    if (find("A") < 0) throw std::runtime_error("io: " + what + " has no alpha channel (A)");
    pick = {find("A")};
  }
  // Unprefixed channels are the beauty (encodeExr writes it so, and PNG/HDR have nothing else).
  for (const std::string& prefix : aov == "beauty" ? std::vector<std::string>{"beauty.", ""} : std::vector<std::string>{aov + "."}) {
    if (!pick.empty()) break;
    const int r = find(prefix + "R"), g = find(prefix + "G"), b = find(prefix + "B"), yy = find(prefix + "Y");
    if (r >= 0 && g >= 0 && b >= 0) pick = {r, g, b};
    else if (yy >= 0) pick = {yy};
    if (!pick.empty()) break;
  }
  std::vector<std::string> layers;  // the prefixes of the file's layered channels
  for (const auto& n : spec.channelnames)
    if (const auto dot = n.rfind('.'); dot != std::string::npos &&
        std::find(layers.begin(), layers.end(), n.substr(0, dot)) == layers.end())
      layers.push_back(n.substr(0, dot));
  if (pick.empty() && layers.size() == 1 && aov == "beauty") {  // one layer, whatever its name
    const std::string& l = layers[0];
    const int r = find(l + ".R"), g = find(l + ".G"), b = find(l + ".B"), yy = find(l + ".Y");
    if (r >= 0 && g >= 0 && b >= 0) pick = {r, g, b};
    else if (yy >= 0) pick = {yy};
  }
  if (pick.empty()) {
    const bool layered = !layers.empty();
    if (layered && aov != "beauty") {
      std::string names;
      for (const auto& n : spec.channelnames) names += (names.empty() ? "" : ", ") + n;
      throw std::runtime_error("io: " + what + " has no layer '" + aov + "' (channels: " + names + ")");
    }
    pick = spec.nchannels >= 3 ? std::vector<int>{0, 1, 2} : std::vector<int>{0};
  }
  Image img = Image::make(aov, spec.width, spec.height, static_cast<int>(pick.size()));
  std::vector<float> all(static_cast<std::size_t>(spec.width) * spec.height * spec.nchannels);
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, all.data()))
    throw std::runtime_error("io: read " + what + ": " + in->geterror());
  for (std::size_t p = 0; p < static_cast<std::size_t>(spec.width) * spec.height; ++p)
    for (int c = 0; c < img.channels; ++c) img.pixels[p * img.channels + c] = all[p * spec.nchannels + pick[c]];
  return img;
}

}  // namespace

Image readImage(const std::string& path, const std::string& aov) {
  auto in = OIIO::ImageInput::open(path);
  return readFrom(in.get(), path, aov);
}

ImageRgba8 decodePngRgba8(std::string_view bytes) {
  if (bytes.substr(0, 4) != "\x89PNG") throw std::runtime_error("io: not a PNG image");
  MemoryReader reader(bytes);
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);  // the codes as stored, not premultiplied
  // create + set_ioproxy + open: ImageInput::open(name, &config, proxy) ignores the proxy here.
  auto in = OIIO::ImageInput::create("png");
  OIIO::ImageSpec spec;
  if (!in || !in->set_ioproxy(&reader) || !in->open("image.png", spec, config))
    throw std::runtime_error("io: cannot read the PNG: " + (in ? in->geterror() : OIIO::geterror()));
  const int n = spec.nchannels;
  if (spec.width <= 0 || spec.height <= 0 || n < 1 || n > 4 || spec.format != OIIO::TypeDesc::UINT8)
    throw std::runtime_error("io: the PNG is not 8-bit with 1 to 4 channels");
  std::vector<unsigned char> all(static_cast<std::size_t>(spec.width) * spec.height * n);
  if (!in->read_image(0, 0, 0, n, OIIO::TypeDesc::UINT8, all.data()))
    throw std::runtime_error("io: read the PNG: " + in->geterror());
  ImageRgba8 img = ImageRgba8::make(spec.width, spec.height);
  const bool hasAlpha = n == 2 || n == 4;
  const int colours = hasAlpha ? n - 1 : n;
  for (std::size_t p = 0; p < static_cast<std::size_t>(spec.width) * spec.height; ++p) {
    for (int c = 0; c < 3; ++c) img.pixels[p * 4 + c] = all[p * n + std::min(c, colours - 1)];
    img.pixels[p * 4 + 3] = hasAlpha ? all[p * n + n - 1] : 255;
  }
  return img;
}

std::string encodePngRgba8(const ImageRgba8& image, bool alpha, int zlibLevel) {
  if (image.width <= 0 || image.height <= 0 || image.pixels.size() != static_cast<std::size_t>(image.width) * image.height * 4)
    throw std::runtime_error("io: encodePngRgba8(): empty or malformed image");
  OIIO::ImageSpec spec(image.width, image.height, alpha ? 4 : 3, OIIO::TypeDesc::UINT8);
  spec.attribute("png:compressionLevel", std::clamp(zlibLevel, 0, 9));
  if (alpha) spec.attribute("oiio:UnassociatedAlpha", 1);
  if (alpha) return writeToMemory("image.png", spec, OIIO::TypeDesc::UINT8, image.pixels.data());
  std::vector<unsigned char> rgb(static_cast<std::size_t>(image.width) * image.height * 3);
  for (std::size_t p = 0; p < static_cast<std::size_t>(image.width) * image.height; ++p)
    for (int c = 0; c < 3; ++c) rgb[p * 3 + c] = image.pixels[p * 4 + c];
  return writeToMemory("image.png", spec, OIIO::TypeDesc::UINT8, rgb.data());
}

namespace {

// An attribute of type chlist: channels (name\0, int32 pixel type 0-2, uint8 pLinear, 3 reserved bytes,
// int32 x and y sampling >= 1) ended by an empty name, all inside the attribute's declared size.
// OpenEXR reads the list until its terminator whatever the size: an 884-byte upload whose last channel
// name ran one byte past its attribute made it read the next attributes as channels, and opening it
// took 1.5 GB and 8 s (image fuzzer, 2026-12-04).
int checkExrChannelList(std::string_view v, const std::function<void(const std::string&)>& bad) {
  std::size_t i = 0;
  int channels = 0;
  auto le32 = [&](std::size_t at) {
    return std::int32_t(std::uint32_t(std::uint8_t(v[at])) | std::uint32_t(std::uint8_t(v[at + 1])) << 8 |
                        std::uint32_t(std::uint8_t(v[at + 2])) << 16 | std::uint32_t(std::uint8_t(v[at + 3])) << 24);
  };
  for (;; ++channels) {
    if (i >= v.size()) bad("the channel list does not end inside its attribute");
    if (v[i] == '\0') {
      if (i + 1 != v.size()) bad("the channel list ends before its attribute does");
      break;
    }
    const std::size_t end = v.find('\0', i);
    if (end == std::string_view::npos || end - i > 255) bad("a channel name is not terminated inside the channel list");
    i = end + 1;
    if (v.size() - i < 16) bad("channel " + std::to_string(channels) + " is cut short");
    const std::int32_t type = le32(i), xs = le32(i + 8), ys = le32(i + 12);
    if (type < 0 || type > 2) bad("channel " + std::to_string(channels) + " has pixel type " + std::to_string(type));
    if (xs < 1 || ys < 1 || xs > 65536 || ys > 65536) bad("channel " + std::to_string(channels) + " has sampling out of range");
    i += 16;
    if (channels > 1024) bad("more than 1024 channels");
  }
  if (channels == 0) bad("the channel list is empty");
  return channels;
}

// An OpenEXR header's attributes (name\0 type\0 int32 size, value), checked before OpenEXR reads them:
// OpenEXR allocates an attribute's declared size first, so a 508-byte upload declaring a 1.6 GB string
// took the daemon to 2 GB (found by tests/fuzz/image_fuzzer.cpp, 2026-12-04). Every header (several in
// a multi-part file) must end inside the bytes, names and types must be terminated within 256 bytes,
// and no value may be larger than what is left of the file. A chlist must pass checkExrChannelList, each
// header must name its channels and a box2i dataWindow, and the data window is charged to the decode
// budget (chargeDecode) before OpenEXR allocates for it.
void checkExrHeaders(std::string_view b, std::size_t maxDecodedBytes) {
  auto bad = [](const std::string& why) { throw std::runtime_error("io: the uploaded exr image is invalid: " + why); };
  if (b.size() < 8) bad("shorter than its magic number and version");
  const std::uint32_t flags = std::uint8_t(b[5]) | std::uint32_t(std::uint8_t(b[6])) << 8 | std::uint32_t(std::uint8_t(b[7])) << 16;
  const bool multipart = (flags & 0x10) != 0;  // bit 12 of the version field
  std::size_t i = 8;
  for (int header = 0;; ++header) {
    int attributes = 0;
    bool hasChannels = false, hasDataWindow = false;
    int channels = 0;
    std::int64_t width = 0, height = 0;
    for (;; ++attributes) {
      if (i >= b.size()) bad("a header does not end inside the file");
      if (b[i] == '\0') {  // the header's end
        ++i;
        break;
      }
      std::string_view fields[2];
      for (int field = 0; field < 2; ++field) {  // name, then type
        const std::size_t end = b.find('\0', i);
        if (end == std::string_view::npos || end - i > 255) bad("an attribute name or type is not terminated");
        fields[field] = b.substr(i, end - i);
        i = end + 1;
      }
      if (b.size() - i < 4) bad("an attribute has no size");
      const std::int32_t size = std::int32_t(std::uint32_t(std::uint8_t(b[i])) | std::uint32_t(std::uint8_t(b[i + 1])) << 8 |
                                             std::uint32_t(std::uint8_t(b[i + 2])) << 16 |
                                             std::uint32_t(std::uint8_t(b[i + 3])) << 24);
      i += 4;
      if (size < 0 || std::size_t(size) > b.size() - i)
        bad("attribute " + std::to_string(attributes) + " declares " + std::to_string(size) + " bytes, more than the file holds");
      const std::string_view value = b.substr(i, std::size_t(size));
      const int listed = fields[1] == "chlist" ? checkExrChannelList(value, bad) : 0;
      if (fields[0] == "channels") hasChannels = fields[1] == "chlist", channels = listed;
      if (fields[0] == "dataWindow") {
        if (fields[1] != "box2i" || value.size() != 16) bad("dataWindow is not a box2i");
        auto le32 = [&](std::size_t at) {
          return std::int64_t(std::int32_t(std::uint32_t(std::uint8_t(value[at])) | std::uint32_t(std::uint8_t(value[at + 1])) << 8 |
                                           std::uint32_t(std::uint8_t(value[at + 2])) << 16 |
                                           std::uint32_t(std::uint8_t(value[at + 3])) << 24));
        };
        width = le32(8) - le32(0) + 1, height = le32(12) - le32(4) + 1;
        if (width <= 0 || height <= 0) bad("the dataWindow is empty");
        hasDataWindow = true;
      }
      i += std::size_t(size);
    }
    // Every part of an image names its channels and its data window (OpenEXR's required attributes).
    if (attributes > 0 && (!hasChannels || !hasDataWindow)) bad("a header has no channels or no dataWindow");
    // Its size against the decode budget, as readFrom charges it, before OpenEXR allocates anything
    // (a 100000 x 100000 header was "Unexpected end of file" where HDR and PNG were limit-exceeded).
    if (attributes > 0) chargeDecode("the uploaded exr image", width, height, channels, maxDecodedBytes);
    // A multi-part file lists its headers one after the other and ends the list with an empty one.
    if (!multipart || attributes == 0 || header > 1024) break;
  }
}

// A PNG's chunks (length, type, data, CRC), checked before libpng reads them: libpng allocates a chunk's
// declared length first, so a 304-byte upload whose tEXt chunk declared 1.7 GB took 2 GB (found by
// tests/fuzz/image_fuzzer.cpp, 2026-12-04). Every chunk must lie inside the bytes.
void checkPngChunks(std::string_view b) {
  std::size_t i = 8;  // after the signature
  while (i < b.size()) {
    if (b.size() - i < 12) throw std::runtime_error("io: the uploaded png image is invalid: a chunk is cut short");
    const std::uint32_t length = std::uint32_t(std::uint8_t(b[i])) << 24 | std::uint32_t(std::uint8_t(b[i + 1])) << 16 |
                                 std::uint32_t(std::uint8_t(b[i + 2])) << 8 | std::uint32_t(std::uint8_t(b[i + 3]));
    if (length > b.size() - i - 12)
      throw std::runtime_error("io: the uploaded png image is invalid: chunk " + std::string(b.substr(i + 4, 4)) +
                               " declares " + std::to_string(length) + " bytes, more than the file holds");
    if (b.substr(i + 4, 4) == "IEND") return;
    i += 12 + length;
  }
}

}  // namespace

Image decodeImage(std::string_view bytes, const std::string& aov, std::size_t maxDecodedBytes,
                  const std::function<void(std::size_t)>& reserve) {
  auto starts = [&](std::string_view magic) { return bytes.substr(0, magic.size()) == magic; };
  const char* name = starts(std::string_view("\x76\x2f\x31\x01", 4)) ? "image.exr"
                     : starts("#?RADIANCE") || starts("#?RGBE") ? "image.hdr"
                     : starts("\x89PNG")                        ? "image.png"
                                                                 : nullptr;
  if (!name) throw std::runtime_error("io: not an EXR, Radiance HDR or PNG image");
  if (name == std::string_view("image.exr")) checkExrHeaders(bytes, maxDecodedBytes);
  if (name == std::string_view("image.png")) checkPngChunks(bytes);
  MemoryReader reader(bytes);
  auto in = OIIO::ImageInput::open(name, nullptr, &reader);
  return readFrom(in.get(), std::string("the uploaded ") + (name + 6) + " image", aov, maxDecodedBytes, reserve);
}

}  // namespace radiant::io
