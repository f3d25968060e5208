// libFuzzer: the glTF/GLB loader with its limits. Any input loads or throws SceneError; a crash, a
// sanitizer report or any other exception is a bug. The decode budget is small so that inputs
// cannot make the fuzzer itself run out of memory (which would hide real findings).
#include <cstdint>
#include <string_view>

#include "renderer/scene/GltfLoader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  radiant::LoadOptions options;
  options.maxBytes = 1u << 20;
  options.maxDecodedBytes = 64u << 20;
  try {
    radiant::loadSceneFromMemory(std::string_view(reinterpret_cast<const char*>(data), size), options);
  } catch (const radiant::SceneError&) {
  }
  return 0;
}
