#include "renderer/scene/GltfPackage.h"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <optional>
#include <vector>

#include <nlohmann/json.hpp>

#include "api/Base64.h"

namespace radiant {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

std::string percentDecode(std::string_view s) {
  auto hex = [](char c) -> int {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
  };
  std::string out;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '%' && i + 2 < s.size() && hex(s[i + 1]) >= 0 && hex(s[i + 2]) >= 0) {
      out.push_back(char(hex(s[i + 1]) * 16 + hex(s[i + 2])));
      i += 2;
    } else {
      out.push_back(s[i]);
    }
  }
  return out;
}

bool isDataUri(std::string_view uri) { return uri.substr(0, 5) == "data:"; }

// RFC 2397 data URI with base64 payload -> bytes.
std::string decodeDataUri(const std::string& uri, const std::string& pointer) {
  const auto comma = uri.find(',');
  if (comma == std::string::npos || comma < 7 || uri.compare(comma - 7, 7, ";base64") != 0)
    throw PackError(pointer, "data URI refused: only base64 data URIs are supported");
  std::size_t bad = 0;
  std::optional<std::string> bytes = api::base64Decode(std::string_view(uri).substr(comma + 1), &bad);
  if (!bytes)
    throw PackError(pointer, "data URI is not valid base64 (byte " + std::to_string(comma + 1 + bad) + ")");
  return std::move(*bytes);
}

std::uint32_t le32(const char* p) {
  const auto* u = reinterpret_cast<const unsigned char*>(p);
  return std::uint32_t(u[0]) | std::uint32_t(u[1]) << 8 | std::uint32_t(u[2]) << 16 | std::uint32_t(u[3]) << 24;
}

void put32(std::string& s, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) s.push_back(char((v >> (8 * i)) & 255));
}

// The image's media type from its first bytes (glTF 2.0 allows PNG and JPEG; extensions add KTX2, WebP).
std::string sniffMime(const std::string& b, const fs::path& file) {
  if (b.size() >= 8 && b.compare(0, 8, "\x89PNG\r\n\x1a\n") == 0) return "image/png";
  if (b.size() >= 3 && static_cast<unsigned char>(b[0]) == 0xFF && static_cast<unsigned char>(b[1]) == 0xD8) return "image/jpeg";
  if (b.size() >= 12 && b.compare(0, 4, "RIFF") == 0 && b.compare(8, 4, "WEBP") == 0) return "image/webp";
  if (b.size() >= 12 && b.compare(0, 12, "\xABKTX 20\xBB\r\n\x1a\n") == 0) return "image/ktx2";
  std::string ext = file.extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".png") return "image/png";
  if (ext == ".jpg" || ext == ".jpeg") return "image/jpeg";
  return "application/octet-stream";
}

struct Reader {
  fs::path baseDir, root;
  std::size_t budget;
  std::size_t files = 0;
  std::string read(const std::string& uri, const std::string& pointer) {
    const fs::path p = resolveRelativeUri(uri, pointer, baseDir, root);
    std::error_code ec;
    if (!fs::is_regular_file(p, ec))
      throw PackError(pointer, "URI \"" + uri + "\": " + p.string() + " does not exist or is not a regular file");
    const auto size = fs::file_size(p, ec);
    if (ec) throw PackError(pointer, "URI \"" + uri + "\": cannot stat " + p.string() + ": " + ec.message());
    if (size > budget)
      throw PackError(pointer, "URI \"" + uri + "\": " + p.string() + " (" + std::to_string(size) +
                                   " bytes) is over the size limit of the packed scene");
    std::ifstream in(p, std::ios::binary);
    std::string bytes(size, '\0');
    if (!in.read(bytes.data(), std::streamsize(size)))
      throw PackError(pointer, "URI \"" + uri + "\": cannot read " + p.string());
    budget -= size;
    ++files;
    return bytes;
  }
};

bool hasExternalUri(const json& doc) {
  for (const char* key : {"buffers", "images"}) {
    const auto it = doc.find(key);
    if (it == doc.end() || !it->is_array()) continue;
    for (const auto& o : *it)
      if (o.is_object() && o.contains("uri") && o["uri"].is_string() && !isDataUri(o["uri"].get<std::string>()))
        return true;
  }
  return false;
}

}  // namespace

bool pathIsInside(const fs::path& root, const fs::path& p) {
  auto r = root.begin();
  auto q = p.begin();
  for (; r != root.end(); ++r, ++q) {
    if (r->empty()) continue;  // trailing separator
    if (q == p.end() || *r != *q) return false;
  }
  return true;
}

fs::path resolveRelativeUri(const std::string& uri, const std::string& ptr, const fs::path& baseDir,
                            const fs::path& root) {
  // A scheme is letters, digits, + - . followed by ':' (RFC 3986 section 3.1).
  const auto colon = uri.find(':');
  if (colon != std::string::npos && colon > 0 && std::isalpha(static_cast<unsigned char>(uri[0])) &&
      std::all_of(uri.begin(), uri.begin() + long(colon), [](char c) {
        return std::isalnum(static_cast<unsigned char>(c)) || c == '+' || c == '-' || c == '.';
      }))
    throw PackError(ptr, "URI \"" + uri + "\" refused: only data: URIs and relative file paths are supported (scheme \"" +
                             uri.substr(0, colon) + ":\")");
  const std::string path = percentDecode(uri);
  if (path.find('\0') != std::string::npos) throw PackError(ptr, "URI \"" + uri + "\" refused: it contains a NUL byte");
  if (path.empty()) throw PackError(ptr, "URI \"\" refused: the path is empty");
  if (path[0] == '/' || path[0] == '\\' || fs::path(path).is_absolute())
    throw PackError(ptr, "URI \"" + uri + "\" refused: absolute paths are not allowed (use a path relative to the .gltf)");
  std::size_t start = 0;
  while (start <= path.size()) {
    const std::size_t end = std::min(path.find_first_of("/\\", start), path.size());
    if (path.compare(start, end - start, "..") == 0)
      throw PackError(ptr, "URI \"" + uri + "\" refused: \"..\" is not allowed in paths (only files inside the "
                               "folder of the .gltf are packed)");
    start = end + 1;
  }
  std::error_code ec;
  const fs::path resolved = fs::weakly_canonical(baseDir / path, ec);
  if (ec || !pathIsInside(root, resolved))
    throw PackError(ptr, "URI \"" + uri + "\" refused: it resolves to " + resolved.string() + ", outside the asset root " +
                             root.string());
  return resolved;
}

PackResult packGltf(std::string_view bytes, const fs::path& baseDir, const fs::path& root, std::size_t maxBytes,
                    bool force) {
  const bool glb = bytes.size() >= 4 && bytes.substr(0, 4) == "glTF";
  std::string_view jsonText = bytes, bin;
  bool hasBin = false;
  if (glb) {
    if (bytes.size() < 20) throw PackError("", "truncated GLB (" + std::to_string(bytes.size()) + " bytes)");
    const std::uint32_t length = std::min<std::uint64_t>(le32(bytes.data() + 8), bytes.size());
    const std::uint32_t jsonLength = le32(bytes.data() + 12);
    if (std::uint64_t(jsonLength) + 20 > length) throw PackError("", "truncated GLB: the JSON chunk overruns the file");
    jsonText = bytes.substr(20, jsonLength);
    const std::size_t binHeader = 20 + ((jsonLength + 3) & ~3u);
    if (binHeader + 8 <= length && le32(bytes.data() + binHeader + 4) == 0x004E4942u) {
      const std::uint32_t binLength = le32(bytes.data() + binHeader);
      if (binHeader + 8 + std::uint64_t(binLength) > length) throw PackError("", "truncated GLB: the BIN chunk overruns the file");
      bin = bytes.substr(binHeader + 8, binLength);
      hasBin = true;
    }
  }
  json doc = json::parse(jsonText, nullptr, false);
  if (doc.is_discarded() || !doc.is_object())
    throw PackError("", std::string(glb ? "the GLB JSON chunk" : "the file") + " is not a glTF JSON object");
  PackResult result;
  if (!force && !hasExternalUri(doc)) {
    result.bytes = std::string(bytes);
    return result;
  }

  Reader reader{baseDir, root, maxBytes};
  std::string newBin;
  json newBuffers = json::array();
  newBuffers.push_back(json::object());  // 0: the BIN chunk, byteLength filled in below
  auto append = [&](std::string_view data) {
    newBin.resize((newBin.size() + 15) & ~std::size_t(15), '\0');
    const std::size_t offset = newBin.size();
    newBin.append(data);
    return offset;
  };
  // Old buffer index -> (new buffer index, byte offset in it).
  std::vector<std::pair<std::size_t, std::size_t>> where;
  if (doc.contains("buffers") && doc["buffers"].is_array()) {
    json& buffers = doc["buffers"];
    for (std::size_t i = 0; i < buffers.size(); ++i) {
      json& b = buffers[i];
      const std::string ptr = "/buffers/" + std::to_string(i);
      if (!b.is_object()) throw PackError(ptr, "a buffer must be an object");
      if (b.contains("uri") && b["uri"].is_string()) {
        const std::string uri = b["uri"];
        const std::string data = isDataUri(uri) ? decodeDataUri(uri, ptr + "/uri") : reader.read(uri, ptr + "/uri");
        where.emplace_back(0, append(data));
      } else if (glb && i == 0 && hasBin) {
        where.emplace_back(0, append(bin));
      } else {
        // No data of its own (an EXT_meshopt_compression fallback buffer): kept as it is.
        json kept = b;
        kept.erase("uri");
        newBuffers.push_back(kept);
        where.emplace_back(newBuffers.size() - 1, 0);
      }
    }
  }
  auto rebase = [&](json& o, const std::string& ptr) {
    if (!o.is_object() || !o.contains("buffer") || !o["buffer"].is_number_unsigned()) return;
    const std::size_t b = o["buffer"].get<std::size_t>();
    if (b >= where.size()) throw PackError(ptr + "/buffer", "buffer " + std::to_string(b) + " does not exist");
    o["buffer"] = where[b].first;
    const std::uint64_t offset = o.contains("byteOffset") && o["byteOffset"].is_number_unsigned()
                                     ? o["byteOffset"].get<std::uint64_t>() : 0;
    o["byteOffset"] = offset + where[b].second;
  };
  if (doc.contains("bufferViews") && doc["bufferViews"].is_array()) {
    json& views = doc["bufferViews"];
    for (std::size_t i = 0; i < views.size(); ++i) {
      const std::string ptr = "/bufferViews/" + std::to_string(i);
      rebase(views[i], ptr);
      if (views[i].is_object() && views[i].contains("extensions") && views[i]["extensions"].is_object() &&
          views[i]["extensions"].contains("EXT_meshopt_compression"))
        rebase(views[i]["extensions"]["EXT_meshopt_compression"], ptr + "/extensions/EXT_meshopt_compression");
    }
  } else {
    doc["bufferViews"] = json::array();
  }
  if (doc.contains("images") && doc["images"].is_array()) {
    json& images = doc["images"];
    for (std::size_t i = 0; i < images.size(); ++i) {
      json& img = images[i];
      if (!img.is_object() || !img.contains("uri") || !img["uri"].is_string()) continue;
      const std::string uri = img["uri"];
      if (isDataUri(uri)) continue;
      const std::string ptr = "/images/" + std::to_string(i) + "/uri";
      const std::string data = reader.read(uri, ptr);
      const std::size_t offset = append(data);
      doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", data.size()}});
      img.erase("uri");
      img["bufferView"] = doc["bufferViews"].size() - 1;
      if (!img.contains("mimeType")) img["mimeType"] = sniffMime(data, percentDecode(uri));
    }
  }
  newBin.resize((newBin.size() + 3) & ~std::size_t(3), '\0');
  newBuffers[0]["byteLength"] = newBin.size();
  doc["buffers"] = newBuffers;

  std::string text = doc.dump();
  text.resize((text.size() + 3) & ~std::size_t(3), ' ');
  std::string out;
  out.reserve(28 + text.size() + newBin.size());
  out += "glTF";
  put32(out, 2);
  put32(out, std::uint32_t(12 + 8 + text.size() + 8 + newBin.size()));
  put32(out, std::uint32_t(text.size()));
  put32(out, 0x4E4F534Au);  // "JSON"
  out += text;
  put32(out, std::uint32_t(newBin.size()));
  put32(out, 0x004E4942u);  // "BIN\0"
  out += newBin;
  result.bytes = std::move(out);
  result.externalFiles = reader.files;
  result.packed = true;
  return result;
}

PackResult packGltfFile(const fs::path& file, const fs::path& rootIn, std::size_t maxBytes) {
  std::error_code ec;
  const fs::path canon = fs::weakly_canonical(fs::absolute(file, ec), ec);
  if (ec || !fs::exists(canon)) throw PackError("", file.string() + " does not exist", PackError::Kind::Missing);
  if (!fs::is_regular_file(canon))
    throw PackError("", file.string() + " is not a regular file (a directory, FIFO or device)", PackError::Kind::NotRegular);
  fs::path root = rootIn.empty() ? canon.parent_path() : fs::canonical(rootIn, ec);
  if (ec) throw PackError("", "the root " + rootIn.string() + " does not exist", PackError::Kind::Missing);
  if (!pathIsInside(root, canon)) throw PackError("", file.string() + " is outside " + root.string(), PackError::Kind::Missing);
  const auto size = fs::file_size(canon, ec);
  if (ec) throw PackError("", file.string() + ": " + ec.message(), PackError::Kind::Missing);
  if (size > maxBytes)
    throw PackError("", file.string() + " is " + std::to_string(size) + " bytes, over the size limit of " +
                            std::to_string(maxBytes) + " bytes",
                    PackError::Kind::TooLarge);
  std::ifstream in(canon, std::ios::binary);
  std::string bytes(size, '\0');
  if (!in.read(bytes.data(), std::streamsize(size))) throw PackError("", "cannot read " + file.string());
  return packGltf(bytes, canon.parent_path(), root, maxBytes - size);
}

}  // namespace radiant
