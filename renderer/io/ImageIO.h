#pragma once
// Image encoding with OpenImageIO. Pure CPU: safe to call from any thread (the server runs it off the
// render thread so the GPU keeps working while frames are written).

#include <stdexcept>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "api/Types.h"
#include "renderer/Image.h"

namespace radiant::io {

// A multi-AOV OpenEXR file: each AOV becomes a channel group ("beauty.R", "depth.Z", ...), with
// beauty as the unprefixed default layer (R, G, B) so viewers show it first; an "alpha" image becomes
// its A channel (premultiplied, as EXR expects). halfFloat selects HALF, whose values beyond +-kHalfMax
// (+-Inf included) are written as +-kHalfMax, never as Inf; then `clampedPerAov` (when given) receives
// how many values of each AOV were clamped, in `aovs`' order.
std::string encodeExr(const std::vector<Image>& aovs, bool halfFloat, std::vector<std::size_t>* clampedPerAov = nullptr);
// The largest finite IEEE 754 binary16 value: (2 - 2^-10) x 2^15.
inline constexpr float kHalfMax = 65504.f;
// Values of `image` that a half-float EXR cannot hold (|v| > kHalfMax): the ones encodeExr(.., true)
// clamps. NaN is not counted (the renderer has zeroed every NaN before any output is encoded).
std::size_t valuesBeyondHalf(const Image& image);
// How a PNG is written (render_request.json exposure, tone_map, png_compression, background).
struct PngOptions {
  float exposureEV = 0.f;
  // The view transform (renderer/io/ToneMap.h) of a radiance AOV; data AOVs (api::AovInfo::radiance
  // false: albedo, normal, depth, ao, ...) and one-channel images are always written `standard`.
  api::ToneMap toneMap = api::ToneMap::Standard;
  int zlibLevel = 1;  // 0 (stored) .. 9; 1 is the service's default (see docs/PERFORMANCE.md)
  // Coverage in [0, 1] (one channel, the image's size): an RGBA PNG whose alpha it is. The image is
  // premultiplied (the renderer's transparent beauty: 0 where nothing was hit), so the colour written is
  // toneMap(image / alpha) (PNG alpha is straight), 0 where alpha is 0.
  const Image* alpha = nullptr;
};
// 8-bit sRGB PNG of one AOV: toneMap(value * 2^exposure) in [0,1] (never wrapped), sRGB transfer.
std::string encodePng(const Image& image, const PngOptions& options);
// The same with the `standard` view transform (clamp) and no alpha.
std::string encodePng(const Image& image, float exposureEV, int zlibLevel = 1);
void writeFile(const std::string& path, const std::string& bytes);
// Reads an EXR/HDR/PNG into float RGB (its first three channels, or its one channel) for
// compare-against-upload and tests; aov "alpha" reads the A channel (a transparent frame's coverage).
// Throws std::runtime_error naming what failed.
Image readImage(const std::string& path, const std::string& aov = "beauty");
// The same from bytes in memory; the format comes from the magic bytes (EXR, Radiance HDR, PNG).
// maxDecodedBytes > 0: the header's width x height x channels is checked against it before any
// pixel is read (DecodeLimitExceeded). `reserve`, when given, is then called with the bytes the decode
// will allocate, before it does (the daemon's shared decode memory; its exception passes through).
Image decodeImage(std::string_view bytes, const std::string& aov = "beauty", std::size_t maxDecodedBytes = 0,
                  const std::function<void(std::size_t)>& reserve = {});
struct DecodeLimitExceeded : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// A PNG's 8-bit codes as they are stored (no transfer decoded, straight alpha kept: OpenImageIO would
// otherwise premultiply), RGBA; an RGB or grey file gets alpha 255. What the render-fidelity metric
// scores. Throws std::runtime_error for anything but an 8-bit PNG of 1 to 4 channels.
ImageRgba8 decodePngRgba8(std::string_view bytes);
// An 8-bit PNG of the codes as they are (straight alpha; alpha = false writes RGB and drops it).
std::string encodePngRgba8(const ImageRgba8& image, bool alpha = true, int zlibLevel = 6);

// sRGB transfer of one linear value in [0,1] (IEC 61966-2-1).
float linearToSrgb(float linear);
float srgbToLinear(float encoded);

}  // namespace radiant::io
