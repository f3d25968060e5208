#pragma once
// Base64 (RFC 4648 §4, the standard alphabet with '=' padding), the one codec of the project: inline
// GLB scenes in requests (server), data URIs in glTF files (renderer/scene/GltfPackage), and PNG data
// URIs in the client's offline HTML reports.
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

namespace radiant::api {

std::string base64Encode(std::string_view bytes);

// The bytes of `text`, or nullopt with *badIndex set to the offset of the first character outside
// the alphabet. Decoding stops at the first '='; CR and LF are skipped (MIME line breaks).
std::optional<std::string> base64Decode(std::string_view text, std::size_t* badIndex = nullptr);

}  // namespace radiant::api
