#pragma once
// Builds small glTF documents in tests: JSON plus one binary buffer, emitted as .gltf with a data
// URI, as .gltf with an external .bin, or as GLB. Also a minimal PNG encoder for texture tests.

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

namespace radiant::test {

using json = nlohmann::json;

inline std::string base64(std::string_view in) {
  static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  std::size_t i = 0;
  for (; i + 2 < in.size(); i += 3) {
    const std::uint32_t v = std::uint32_t(std::uint8_t(in[i])) << 16 |
                            std::uint32_t(std::uint8_t(in[i + 1])) << 8 | std::uint8_t(in[i + 2]);
    out += {k[v >> 18], k[(v >> 12) & 63], k[(v >> 6) & 63], k[v & 63]};
  }
  if (i + 1 == in.size()) {
    const std::uint32_t v = std::uint32_t(std::uint8_t(in[i])) << 16;
    out += {k[v >> 18], k[(v >> 12) & 63], '=', '='};
  } else if (i + 2 == in.size()) {
    const std::uint32_t v = std::uint32_t(std::uint8_t(in[i])) << 16 | std::uint32_t(std::uint8_t(in[i + 1])) << 8;
    out += {k[v >> 18], k[(v >> 12) & 63], k[(v >> 6) & 63], '='};
  }
  return out;
}

// A PNG of 8-bit RGBA texels (row 0 at the top), zlib "stored" blocks, no compression.
inline std::string encodePng(int w, int h, const std::vector<std::uint8_t>& rgba) {
  auto crcTable = [] {
    std::vector<std::uint32_t> t(256);
    for (std::uint32_t n = 0; n < 256; ++n) {
      std::uint32_t c = n;
      for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[n] = c;
    }
    return t;
  }();
  auto be32 = [](std::string& s, std::uint32_t v) {
    for (int i = 3; i >= 0; --i) s.push_back(char((v >> (8 * i)) & 255));
  };
  auto chunk = [&](std::string& out, const char* type, const std::string& data) {
    be32(out, std::uint32_t(data.size()));
    std::string td = std::string(type, 4) + data;
    std::uint32_t c = 0xFFFFFFFFu;
    for (unsigned char b : td) c = crcTable[(c ^ b) & 255] ^ (c >> 8);
    out += td;
    be32(out, c ^ 0xFFFFFFFFu);
  };
  std::string raw;
  for (int y = 0; y < h; ++y) {
    raw.push_back(0);  // filter: none
    raw.append(reinterpret_cast<const char*>(rgba.data()) + std::size_t(y) * w * 4, std::size_t(w) * 4);
  }
  std::string z = "\x78\x01";
  for (std::size_t at = 0; at < raw.size() || at == 0; at += 65535) {  // stored blocks of <= 65535 bytes
    const auto len = std::uint16_t(std::min<std::size_t>(65535, raw.size() - at));
    z.push_back(at + len >= raw.size() ? 1 : 0);  // BFINAL on the last block
    z.push_back(char(len & 255)); z.push_back(char(len >> 8));
    z.push_back(char(~len & 255)); z.push_back(char((~len >> 8) & 255));
    z += raw.substr(at, len);
    if (raw.empty()) break;
  }
  std::uint32_t a = 1, b = 0;
  for (unsigned char c : raw) { a = (a + c) % 65521; b = (b + a) % 65521; }
  be32(z, (b << 16) | a);
  std::string ihdr;
  be32(ihdr, std::uint32_t(w)); be32(ihdr, std::uint32_t(h));
  ihdr += {8, 6, 0, 0, 0};  // 8 bit, RGBA
  std::string png = "\x89PNG\r\n\x1a\n";
  chunk(png, "IHDR", ihdr);
  chunk(png, "IDAT", z);
  chunk(png, "IEND", "");
  return png;
}

class GltfBuilder {
public:
  json doc = {{"asset", {{"version", "2.0"}}}};
  std::string bin;

  int view(const void* data, std::size_t size, int byteStride = 0) {
    while (bin.size() % 4) bin.push_back('\0');
    json v = {{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", size}};
    if (byteStride) v["byteStride"] = byteStride;
    bin.append(static_cast<const char*>(data), size);
    return push("bufferViews", v);
  }
  int accessor(int bufferView, int componentType, std::size_t count, const char* type,
               std::size_t byteOffset = 0) {
    json a = {{"bufferView", bufferView}, {"componentType", componentType}, {"count", count}, {"type", type}};
    if (byteOffset) a["byteOffset"] = byteOffset;
    return push("accessors", a);
  }
  int vec3(const std::vector<glm::vec3>& v) {
    const int a = accessor(view(v.data(), v.size() * 12), 5126, v.size(), "VEC3");
    if (!v.empty()) {
      glm::vec3 lo = v[0], hi = v[0];
      for (const auto& p : v) { lo = glm::min(lo, p); hi = glm::max(hi, p); }
      doc["accessors"][a]["min"] = {lo.x, lo.y, lo.z};
      doc["accessors"][a]["max"] = {hi.x, hi.y, hi.z};
    }
    return a;
  }
  int vec2(const std::vector<glm::vec2>& v) { return accessor(view(v.data(), v.size() * 8), 5126, v.size(), "VEC2"); }
  int vec4(const std::vector<glm::vec4>& v) { return accessor(view(v.data(), v.size() * 16), 5126, v.size(), "VEC4"); }
  template <class T>
  int indices(const std::vector<T>& v) {
    const int type = sizeof(T) == 1 ? 5121 : sizeof(T) == 2 ? 5123 : 5125;
    return accessor(view(v.data(), v.size() * sizeof(T)), type, v.size(), "SCALAR");
  }
  int mesh(const json& primitives) { return push("meshes", {{"primitives", primitives}}); }
  int node(const json& n) { return push("nodes", n); }
  int material(const json& m) { return push("materials", m); }
  void scene(const std::vector<int>& roots) {
    doc["scenes"] = json::array({{{"nodes", roots}}});
    doc["scene"] = 0;
  }
  int push(const char* key, const json& value) {
    if (!doc.contains(key)) doc[key] = json::array();
    doc[key].push_back(value);
    return int(doc[key].size()) - 1;
  }

  // .gltf text with the buffer as a data URI.
  std::string gltf() const {
    json d = doc;
    if (!bin.empty())
      d["buffers"] = json::array({{{"byteLength", bin.size()},
                                   {"uri", "data:application/octet-stream;base64," + base64(bin)}}});
    return d.dump();
  }
  // .gltf text whose buffer is the external file `uri` (write `bin` there yourself).
  std::string gltfExternal(const std::string& uri) const {
    json d = doc;
    d["buffers"] = json::array({{{"byteLength", bin.size()}, {"uri", uri}}});
    return d.dump();
  }
  // EXT_meshopt_compression: `stream` (count x stride bytes compressed) goes into buffer 0 and a
  // bufferView on the uri-less fallback buffer 1 (which glb() then writes) points at it. `fields`
  // ("mode", "filter", or overrides of "byteStride", "count") are merged into the extension object;
  // the parent view gets byteStride too when `parentStride`.
  int meshoptView(const std::string& stream, std::size_t count, std::size_t stride, const json& fields,
                  bool parentStride = false) {
    const json& data = doc["bufferViews"][std::size_t(view(stream.data(), stream.size()))];
    json ext = {{"buffer", 0}, {"byteOffset", data["byteOffset"]}, {"byteLength", stream.size()},
                {"byteStride", stride}, {"count", count}};
    ext.update(fields);
    json v = {{"buffer", 1}, {"byteOffset", fallbackBytes}, {"byteLength", count * stride},
              {"extensions", {{"EXT_meshopt_compression", ext}}}};
    if (parentStride) v["byteStride"] = stride;
    fallbackBytes += (count * stride + 3) & ~std::size_t(3);
    doc["extensionsUsed"] = {"EXT_meshopt_compression"};
    doc["extensionsRequired"] = {"EXT_meshopt_compression"};
    return push("bufferViews", v);
  }
  std::size_t fallbackBytes = 0;  // the size of meshoptView()'s fallback buffer 1

  std::string glb() const {
    json d = doc;
    std::string b = bin;
    while (b.size() % 4) b.push_back('\0');
    if (!b.empty()) d["buffers"] = json::array({{{"byteLength", bin.size()}}});
    if (fallbackBytes)
      d["buffers"].push_back({{"byteLength", fallbackBytes}, {"extensions", {{"EXT_meshopt_compression", {{"fallback", true}}}}}});
    std::string j = d.dump();
    while (j.size() % 4) j.push_back(' ');
    std::string out;
    auto le32 = [&](std::uint32_t v) { for (int i = 0; i < 4; ++i) out.push_back(char((v >> (8 * i)) & 255)); };
    const std::size_t total = 12 + 8 + j.size() + (b.empty() ? 0 : 8 + b.size());
    out += "glTF";
    le32(2);
    le32(std::uint32_t(total));
    le32(std::uint32_t(j.size()));
    le32(0x4E4F534Au);
    out += j;
    if (!b.empty()) {
      le32(std::uint32_t(b.size()));
      le32(0x004E4942u);
      out += b;
    }
    return out;
  }
};

// A triangle mesh: positions, optional normals/uvs, indices of type T (or none when empty).
template <class T = std::uint16_t>
json trianglePrimitive(GltfBuilder& b, const std::vector<glm::vec3>& p, const std::vector<T>& idx,
                       const std::vector<glm::vec3>& n = {}, const std::vector<glm::vec2>& uv = {},
                       int material = -1) {
  json prim = {{"attributes", {{"POSITION", b.vec3(p)}}}};
  if (!n.empty()) prim["attributes"]["NORMAL"] = b.vec3(n);
  if (!uv.empty()) prim["attributes"]["TEXCOORD_0"] = b.vec2(uv);
  if (!idx.empty()) prim["indices"] = b.indices(idx);
  if (material >= 0) prim["material"] = material;
  return prim;
}

inline void writeFile(const std::filesystem::path& p, std::string_view bytes) {
  std::filesystem::create_directories(p.parent_path());
  std::ofstream(p, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
}

// A fresh empty directory under the system temp dir, removed at destruction.
struct TempDir {
  std::filesystem::path path;
  explicit TempDir(const std::string& name) {
    path = std::filesystem::temp_directory_path() /
           ("radiant_scene_test_" + name + "_" + std::to_string(::getpid()));
    std::filesystem::remove_all(path);
    std::filesystem::create_directories(path);
  }
  ~TempDir() { std::error_code ec; std::filesystem::remove_all(path, ec); }
};

// The unit right triangle in z = 0 and a scene with one node showing it: the smallest valid file.
inline const std::vector<glm::vec3> kTriangle = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
inline GltfBuilder triangle() {
  GltfBuilder b;
  const int m = b.mesh(json::array({trianglePrimitive<std::uint8_t>(b, kTriangle, {0, 1, 2})}));
  b.scene({b.node({{"mesh", m}})});
  return b;
}

}  // namespace radiant::test
