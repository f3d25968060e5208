// libFuzzer: image headers and pixels from an untrusted source (issue 30, "Validate before decoding"),
// both ways images enter radiantd:
// - an uploaded image (environment map, comparison image): io::decodeImage with a decode budget
//   (EXR, Radiance HDR, PNG through OpenImageIO);
// - a glTF texture: the input as the one image of a minimal GLB, through the loader's image path
//   (the header charged against the decode budget first, then stb_image or libwebp: PNG, JPEG, webp,
//   and whatever else stb_image reads).
// Seeds: tests/data/crashers/images. Any input decodes or throws std::runtime_error (uploads) or
// SceneError (the loader); a crash, a sanitizer report or another exception is a bug.
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>

#include "renderer/io/ImageIO.h"
#include "renderer/scene/GltfLoader.h"

namespace {

void put32(std::string& s, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) s.push_back(char((v >> (8 * i)) & 255));
}

// A GLB whose BIN chunk is `image`, used as the base colour texture of one triangle's material.
std::string glbWithImage(std::string_view image) {
  std::string bin(image);
  while (bin.size() % 4) bin.push_back('\0');
  const std::size_t imageBytes = image.size();
  // The triangle's positions after the image, 4-byte aligned.
  const std::size_t positions = bin.size();
  const float p[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  bin.append(reinterpret_cast<const char*>(p), sizeof p);
  std::string json = R"({"asset":{"version":"2.0"},"buffers":[{"byteLength":)" + std::to_string(bin.size()) +
                     R"(}],"bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":)" + std::to_string(imageBytes) +
                     R"(},{"buffer":0,"byteOffset":)" + std::to_string(positions) +
                     R"(,"byteLength":36}],"accessors":[{"bufferView":1,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}],)"
                     R"("images":[{"bufferView":0,"mimeType":"image/png"}],"textures":[{"source":0}],)"
                     R"("materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0}}}],)"
                     R"("meshes":[{"primitives":[{"attributes":{"POSITION":0},"material":0}]}],)"
                     R"("nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}],"scene":0})";
  while (json.size() % 4) json.push_back(' ');
  std::string glb = "glTF";
  put32(glb, 2);
  put32(glb, std::uint32_t(12 + 8 + json.size() + 8 + bin.size()));
  put32(glb, std::uint32_t(json.size()));
  glb += "JSON";
  glb += json;
  put32(glb, std::uint32_t(bin.size()));
  glb += std::string("BIN\0", 4);
  glb += bin;
  return glb;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  try {
    radiant::io::decodeImage(bytes, "beauty", 64u << 20);
  } catch (const std::runtime_error&) {
  }
  radiant::LoadOptions options;
  options.maxBytes = 1u << 20;
  options.maxDecodedBytes = 64u << 20;
  try {
    radiant::loadSceneFromMemory(glbWithImage(bytes), options);
  } catch (const radiant::SceneError&) {
  }
  return 0;
}
