// libFuzzer: the request validator. Any input is either a RenderRequest or an api::ApiError with a
// 4xx status whose detail and pointer a strict JSON writer accepts; anything else (a crash, a
// sanitizer report, another exception, a 5xx) is a bug.
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "api/JsonLimits.h"
#include "api/Validate.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  radiant::api::RequestLimits limits;
  limits.maxOutputBytes = 512u << 20;
  try {
    radiant::api::parseRenderRequest(text, limits);
  } catch (const radiant::api::ApiError& e) {
    if (e.status < 400 || e.status >= 500) std::abort();
    if (!radiant::api::isValidUtf8(e.detail()) || !radiant::api::isValidUtf8(e.pointer)) std::abort();
    (void)nlohmann::json({{"detail", e.detail()}, {"pointer", e.pointer}}).dump();  // throws on bad UTF-8
  }
  return 0;
}
