#pragma once
// Guards for JSON that comes from outside (render requests, glTF documents), applied BEFORE any
// recursive code sees the text, and for text on its way into a JSON writer or a log line.
//
// - scanJson(): one pass over the bytes with an explicit stack (no recursion, O(n) time, memory
//   bounded by the depth limit), finding the three inputs that nlohmann::json and tinygltf turn into
//   crashes or 500s: nesting deeper than a limit (recursive copy/validation overflows the stack),
//   invalid UTF-8 in a string (dump() throws), and numbers that overflow a double (parse throws
//   out_of_range 406). Each problem comes with the JSON pointer of the value and its byte offset.
//   It is not a full JSON validator: syntax errors are left to the real parser.
// - sanitizeUtf8() / truncateUtf8() / dumpSafe(): text reaching a writer is valid UTF-8, and a
//   shortened string never ends in the middle of a code point.

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace radiant::api {

// The default nesting limit of requests and glTF documents (radiantd --max-json-depth).
inline constexpr std::size_t kDefaultMaxJsonDepth = 64;

struct JsonScanProblem {
  enum class Kind { TooDeep, InvalidUtf8, NumberOverflow };
  Kind kind;
  std::string pointer;     // RFC 6901 pointer of the offending value (or key)
  std::size_t byte = 0;    // offset of the offending byte in the text
  std::string detail;      // human-readable, valid UTF-8, names the pointer
};

// nullopt when the text has none of the problems above (it may still be malformed JSON).
// A document nested exactly maxDepth containers deep passes; maxDepth + 1 is refused.
std::optional<JsonScanProblem> scanJson(std::string_view text, std::size_t maxDepth);

// Depth of an already parsed value (a scalar is 0, [] is 1), computed without recursion; stops
// counting at stopAt + 1, so the cost is bounded for huge documents.
std::size_t jsonDepth(const nlohmann::json& value, std::size_t stopAt);

// Length of the valid UTF-8 prefix of `s` (s.size() when all of it is valid). Overlong forms,
// surrogates and code points above U+10FFFF are invalid (RFC 3629).
std::size_t validUtf8Prefix(std::string_view s);
inline bool isValidUtf8(std::string_view s) { return validUtf8Prefix(s) == s.size(); }

// Every invalid byte replaced by U+FFFD.
std::string sanitizeUtf8(std::string_view s);

// At most maxBytes bytes of `s`, cut at a code-point boundary, "..." appended when shortened
// (the result, with the dots, is at most maxBytes + 3 bytes).
std::string truncateUtf8(std::string_view s, std::size_t maxBytes);

// json::dump() that never throws on invalid UTF-8 (bad bytes become U+FFFD).
std::string dumpSafe(const nlohmann::json& value, int indent = -1);

}  // namespace radiant::api
