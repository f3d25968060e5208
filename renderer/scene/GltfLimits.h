#pragma once
// The glTF loader's defences against hostile files, kept apart from the loader so that the limits
// can be read (and changed) in one place. Each runs before the code it protects:
//
//   checkGltfText()         the JSON text (glTF file or GLB JSON chunk), before nlohmann or tinygltf
//                           parse it: nesting depth (tinygltf copies "extras" recursively and dies
//                           from ~14k levels), UTF-8, numbers beyond a double.
//   checkGltfDocument()     the parsed JSON, before tinygltf: every number that becomes a float fits
//                           one; node transforms and camera/light values are finite and within
//                           kMaxCoordinate; and the memory that expanding every accessor of every
//                           mesh instance takes, charged against the decode budget.
//   DecodeBudget::chargeImage()  each embedded image, from its header (stb_image's own parser, so
//                           every format stb decodes is covered), before stb allocates the pixels.
//   checkSceneMagnitudes()  the loaded Scene: world-space positions, the camera and the lights are
//                           finite and within kMaxCoordinate, so no ray built from them is invalid.
//
// Over a configured limit -> SceneLimitError (the server's 422 limit-exceeded, naming the flag);
// anything else -> SceneError (422 invalid-scene). Both carry a JSON pointer into the glTF.

#include <cstddef>
#include <exception>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "renderer/scene/GltfLoader.h"

namespace radiant {

// World coordinates, translations and scale factors beyond this are refused: far inside float
// range (so products of a few do not overflow) and inside Embree's valid ray origins (|o| < 1.8e19).
inline constexpr double kMaxCoordinate = 1e9;

// A file within the glTF spec but over a limit this loader was configured with.
struct SceneLimitError : SceneError {
  SceneLimitError(std::string pointer, const std::string& message, std::string flag_)
      : SceneError(std::move(pointer), message), flag(std::move(flag_)) {}
  std::string flag;  // the radiantd flag that raises the limit ("--max-decode-bytes")
};

// Bytes of decoded data one load may still allocate (images, expanded accessors).
class DecodeBudget {
public:
  explicit DecodeBudget(std::size_t bytes, std::function<void(std::size_t)> reserve = {})
      : limit_(bytes), remaining_(bytes), reserve_(std::move(reserve)) {}
  std::size_t remaining() const { return remaining_; }
  std::size_t limit() const { return limit_; }
  // Takes `bytes` or throws SceneLimitError at `pointer`; then reserves them (LoadOptions::reserveDecoded),
  // whose exception passes through.
  void charge(std::size_t bytes, const std::string& pointer, const std::string& what);
  // For tinygltf's image callback (which must not throw): reads the image header, charges the
  // decoded size (RGBA at the file's bit depth, plus the 8-bit copy the Scene keeps) and returns
  // true, or records the error (rethrown by rethrowImageError()) and returns false.
  bool chargeImage(const unsigned char* bytes, std::size_t size, int imageIndex, std::string* err);
  // After a failed tinygltf load: throws what chargeImage() recorded (the reservation's own exception
  // first, else the SceneLimitError/SceneError).
  void rethrowImageError() const;

private:
  std::size_t limit_, remaining_;
  std::function<void(std::size_t)> reserve_;
  std::optional<SceneLimitError> imageError_;
  std::exception_ptr reserveError_;
};

// Decoded RGBA bytes of an image, from its header: nullopt when stb_image cannot read it.
struct ImageHeader {
  int width = 0, height = 0, channels = 0;
  bool sixteenBit = false;
};
std::optional<ImageHeader> readImageHeader(const unsigned char* bytes, std::size_t size);
// A WebP file (RIFF container, "WEBP" form type: EXT_texture_webp). stb_image does not decode WebP;
// libwebp does (GltfFiles.cpp), 8-bit RGBA.
bool isWebp(const unsigned char* bytes, std::size_t size);
// PNG, JPEG or WebP by its magic bytes: the image formats a glTF may hold (DecodeBudget::chargeImage
// refuses the others before a decoder sees them).
bool isGltfImageFormat(const unsigned char* bytes, std::size_t size);

void checkGltfText(std::string_view jsonText, const LoadOptions& options);
// Returns the budget left for images once accessor expansion is charged.
DecodeBudget checkGltfDocument(const nlohmann::json& doc, const LoadOptions& options);
void checkSceneMagnitudes(const Scene& scene, const nlohmann::json& doc);

}  // namespace radiant
