#include "api/JsonLimits.h"

#include <cmath>
#include <cstdlib>
#include <vector>

namespace radiant::api {

using nlohmann::json;

namespace {

// Length of the valid UTF-8 sequence starting at s[i], or 0 when the byte there starts none
// (RFC 3629 table 3-7 of Unicode: the second byte's range depends on the first).
std::size_t utf8SequenceLength(std::string_view s, std::size_t i) {
  const auto b = [&](std::size_t k) { return static_cast<unsigned char>(s[k]); };
  const unsigned char c = b(i);
  if (c < 0x80) return 1;
  std::size_t n = 0;
  unsigned char lo = 0x80, hi = 0xBF;
  if (c >= 0xC2 && c <= 0xDF) n = 2;
  else if (c == 0xE0) { n = 3; lo = 0xA0; }
  else if (c >= 0xE1 && c <= 0xEC) n = 3;
  else if (c == 0xED) { n = 3; hi = 0x9F; }  // no UTF-16 surrogates
  else if (c >= 0xEE && c <= 0xEF) n = 3;
  else if (c == 0xF0) { n = 4; lo = 0x90; }
  else if (c >= 0xF1 && c <= 0xF3) n = 4;
  else if (c == 0xF4) { n = 4; hi = 0x8F; }  // nothing above U+10FFFF
  else return 0;
  if (i + n > s.size()) return 0;
  if (b(i + 1) < lo || b(i + 1) > hi) return 0;
  for (std::size_t k = 2; k < n; ++k)
    if (b(i + k) < 0x80 || b(i + k) > 0xBF) return 0;
  return n;
}

std::string escapeToken(std::string_view key) {
  std::string out;
  for (char c : key) {
    if (c == '~') out += "~0";
    else if (c == '/') out += "~1";
    else out += c;
  }
  return out;
}

void appendUtf8(std::string& out, unsigned cp) {
  if (cp < 0x80) out += char(cp);
  else if (cp < 0x800) { out += char(0xC0 | cp >> 6); out += char(0x80 | (cp & 63)); }
  else { out += char(0xE0 | cp >> 12); out += char(0x80 | (cp >> 6 & 63)); out += char(0x80 | (cp & 63)); }
}

// An object key as the pointer token it names: JSON escapes decoded (a \u escape of a surrogate
// becomes U+FFFD: the pointer is for people, not for lookups), invalid bytes replaced.
std::string decodeKey(std::string_view raw) {
  std::string out;
  for (std::size_t i = 0; i < raw.size(); ++i) {
    if (raw[i] != '\\' || i + 1 >= raw.size()) { out += raw[i]; continue; }
    const char e = raw[++i];
    switch (e) {
      case 'b': out += '\b'; break;
      case 'f': out += '\f'; break;
      case 'n': out += '\n'; break;
      case 'r': out += '\r'; break;
      case 't': out += '\t'; break;
      case 'u': {
        unsigned cp = 0;
        bool ok = i + 4 < raw.size();
        for (int k = 1; ok && k <= 4; ++k) {
          const char h = raw[i + std::size_t(k)];
          cp = cp * 16 + unsigned(h >= '0' && h <= '9' ? h - '0' : h >= 'a' && h <= 'f' ? h - 'a' + 10
                                                           : h >= 'A' && h <= 'F' ? h - 'A' + 10 : (ok = false, 0));
        }
        if (!ok) { out += "\\u"; break; }
        i += 4;
        appendUtf8(out, cp >= 0xD800 && cp <= 0xDFFF ? 0xFFFD : cp);
        break;
      }
      default: out += e;  // \" \\ \/ and anything the parser will refuse anyway
    }
  }
  return sanitizeUtf8(out);
}

struct Frame {
  bool array = false;
  std::size_t index = 0;    // arrays: index of the current element
  std::string key;          // objects: the current key
  bool expectKey = true;    // objects: the next string is a key
};

std::string pointerOf(const std::vector<Frame>& stack) {
  std::string p;
  for (const auto& f : stack) p += "/" + (f.array ? std::to_string(f.index) : escapeToken(f.key));
  return p;
}

std::string shownPointer(const std::string& p) { return p.empty() ? "the document" : p; }

}  // namespace

std::size_t validUtf8Prefix(std::string_view s) {
  std::size_t i = 0;
  while (i < s.size()) {
    const std::size_t n = utf8SequenceLength(s, i);
    if (n == 0) return i;
    i += n;
  }
  return i;
}

std::string sanitizeUtf8(std::string_view s) {
  std::string out;
  out.reserve(s.size());
  std::size_t i = 0;
  while (i < s.size()) {
    const std::size_t n = utf8SequenceLength(s, i);
    if (n == 0) {
      out += "\xEF\xBF\xBD";
      ++i;
    } else {
      out.append(s.substr(i, n));
      i += n;
    }
  }
  return out;
}

std::string truncateUtf8(std::string_view s, std::size_t maxBytes) {
  std::string clean = sanitizeUtf8(s);
  if (clean.size() <= maxBytes) return clean;
  std::size_t cut = maxBytes;
  // Step back over continuation bytes so the cut falls before a lead byte.
  while (cut > 0 && (static_cast<unsigned char>(clean[cut]) & 0xC0) == 0x80) --cut;
  return clean.substr(0, cut) + "...";
}

std::string dumpSafe(const json& value, int indent) {
  return value.dump(indent, ' ', false, json::error_handler_t::replace);
}

std::optional<JsonScanProblem> scanJson(std::string_view text, std::size_t maxDepth) {
  std::vector<Frame> stack;
  const std::size_t n = text.size();
  // A value has been read inside the innermost object: the next string is a key after a ','.
  auto afterValue = [&] {
    if (!stack.empty() && !stack.back().array) stack.back().expectKey = false;
  };
  for (std::size_t i = 0; i < n;) {
    const char c = text[i];
    switch (c) {
      case '[':
      case '{': {
        if (stack.size() >= maxDepth)
          return JsonScanProblem{JsonScanProblem::Kind::TooDeep, pointerOf(stack), i,
                                 shownPointer(pointerOf(stack)) + ": nested deeper than " +
                                     std::to_string(maxDepth) + " levels (byte " + std::to_string(i) + ")"};
        stack.push_back(Frame{c == '[', 0, {}, true});
        ++i;
        break;
      }
      case ']':
      case '}':
        if (!stack.empty()) stack.pop_back();
        afterValue();
        ++i;
        break;
      case ',':
        if (!stack.empty()) {
          if (stack.back().array) ++stack.back().index;
          else stack.back().expectKey = true;
        }
        ++i;
        break;
      case '"': {
        const std::size_t start = ++i;
        while (i < n && text[i] != '"') i += text[i] == '\\' ? 2 : 1;
        const std::string_view body = text.substr(start, std::min(i, n) - start);
        const bool isKey = !stack.empty() && !stack.back().array && stack.back().expectKey;
        if (isKey) stack.back().key = decodeKey(body);
        const std::size_t valid = validUtf8Prefix(body);
        if (valid != body.size()) {
          const std::string p = pointerOf(stack);
          return JsonScanProblem{JsonScanProblem::Kind::InvalidUtf8, p, start + valid,
                                 shownPointer(p) + ": " + (isKey ? "a key" : "a string") +
                                     " is not valid UTF-8 (byte " + std::to_string(start + valid) + ")"};
        }
        if (isKey) stack.back().expectKey = false;  // the value follows the ':'
        else afterValue();
        i = std::min(i + 1, n);
        break;
      }
      case '-':
      case '0': case '1': case '2': case '3': case '4':
      case '5': case '6': case '7': case '8': case '9': {
        const std::size_t start = i;
        bool simple = true;  // short integers cannot overflow a double
        while (i < n && (std::isdigit(static_cast<unsigned char>(text[i])) || text[i] == '-' || text[i] == '+' ||
                         text[i] == '.' || text[i] == 'e' || text[i] == 'E')) {
          if (text[i] == 'e' || text[i] == 'E') simple = false;
          ++i;
        }
        if (!simple || i - start > 300) {
          const std::string token(text.substr(start, i - start));
          const double v = std::strtod(token.c_str(), nullptr);
          if (std::isinf(v)) {
            const std::string p = pointerOf(stack);
            return JsonScanProblem{JsonScanProblem::Kind::NumberOverflow, p, start,
                                   shownPointer(p) + ": " + truncateUtf8(token, 40) +
                                       " is too large for a double-precision number"};
          }
        }
        afterValue();
        break;
      }
      default:
        // true/false/null, whitespace, ':' and anything the parser will refuse.
        if (c == 't' || c == 'f' || c == 'n') {
          while (i < n && std::isalpha(static_cast<unsigned char>(text[i]))) ++i;
          afterValue();
        } else {
          ++i;
        }
    }
  }
  return std::nullopt;
}

std::size_t jsonDepth(const json& value, std::size_t stopAt) {
  std::size_t deepest = 0;
  std::vector<std::pair<const json*, std::size_t>> todo{{&value, 0}};
  while (!todo.empty()) {
    const auto [v, depth] = todo.back();
    todo.pop_back();
    if (!v->is_structured()) continue;
    deepest = std::max(deepest, depth + 1);
    if (deepest > stopAt) return deepest;
    for (const auto& child : *v) todo.emplace_back(&child, depth + 1);
  }
  return deepest;
}

}  // namespace radiant::api
