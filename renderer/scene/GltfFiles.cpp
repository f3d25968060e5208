#include "renderer/scene/GltfFiles.h"

#include <algorithm>
#include <fstream>
#include <optional>

#include <webp/decode.h>

#include "renderer/scene/GltfExtensions.h"
#include "renderer/scene/GltfLimits.h"
#include "renderer/scene/GltfLoader.h"
#include "renderer/scene/GltfPackage.h"
#include "renderer/scene/GltfAccessors.h"

namespace radiant::gltf {

namespace fs = std::filesystem;
using json = nlohmann::json;

// ---- paths ---------------------------------------------------------------------------------

namespace {

bool isDataUri(std::string_view uri) { return uri.substr(0, 5) == "data:"; }

std::optional<fs::path> resolveInside(FsContext& ctx, const std::string& path) {
  if (ctx.root.empty()) {
    ctx.refused = "external files are disabled (no asset root)";
    return std::nullopt;
  }
  std::error_code ec;
  const fs::path canon = fs::weakly_canonical(fs::absolute(fs::path(path), ec), ec);
  if (ec || !pathIsInside(ctx.root, canon)) {
    ctx.refused = "\"" + path + "\" is outside the asset root";
    return std::nullopt;
  }
  return canon;
}

}  // namespace

bool fsFileExists(const std::string& path, void* user) {
  auto& ctx = *static_cast<FsContext*>(user);
  const auto p = resolveInside(ctx, path);
  std::error_code ec;
  return p && fs::is_regular_file(*p, ec);
}

std::string fsExpandFilePath(const std::string& path, void*) { return path; }

bool fsReadWholeFile(std::vector<unsigned char>* out, std::string* err, const std::string& path,
                     void* user) {
  auto& ctx = *static_cast<FsContext*>(user);
  const auto p = resolveInside(ctx, path);
  if (!p) {
    if (err) *err += ctx.refused;
    return false;
  }
  std::error_code ec;
  const auto size = fs::file_size(*p, ec);
  if (ec) {
    if (err) *err += "cannot stat " + p->string() + ": " + ec.message();
    return false;
  }
  if (size > ctx.budget) {
    if (err) *err += p->string() + " (" + std::to_string(size) + " bytes) exceeds the size limit";
    return false;
  }
  std::ifstream in(*p, std::ios::binary);
  out->resize(size);
  if (!in.read(reinterpret_cast<char*>(out->data()), std::streamsize(size))) {
    if (err) *err += "cannot read " + p->string();
    return false;
  }
  ctx.budget -= size;
  if (ctx.digest) {
    // Name (relative to the glTF's directory, so moving the root does not matter) and length
    // before the bytes, so the concatenation is unambiguous.
    const std::string rel = p->lexically_relative(ctx.baseDir).generic_string();
    ctx.digest->update(rel.data(), rel.size() + 1);  // includes the terminating NUL
    std::uint8_t len[8];
    for (int i = 0; i < 8; ++i) len[i] = std::uint8_t(std::uint64_t(size) >> (8 * i));
    ctx.digest->update(len, 8);
    ctx.digest->update(out->data(), out->size());
  }
  return true;
}

bool fsWriteWholeFile(std::string* err, const std::string&, const std::vector<unsigned char>&,
                      void*) {
  if (err) *err += "writing is not supported";
  return false;
}

// Every image's decoded size is charged against the scene's decode budget from its header, before
// stb_image allocates it (GltfLimits.h).
bool loadImageData(tinygltf::Image* image, const int index, std::string* err, std::string* warn,
                   int reqWidth, int reqHeight, const unsigned char* bytes, int size, void* user) {
  auto& budget = *static_cast<DecodeBudget*>(user);
  if (!budget.chargeImage(bytes, std::size_t(std::max(size, 0)), index, err)) return false;
  // EXT_texture_webp: libwebp decodes to 8-bit RGBA (the header, read above, was a still image).
  if (isWebp(bytes, std::size_t(std::max(size, 0)))) {
    int w = 0, h = 0;
    std::uint8_t* rgba = WebPDecodeRGBA(bytes, std::size_t(size), &w, &h);
    if (!rgba) {
      if (err) *err += "/images/" + std::to_string(index) + ": the WebP image could not be decoded\n";
      return false;
    }
    image->width = w;
    image->height = h;
    image->component = 4;
    image->bits = 8;
    image->pixel_type = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
    image->image.assign(rgba, rgba + std::size_t(w) * std::size_t(h) * 4);
    WebPFree(rgba);
    return true;
  }
  // nullptr options: expand every image to RGBA (8 or 16 bit per channel).
  return tinygltf::LoadImageData(image, index, err, warn, reqWidth, reqHeight, bytes, size, nullptr);
}

// ---- validation of the raw JSON, before tinygltf sees it -----------------------------------

namespace {

void checkExternalUri(const std::string& uri, const std::string& ptr, const fs::path& baseDir,
                      const fs::path& root) {
  if (root.empty())
    throw SceneError(ptr, "external URI \"" + uri +
                              "\" refused: no asset root is configured (upload one GLB: `radiant render "
                              "FILE.gltf` packs a .gltf and its files; or put the files under radiantd "
                              "--asset-root DIR and name the scene with scene.asset)");
  // The packer's check (GltfPackage.h): one definition of what a safe relative URI is.
  try {
    resolveRelativeUri(uri, ptr, baseDir, root);
  } catch (const PackError& e) {
    throw SceneError(e.pointer, e.what());
  }
}

std::uint64_t jsonUnsigned(const json& o, const char* key, std::uint64_t fallback) {
  const auto it = o.find(key);
  return it != o.end() && it->is_number_unsigned() ? it->get<std::uint64_t>() : fallback;
}

}  // namespace

void validateDocument(const json& doc, const fs::path& baseDir, const fs::path& root,
                      std::vector<std::string>& warnings) {
  if (!doc.is_object()) throw SceneError("", "a glTF document must be a JSON object");
  gltf::checkExtensions(doc, warnings);  // the extension table: GltfExtensions.cpp
  for (const char* key : {"buffers", "images"}) {
    const auto it = doc.find(key);
    if (it == doc.end() || !it->is_array()) continue;
    for (std::size_t i = 0; i < it->size(); ++i) {
      const auto& o = (*it)[i];
      if (!o.is_object()) continue;
      const auto uri = o.find("uri");
      if (uri == o.end() || !uri->is_string()) continue;
      const std::string s = uri->get<std::string>();
      if (!isDataUri(s)) checkExternalUri(s, pointer(std::string("/") + key, i) + "/uri", baseDir, root);
    }
  }
  // Buffer views against the declared buffer sizes (tinygltf checks that each buffer really has
  // byteLength bytes, but not that the views stay inside it).
  const auto buffers = doc.find("buffers");
  const auto views = doc.find("bufferViews");
  if (views != doc.end() && views->is_array()) {
    for (std::size_t i = 0; i < views->size(); ++i) {
      const auto& v = (*views)[i];
      if (!v.is_object()) continue;
      const std::uint64_t b = jsonUnsigned(v, "buffer", ~0ull);
      if (buffers == doc.end() || !buffers->is_array() || b >= buffers->size())
        throw SceneError(pointer("/bufferViews", i) + "/buffer",
                         "bufferView " + std::to_string(i) + " names a buffer that does not exist");
      const std::uint64_t off = jsonUnsigned(v, "byteOffset", 0), len = jsonUnsigned(v, "byteLength", 0);
      const std::uint64_t have = jsonUnsigned((*buffers)[b], "byteLength", 0);
      if (off > have || len > have - off)
        throw SceneError(pointer("/bufferViews", i),
                         "bufferView " + std::to_string(i) + " spans bytes [" + std::to_string(off) +
                             ", " + std::to_string(off + len) + ") but buffer " + std::to_string(b) +
                             " has " + std::to_string(have) + " bytes");
    }
  }
}

namespace {
std::uint32_t le32(const char* p) {
  const auto* u = reinterpret_cast<const unsigned char*>(p);
  return std::uint32_t(u[0]) | std::uint32_t(u[1]) << 8 | std::uint32_t(u[2]) << 16 | std::uint32_t(u[3]) << 24;
}
}  // namespace

// The JSON chunk of a GLB, after checking the header and chunk lengths against the bytes we have
// (glTF spec 4.4, "Binary glTF Layout").
std::string_view glbJson(std::string_view bytes) {
  if (bytes.size() < 20)
    throw SceneError("", "truncated GLB: " + std::to_string(bytes.size()) +
                             " bytes, shorter than the 12-byte header and a chunk header");
  const std::uint32_t version = le32(bytes.data() + 4), length = le32(bytes.data() + 8);
  if (version != 2)
    throw SceneError("", "GLB version " + std::to_string(version) + " is not supported (only 2)");
  if (length > bytes.size())
    throw SceneError("", "truncated GLB: the header declares " + std::to_string(length) +
                             " bytes but only " + std::to_string(bytes.size()) + " are present");
  const std::uint32_t jsonLength = le32(bytes.data() + 12), jsonType = le32(bytes.data() + 16);
  if (jsonType != 0x4E4F534Au)
    throw SceneError("", "invalid GLB: the first chunk is not JSON");
  if (std::uint64_t(jsonLength) + 20 > length)
    throw SceneError("", "truncated GLB: the JSON chunk declares " + std::to_string(jsonLength) +
                             " bytes but the file ends after " + std::to_string(length - 20));
  return bytes.substr(20, jsonLength);
}

}  // namespace radiant::gltf
