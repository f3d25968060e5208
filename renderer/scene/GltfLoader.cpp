#include "renderer/scene/GltfLoader.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <numeric>
#include <optional>

#include <glm/gtc/matrix_inverse.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <nlohmann/json.hpp>
#include <tiny_gltf.h>  // Debian ships tinygltf as a shared library: no TINYGLTF_IMPLEMENTATION here
#include <webp/decode.h>

#include "api/Media.h"
#include "api/Types.h"
#include "api/Validate.h"
#include "renderer/scene/GltfCompression.h"
#include "renderer/scene/GltfExtensions.h"
#include "renderer/scene/GltfPackage.h"
#include "renderer/scene/GltfLimits.h"
#include "renderer/scene/MikkTSpace.h"

namespace radiant {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

std::string pointer(std::string_view base, std::size_t index) {
  return std::string(base) + "/" + std::to_string(index);
}

std::string primitivePointer(int mesh, int prim) {
  return "/meshes/" + std::to_string(mesh) + "/primitives/" + std::to_string(prim);
}

// ---- paths ---------------------------------------------------------------------------------

// True when `p` equals `root` or lies below it; both must be canonical.

bool isDataUri(std::string_view uri) { return uri.substr(0, 5) == "data:"; }

// Reads, for tinygltf, only regular files inside the asset root, within the byte budget. The
// URIs were already checked (checkExternalUri); this is the second line of defence, applied to
// the exact path tinygltf is about to open (it also probes paths relative to the working directory).
struct FsContext {
  fs::path root;     // canonical; empty = no external files
  fs::path baseDir;  // canonical directory URIs are relative to (names files in the digest)
  std::size_t budget = 0;
  api::Sha256* digest = nullptr;
  std::string refused;  // why the last path was refused, for the error message
};

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

// ---- accessors ------------------------------------------------------------------------------

std::string describeAccessor(int index, const std::string& what) {
  return "accessor " + std::to_string(index) + (what.empty() ? "" : " (" + what + ")");
}

// Converts one component to float, with glTF's normalisation rules (spec 3.11, "Animations" table
// and KHR_mesh_quantization): c / (2^n - 1) for unsigned, max(c / (2^(n-1) - 1), -1) for signed.
float readComponent(const unsigned char* p, int componentType, bool normalized) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: { float f; std::memcpy(&f, p, 4); return f; }
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      const auto c = static_cast<std::int8_t>(*p);
      return normalized ? std::max(c / 127.f, -1.f) : float(c);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return normalized ? *p / 255.f : float(*p);
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      std::int16_t c; std::memcpy(&c, p, 2);
      return normalized ? std::max(c / 32767.f, -1.f) : float(c);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      std::uint16_t c; std::memcpy(&c, p, 2);
      return normalized ? c / 65535.f : float(c);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
      std::uint32_t c; std::memcpy(&c, p, 4);
      return normalized ? float(double(c) / 4294967295.0) : float(c);
    }
    default: return 0.f;
  }
}

std::uint32_t readIndex(const unsigned char* p, int componentType) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return *p;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: { std::uint16_t c; std::memcpy(&c, p, 2); return c; }
    default: { std::uint32_t c; std::memcpy(&c, p, 4); return c; }
  }
}

int componentSize(int componentType) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
    default: return 0;
  }
}

const char* typeName(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR: return "SCALAR";
    case TINYGLTF_TYPE_VEC2: return "VEC2";
    case TINYGLTF_TYPE_VEC3: return "VEC3";
    case TINYGLTF_TYPE_VEC4: return "VEC4";
    case TINYGLTF_TYPE_MAT2: return "MAT2";
    case TINYGLTF_TYPE_MAT3: return "MAT3";
    case TINYGLTF_TYPE_MAT4: return "MAT4";
    default: return "unknown";
  }
}

// A checked window into a buffer view: `count` elements of `elementSize` bytes, `stride` apart.
struct Strided {
  const unsigned char* base = nullptr;
  std::size_t stride = 0;
};

Strided checkedView(const tinygltf::Model& model, int viewIndex, std::size_t byteOffset,
                    std::size_t count, std::size_t elementSize, bool allowStride,
                    const std::string& ptr, const std::string& what) {
  if (viewIndex < 0 || std::size_t(viewIndex) >= model.bufferViews.size())
    throw SceneError(ptr + "/bufferView", what + " names bufferView " + std::to_string(viewIndex) +
                                              ", which does not exist");
  const auto& view = model.bufferViews[std::size_t(viewIndex)];
  const std::string viewPtr = pointer("/bufferViews", std::size_t(viewIndex));
  if (view.buffer < 0 || std::size_t(view.buffer) >= model.buffers.size())
    throw SceneError(viewPtr + "/buffer", "bufferView " + std::to_string(viewIndex) +
                                              " names a buffer that does not exist");
  const auto& buffer = model.buffers[std::size_t(view.buffer)];
  if (view.byteOffset > buffer.data.size() || view.byteLength > buffer.data.size() - view.byteOffset)
    throw SceneError(viewPtr, "bufferView " + std::to_string(viewIndex) + " spans bytes [" +
                                  std::to_string(view.byteOffset) + ", " +
                                  std::to_string(view.byteOffset + view.byteLength) + ") but buffer " +
                                  std::to_string(view.buffer) + " has " +
                                  std::to_string(buffer.data.size()) + " bytes");
  std::size_t stride = elementSize;
  if (allowStride && view.byteStride != 0) {
    if (view.byteStride < elementSize)
      throw SceneError(viewPtr + "/byteStride",
                       "bufferView " + std::to_string(viewIndex) + " has byteStride " +
                           std::to_string(view.byteStride) + ", smaller than the " +
                           std::to_string(elementSize) + "-byte elements of " + what);
    stride = view.byteStride;
  }
  if (count > 0) {
    if (count > view.byteLength)  // every element takes at least one byte
      throw SceneError(ptr, what + " has " + std::to_string(count) + " elements but bufferView " +
                                std::to_string(viewIndex) + " has only " +
                                std::to_string(view.byteLength) + " bytes");
    if (byteOffset > view.byteLength)
      throw SceneError(ptr + "/byteOffset", what + " starts at byte " + std::to_string(byteOffset) +
                                                " of bufferView " + std::to_string(viewIndex) +
                                                ", which has " + std::to_string(view.byteLength) + " bytes");
    // byteOffset and count <= byteLength (< 2^32 here) and stride <= 255: no 64-bit overflow.
    const std::uint64_t end = std::uint64_t(byteOffset) + std::uint64_t(count - 1) * stride + elementSize;
    if (end > view.byteLength)
      throw SceneError(ptr, what + " reads bytes [" + std::to_string(byteOffset) + ", " +
                                std::to_string(end) + ") of bufferView " +
                                std::to_string(viewIndex) + ", which has " +
                                std::to_string(view.byteLength) + " bytes");
  }
  return {buffer.data.data() + view.byteOffset + byteOffset, stride};
}

// All elements of an accessor as floats (count * components), sparse substitution applied.
std::vector<float> readFloats(const tinygltf::Model& model, int index, int expectedType,
                              const std::string& what, std::size_t maxBytes) {
  const std::string ptr = pointer("/accessors", std::size_t(index));
  if (index < 0 || std::size_t(index) >= model.accessors.size())
    throw SceneError(ptr, what + " names accessor " + std::to_string(index) + ", which does not exist");
  const auto& acc = model.accessors[std::size_t(index)];
  const std::string desc = describeAccessor(index, what);
  if (acc.type != expectedType)
    throw SceneError(ptr + "/type", desc + " has type " + typeName(acc.type) + ", expected " +
                                        typeName(expectedType));
  const int comps = tinygltf::GetNumComponentsInType(std::uint32_t(acc.type));
  const int csize = componentSize(acc.componentType);
  if (csize == 0)
    throw SceneError(ptr + "/componentType", desc + " has an invalid componentType " +
                                                 std::to_string(acc.componentType));
  if (acc.count > maxBytes / (std::size_t(comps) * sizeof(float)))
    throw SceneError(ptr + "/count", desc + " has " + std::to_string(acc.count) +
                                         " elements, over the size limit");
  std::vector<float> out(acc.count * std::size_t(comps), 0.f);  // no bufferView: zeros (spec 3.6.2.3)
  if (acc.bufferView >= 0) {
    const Strided s = checkedView(model, acc.bufferView, acc.byteOffset, acc.count,
                                  std::size_t(comps * csize), true, ptr, desc);
    for (std::size_t i = 0; i < acc.count; ++i)
      for (int c = 0; c < comps; ++c)
        out[i * comps + c] = readComponent(s.base + i * s.stride + c * csize, acc.componentType,
                                           acc.normalized);
  }
  if (acc.sparse.isSparse) {
    const std::size_t n = std::size_t(std::max(acc.sparse.count, 0));
    const std::string sp = ptr + "/sparse";
    const int icType = acc.sparse.indices.componentType;
    const int isize = componentSize(icType);
    if (icType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
        icType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT && icType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
      throw SceneError(sp + "/indices/componentType", desc + ": sparse indices must be unsigned integers");
    const Strided si = checkedView(model, acc.sparse.indices.bufferView,
                                   std::size_t(std::max(acc.sparse.indices.byteOffset, 0)), n,
                                   std::size_t(isize), false, sp + "/indices", desc + " sparse indices");
    const Strided sv = checkedView(model, acc.sparse.values.bufferView,
                                   std::size_t(std::max(acc.sparse.values.byteOffset, 0)), n,
                                   std::size_t(comps * csize), false, sp + "/values",
                                   desc + " sparse values");
    for (std::size_t k = 0; k < n; ++k) {
      const std::uint32_t i = readIndex(si.base + k * si.stride, icType);
      if (i >= acc.count)
        throw SceneError(sp + "/indices", desc + ": sparse index " + std::to_string(i) +
                                              " is out of range (count " + std::to_string(acc.count) + ")");
      for (int c = 0; c < comps; ++c)
        out[i * comps + c] = readComponent(sv.base + k * sv.stride + c * csize, acc.componentType,
                                           acc.normalized);
    }
  }
  return out;
}

std::vector<std::uint32_t> readIndices(const tinygltf::Model& model, int index, const std::string& what,
                                       std::size_t maxBytes) {
  const std::string ptr = pointer("/accessors", std::size_t(index));
  if (index < 0 || std::size_t(index) >= model.accessors.size())
    throw SceneError(ptr, what + " names accessor " + std::to_string(index) + ", which does not exist");
  const auto& acc = model.accessors[std::size_t(index)];
  const std::string desc = describeAccessor(index, what);
  if (acc.type != TINYGLTF_TYPE_SCALAR)
    throw SceneError(ptr + "/type", desc + " has type " + typeName(acc.type) + ", expected SCALAR");
  const int t = acc.componentType;
  if (t != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && t != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
      t != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
    throw SceneError(ptr + "/componentType",
                     desc + " must be UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT");
  if (acc.sparse.isSparse)
    throw SceneError(ptr + "/sparse", desc + ": sparse index accessors are not supported");
  if (acc.count > maxBytes / sizeof(std::uint32_t))
    throw SceneError(ptr + "/count", desc + " has " + std::to_string(acc.count) +
                                         " elements, over the size limit");
  std::vector<std::uint32_t> out(acc.count, 0u);
  if (acc.bufferView >= 0) {
    // Index buffer views have no stride (spec 3.7.2.1): elements are tightly packed.
    const Strided s = checkedView(model, acc.bufferView, acc.byteOffset, acc.count,
                                  std::size_t(componentSize(t)), false, ptr, desc);
    for (std::size_t i = 0; i < acc.count; ++i) out[i] = readIndex(s.base + i * s.stride, t);
  }
  return out;
}

// ---- geometry -------------------------------------------------------------------------------

std::vector<glm::vec3> asVec3(const std::vector<float>& f) {
  std::vector<glm::vec3> v(f.size() / 3);
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = {f[3 * i], f[3 * i + 1], f[3 * i + 2]};
  return v;
}
std::vector<glm::vec2> asVec2(const std::vector<float>& f) {
  std::vector<glm::vec2> v(f.size() / 2);
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = {f[2 * i], f[2 * i + 1]};
  return v;
}
std::vector<glm::vec4> asVec4(const std::vector<float>& f) {
  std::vector<glm::vec4> v(f.size() / 4);
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = {f[4 * i], f[4 * i + 1], f[4 * i + 2], f[4 * i + 3]};
  return v;
}

glm::vec3 anyPerpendicular(const glm::vec3& n) {
  const glm::vec3 a = std::abs(n.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
  return glm::normalize(glm::cross(a, n));
}

// Vertex normals as the area-weighted sum of the normals of the triangles sharing the vertex:
// the cross product of two edges has length 2 * area, so summing unnormalised cross products
// weights by area.
std::vector<glm::vec3> areaWeightedNormals(const std::vector<glm::vec3>& p,
                                           const std::vector<std::uint32_t>& idx) {
  std::vector<glm::vec3> n(p.size(), glm::vec3(0.f));
  for (std::size_t t = 0; t + 2 < idx.size(); t += 3) {
    const auto a = idx[t], b = idx[t + 1], c = idx[t + 2];
    const glm::vec3 w = glm::cross(p[b] - p[a], p[c] - p[a]);
    n[a] += w; n[b] += w; n[c] += w;
  }
  for (auto& v : n) {
    const float len = glm::length(v);
    v = len > 0.f && std::isfinite(len) ? v / len : glm::vec3(0, 1, 0);
  }
  return n;
}

// Unit vertex normals for MikkTSpace, in the file's space: the file's own where usable, else the
// area-weighted ones (which is also what the loader gives a file without normals, after the transform).
std::vector<glm::vec3> unitNormals(const std::vector<glm::vec3>& nrm, const std::vector<glm::vec3>& p,
                                   const std::vector<std::uint32_t>& idx) {
  std::vector<glm::vec3> n = nrm, fallback;
  if (n.size() != p.size()) n.assign(p.size(), glm::vec3(0.f));
  for (std::size_t i = 0; i < n.size(); ++i) {
    const float len = glm::length(n[i]);
    if (len > 0.f && std::isfinite(len)) {
      n[i] /= len;
    } else {
      if (fallback.empty()) fallback = areaWeightedNormals(p, idx);
      n[i] = fallback[i];
    }
  }
  return n;
}

glm::mat4 localMatrix(const tinygltf::Node& node) {
  if (node.matrix.size() == 16) {
    glm::mat4 m;
    for (int i = 0; i < 16; ++i) glm::value_ptr(m)[i] = float(node.matrix[std::size_t(i)]);  // column major
    return m;
  }
  glm::mat4 m(1.f);
  if (node.translation.size() == 3)
    m = glm::translate(m, glm::vec3(node.translation[0], node.translation[1], node.translation[2]));
  if (node.rotation.size() == 4)  // glTF stores x, y, z, w
    m *= glm::mat4_cast(glm::normalize(glm::quat(float(node.rotation[3]), float(node.rotation[0]),
                                                 float(node.rotation[1]), float(node.rotation[2]))));
  if (node.scale.size() == 3)
    m = glm::scale(m, glm::vec3(node.scale[0], node.scale[1], node.scale[2]));
  return m;
}

// The camera's rotation and translation with any scale or shear removed (a view matrix must be rigid).
glm::mat4 rigid(const glm::mat4& m) {
  glm::vec3 x(m[0]), y(m[1]), z(m[2]);
  z = glm::length(z) > 0.f ? glm::normalize(z) : glm::vec3(0, 0, 1);
  x = x - z * glm::dot(z, x);
  x = glm::length(x) > 0.f ? glm::normalize(x) : anyPerpendicular(z);
  y = glm::cross(z, x);
  glm::mat4 r(1.f);
  r[0] = glm::vec4(x, 0); r[1] = glm::vec4(y, 0); r[2] = glm::vec4(z, 0); r[3] = m[3];
  return r;
}

// ---- model -> scene -------------------------------------------------------------------------

const tinygltf::Value* extension(const tinygltf::ExtensionMap& ext, const char* name) {
  const auto it = ext.find(name);
  return it != ext.end() && it->second.IsObject() ? &it->second : nullptr;
}

float number(const tinygltf::Value& v, const char* key, float fallback) {
  return v.Has(key) && v.Get(key).IsNumber() ? float(v.Get(key).GetNumberAsDouble()) : fallback;
}

// A tinygltf extension value as JSON, so the request's schema validator can check it.
nlohmann::json toJson(const tinygltf::Value& v) {
  if (v.IsBool()) return v.Get<bool>();
  if (v.IsInt()) return v.Get<int>();
  if (v.IsNumber()) return v.GetNumberAsDouble();
  if (v.IsString()) return v.Get<std::string>();
  if (v.IsArray()) {
    nlohmann::json a = nlohmann::json::array();
    for (std::size_t i = 0; i < v.ArrayLen(); ++i) a.push_back(toJson(v.Get(int(i))));
    return a;
  }
  if (v.IsObject()) {
    nlohmann::json o = nlohmann::json::object();
    for (const auto& k : v.Keys()) o[k] = toJson(v.Get(k));
    return o;
  }
  return nullptr;
}

// Particles of all RADIANT_particle_system nodes of one file together.
constexpr std::size_t kMaxSceneParticles = std::size_t(1) << 20;

class Converter {
public:
  Converter(const tinygltf::Model& model, std::size_t maxBytes) : m_(model), maxBytes_(maxBytes) {}

  Scene run() {
    convertTextures();
    convertMaterials();
    walkScene();
    if (!scene_.camera.fromFile) scene_.camera = defaultCameraFor(sceneBounds(), 1.f);
    return std::move(scene_);
  }

private:
  TextureRef textureRef(int index, int texCoord, float scale, const std::string& ptr, bool srgb) {
    if (index < 0) return {};
    if (std::size_t(index) >= scene_.textures.size())
      throw SceneError(ptr + "/index", "texture " + std::to_string(index) + " does not exist");
    if (!textureUsable_[std::size_t(index)]) return {};  // dropped with a warning (convertTextures)
    if (texCoord < 0 || texCoord > 1)
      throw SceneError(ptr + "/texCoord", "TEXCOORD_" + std::to_string(texCoord) +
                                              " is not supported (only TEXCOORD_0 and TEXCOORD_1)");
    if (srgb) scene_.textures[std::size_t(index)].colorSpace = TextureColorSpace::SRGB;
    TextureRef r;
    r.texture = index;
    r.texCoord = texCoord;
    r.scale = scale;
    return r;
  }

  // A textureInfo object of an extension (tinygltf leaves these as JSON values): index, texCoord, the
  // normal `scale` of a normalTextureInfo, and its KHR_texture_transform.
  TextureRef textureRef(const tinygltf::Value& info, const std::string& ptr, bool srgb = false) {
    if (!info.IsObject() || !info.Has("index")) return {};
    if (!info.Get("index").IsNumber()) throw SceneError(ptr + "/index", "a texture index must be a number");
    const int texCoord = info.Has("texCoord") ? info.Get("texCoord").GetNumberAsInt() : 0;
    const float scale = info.Has("scale") && info.Get("scale").IsNumber() ? float(info.Get("scale").GetNumberAsDouble()) : 1.f;
    TextureRef r = textureRef(info.Get("index").GetNumberAsInt(), texCoord, scale, ptr, srgb);
    if (r.valid() && info.Has("extensions") && info.Get("extensions").Has("KHR_texture_transform"))
      gltf::applyTextureTransform(&info.Get("extensions").Get("KHR_texture_transform"), r, ptr);
    return r;
  }

  void convertTextures() {
    for (std::size_t i = 0; i < m_.textures.size(); ++i) {
      tinygltf::Texture t = m_.textures[i];
      const std::string ptr = pointer("/textures", i);
      // EXT_texture_webp: its image wins over `source`, which is then an optional PNG/JPEG fallback
      // for viewers without WebP (the extension's README, "glTF Schema Updates").
      if (const auto e = t.extensions.find("EXT_texture_webp"); e != t.extensions.end()) {
        const tinygltf::Value& src = e->second.Get("source");
        if (!src.IsInt() && !src.IsNumber())
          throw SceneError(ptr + "/extensions/EXT_texture_webp/source", "texture " + std::to_string(i) +
                                                                          ": EXT_texture_webp needs an image index");
        t.source = src.GetNumberAsInt();
        if (t.source < 0)
          throw SceneError(ptr + "/extensions/EXT_texture_webp/source",
                           "texture " + std::to_string(i) + ": EXT_texture_webp names image " + std::to_string(t.source));
      }
      if (t.source < 0) {
        // Valid glTF (source is optional; an extension such as KHR_texture_basisu may name the only
        // image): the materials render without this texture, and the frame says so.
        scene_.warnings.push_back(ptr + ": texture " + std::to_string(i) +
                                  " has no image this renderer can use: materials render without it");
        scene_.textures.emplace_back();
        textureUsable_.push_back(false);
        continue;
      }
      if (std::size_t(t.source) >= m_.images.size())
        throw SceneError(ptr + "/source", "texture " + std::to_string(i) + " names image " + std::to_string(t.source) +
                                              ", which does not exist");
      const auto& img = m_.images[std::size_t(t.source)];
      const std::string iptr = pointer("/images", std::size_t(t.source));
      if (img.image.empty() || img.width <= 0 || img.height <= 0 || img.component != 4)
        throw SceneError(iptr, "image " + std::to_string(t.source) +
                                   (img.uri.empty() ? std::string() : " (\"" + img.uri + "\")") +
                                   " could not be loaded or decoded");
      Texture out;
      out.name = !t.name.empty() ? t.name : img.name;
      out.width = img.width;
      out.height = img.height;
      const std::size_t texels = std::size_t(img.width) * std::size_t(img.height) * 4;
      out.rgba8.resize(texels);
      if (img.bits == 16 && img.image.size() >= texels * 2) {
        for (std::size_t k = 0; k < texels; ++k) {
          std::uint16_t v; std::memcpy(&v, img.image.data() + 2 * k, 2);
          out.rgba8[k] = std::uint8_t((std::uint32_t(v) * 255u + 32767u) / 65535u);
        }
      } else if (img.bits == 8 && img.image.size() >= texels) {
        std::memcpy(out.rgba8.data(), img.image.data(), texels);
      } else {
        throw SceneError(iptr, "image " + std::to_string(t.source) + " has an unsupported bit depth " +
                                   std::to_string(img.bits));
      }
      if (t.sampler >= 0) {
        if (std::size_t(t.sampler) >= m_.samplers.size())
          throw SceneError(ptr + "/sampler", "sampler " + std::to_string(t.sampler) + " does not exist");
        const auto& s = m_.samplers[std::size_t(t.sampler)];
        out.wrapS = s.wrapS;
        out.wrapT = s.wrapT;
        if (s.minFilter >= 0) out.minFilter = s.minFilter;
        if (s.magFilter >= 0) out.magFilter = s.magFilter;
      }
      scene_.textures.push_back(std::move(out));
      textureUsable_.push_back(true);
    }
  }

  void convertMaterials() {
    for (std::size_t i = 0; i < m_.materials.size(); ++i) {
      const auto& g = m_.materials[i];
      const std::string ptr = pointer("/materials", i);
      const auto& pbr = g.pbrMetallicRoughness;
      Material mat;
      mat.name = g.name;
      if (pbr.baseColorFactor.size() == 4)
        mat.baseColorFactor = glm::vec4(pbr.baseColorFactor[0], pbr.baseColorFactor[1],
                                        pbr.baseColorFactor[2], pbr.baseColorFactor[3]);
      mat.metallicFactor = float(pbr.metallicFactor);
      mat.roughnessFactor = float(pbr.roughnessFactor);
      if (g.emissiveFactor.size() == 3)
        mat.emissiveFactor = glm::vec3(g.emissiveFactor[0], g.emissiveFactor[1], g.emissiveFactor[2]);
      const std::string pp = ptr + "/pbrMetallicRoughness";
      mat.baseColorTexture = textureRef(pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord, 1.f,
                                        pp + "/baseColorTexture", true);
      mat.metallicRoughnessTexture =
          textureRef(pbr.metallicRoughnessTexture.index, pbr.metallicRoughnessTexture.texCoord, 1.f,
                     pp + "/metallicRoughnessTexture", false);
      mat.normalTexture = textureRef(g.normalTexture.index, g.normalTexture.texCoord,
                                     float(g.normalTexture.scale), ptr + "/normalTexture", false);
      mat.occlusionTexture = textureRef(g.occlusionTexture.index, g.occlusionTexture.texCoord,
                                        float(g.occlusionTexture.strength), ptr + "/occlusionTexture",
                                        false);
      mat.emissiveTexture = textureRef(g.emissiveTexture.index, g.emissiveTexture.texCoord, 1.f,
                                       ptr + "/emissiveTexture", true);
      // KHR_texture_transform per texture slot, KHR_materials_unlit (GltfExtensions.h).
      auto transform = [&](const tinygltf::ExtensionMap& ext, TextureRef& ref, const std::string& at) {
        if (ref.valid()) gltf::applyTextureTransform(extension(ext, "KHR_texture_transform"), ref, at);
      };
      transform(pbr.baseColorTexture.extensions, mat.baseColorTexture, pp + "/baseColorTexture");
      transform(pbr.metallicRoughnessTexture.extensions, mat.metallicRoughnessTexture, pp + "/metallicRoughnessTexture");
      transform(g.normalTexture.extensions, mat.normalTexture, ptr + "/normalTexture");
      transform(g.occlusionTexture.extensions, mat.occlusionTexture, ptr + "/occlusionTexture");
      transform(g.emissiveTexture.extensions, mat.emissiveTexture, ptr + "/emissiveTexture");
      mat.unlit = extension(g.extensions, "KHR_materials_unlit") != nullptr;
      mat.doubleSided = g.doubleSided;
      if (g.alphaMode == "MASK") mat.alphaMode = AlphaMode::Mask;
      else if (g.alphaMode == "BLEND") mat.alphaMode = AlphaMode::Blend;
      else if (g.alphaMode == "OPAQUE" || g.alphaMode.empty()) mat.alphaMode = AlphaMode::Opaque;
      else throw SceneError(ptr + "/alphaMode", "unknown alphaMode \"" + g.alphaMode + "\"");
      mat.alphaCutoff = float(g.alphaCutoff);
      const std::string ep = ptr + "/extensions/";
      if (const auto* e = extension(g.extensions, "KHR_materials_transmission")) {
        mat.transmissionFactor = number(*e, "transmissionFactor", 0.f);
        if (e->Has("transmissionTexture"))
          mat.transmissionTexture = textureRef(e->Get("transmissionTexture"),
                                               ep + "KHR_materials_transmission/transmissionTexture");
      }
      if (const auto* e = extension(g.extensions, "KHR_materials_ior")) mat.ior = number(*e, "ior", 1.5f);
      if (const auto* e = extension(g.extensions, "KHR_materials_emissive_strength"))
        mat.emissiveStrength = number(*e, "emissiveStrength", 1.f);
      // The layered extensions: factors and textures (the channels each texture contributes are in
      // MaterialDecode.h). sheenColorTexture and specularColorTexture hold sRGB colour (the extensions'
      // specs); the others are data.
      auto layerTexture = [&](const tinygltf::Value& e, const char* ext, const char* key, bool srgb) {
        return e.Has(key) ? textureRef(e.Get(key), ep + ext + "/" + key, srgb) : TextureRef{};
      };
      auto color3 = [](const tinygltf::Value& e, const char* key, glm::vec3 fallback) {
        if (!e.Has(key)) return fallback;
        const tinygltf::Value& a = e.Get(key);
        if (!a.IsArray() || a.ArrayLen() != 3) return fallback;
        glm::vec3 c;
        for (int k = 0; k < 3; ++k) c[k] = a.Get(k).IsNumber() ? float(a.Get(k).GetNumberAsDouble()) : fallback[k];
        return c;
      };
      if (const auto* e = extension(g.extensions, "KHR_materials_clearcoat")) {
        const char* x = "KHR_materials_clearcoat";
        mat.clearcoatFactor = std::clamp(number(*e, "clearcoatFactor", 0.f), 0.f, 1.f);
        mat.clearcoatRoughnessFactor = std::clamp(number(*e, "clearcoatRoughnessFactor", 0.f), 0.f, 1.f);
        mat.clearcoatTexture = layerTexture(*e, x, "clearcoatTexture", false);
        mat.clearcoatRoughnessTexture = layerTexture(*e, x, "clearcoatRoughnessTexture", false);
        mat.clearcoatNormalTexture = layerTexture(*e, x, "clearcoatNormalTexture", false);
      }
      if (const auto* e = extension(g.extensions, "KHR_materials_sheen")) {
        const char* x = "KHR_materials_sheen";
        mat.sheenColorFactor = glm::clamp(color3(*e, "sheenColorFactor", glm::vec3(0.f)), 0.f, 1.f);
        mat.sheenRoughnessFactor = std::clamp(number(*e, "sheenRoughnessFactor", 0.f), 0.f, 1.f);
        mat.sheenColorTexture = layerTexture(*e, x, "sheenColorTexture", true);
        mat.sheenRoughnessTexture = layerTexture(*e, x, "sheenRoughnessTexture", false);
      }
      if (const auto* e = extension(g.extensions, "KHR_materials_specular")) {
        const char* x = "KHR_materials_specular";
        mat.specularFactor = std::clamp(number(*e, "specularFactor", 1.f), 0.f, 1.f);
        mat.specularColorFactor = glm::max(color3(*e, "specularColorFactor", glm::vec3(1.f)), 0.f);
        mat.specularTexture = layerTexture(*e, x, "specularTexture", false);
        mat.specularColorTexture = layerTexture(*e, x, "specularColorTexture", true);
      }
      if (const auto* e = extension(g.extensions, "KHR_materials_volume")) convertVolume(*e, ep + "KHR_materials_volume", mat);
      scene_.materials.push_back(std::move(mat));
    }
  }

  // KHR_materials_volume. Values outside the spec's ranges (thicknessFactor >= 0, attenuationDistance
  // in (0, inf), attenuationColor in [0, 1]) are repaired with a warning naming the field, as a renderer
  // draws a valid-looking file rather than refuse it: a negative thickness is a thin wall (0), a
  // non-positive or non-numeric distance means no absorption, a colour is clamped to [0, 1].
  void convertVolume(const tinygltf::Value& e, const std::string& at, Material& mat) {
    auto warn = [&](const char* key, const std::string& what) {
      scene_.warnings.push_back(at + "/" + key + ": " + what);
    };
    auto value = [&](const char* key, double fallback, bool& ok) {
      ok = true;
      if (!e.Has(key)) return fallback;
      const tinygltf::Value& v = e.Get(key);
      ok = v.IsNumber() && std::isfinite(v.GetNumberAsDouble());
      return ok ? v.GetNumberAsDouble() : fallback;
    };
    bool ok = true;
    const double thickness = value("thicknessFactor", 0.0, ok);
    if (!ok || thickness < 0.0) warn("thicknessFactor", "must be a number >= 0: the surface is a thin wall (0)");
    else mat.thicknessFactor = float(std::min(thickness, double(std::numeric_limits<float>::max())));
    const double distance = value("attenuationDistance", std::numeric_limits<double>::infinity(), ok);
    if (!ok || !(distance > 0.0)) warn("attenuationDistance", "must be a number > 0: the medium does not absorb");
    // Above FLT_MAX: infinite, no absorption. Below FLT_MIN a float is subnormal, which the ray tracer's
    // threads read as 0 (Embree's recommended flush-to-zero / denormals-are-zero mode): FLT_MIN instead,
    // as opaque as the value asked for.
    else if (distance > double(std::numeric_limits<float>::max()))
      mat.attenuationDistance = std::numeric_limits<float>::infinity();  // a cast would be undefined
    else mat.attenuationDistance = float(std::max(distance, double(std::numeric_limits<float>::min())));
    if (e.Has("attenuationColor")) {
      const tinygltf::Value& a = e.Get("attenuationColor");
      bool valid = a.IsArray() && a.ArrayLen() == 3;
      glm::vec3 c(1.f);
      for (int k = 0; valid && k < 3; ++k) {
        valid = a.Get(k).IsNumber() && std::isfinite(a.Get(k).GetNumberAsDouble());
        if (valid) c[k] = float(a.Get(k).GetNumberAsDouble());
      }
      if (!valid) {
        warn("attenuationColor", "must be three numbers in [0, 1]: white (no absorption) used");
      } else {
        if (glm::any(glm::lessThan(c, glm::vec3(0.f))) || glm::any(glm::greaterThan(c, glm::vec3(1.f))))
          warn("attenuationColor", "components outside [0, 1] clamped");
        mat.attenuationColor = glm::clamp(c, 0.f, 1.f);
      }
    }
    if (e.Has("thicknessTexture")) mat.thicknessTexture = textureRef(e.Get("thicknessTexture"), at + "/thicknessTexture");
  }

  void walkScene() {
    std::vector<int> roots;
    if (!m_.scenes.empty()) {
      const std::size_t s = m_.defaultScene >= 0 ? std::size_t(m_.defaultScene) : 0;
      if (s >= m_.scenes.size()) throw SceneError("/scene", "the default scene does not exist");
      scene_.name = m_.scenes[s].name;
      for (std::size_t k = 0; k < m_.scenes[s].nodes.size(); ++k) {
        const int n = m_.scenes[s].nodes[k];
        if (n < 0 || std::size_t(n) >= m_.nodes.size())
          throw SceneError(pointer(pointer("/scenes", s) + "/nodes", k),
                           "node " + std::to_string(n) + " does not exist");
        roots.push_back(n);
      }
    } else {
      // No scenes: render every node that is nobody's child.
      std::vector<bool> isChild(m_.nodes.size(), false);
      for (const auto& n : m_.nodes)
        for (int c : n.children)
          if (c >= 0 && std::size_t(c) < m_.nodes.size()) isChild[std::size_t(c)] = true;
      for (std::size_t i = 0; i < m_.nodes.size(); ++i)
        if (!isChild[i]) roots.push_back(int(i));
    }
    std::vector<bool> visited(m_.nodes.size(), false);
    // Depth first, in document order, so "the first camera" is well defined.
    std::vector<std::pair<int, glm::mat4>> stack;
    for (auto it = roots.rbegin(); it != roots.rend(); ++it) stack.emplace_back(*it, glm::mat4(1.f));
    while (!stack.empty()) {
      const auto [index, parent] = stack.back();
      stack.pop_back();
      const std::string ptr = pointer("/nodes", std::size_t(index));
      if (visited[std::size_t(index)])
        throw SceneError(ptr, "node " + std::to_string(index) +
                                  " appears twice in the hierarchy (a cycle or a shared child)");
      visited[std::size_t(index)] = true;
      const auto& node = m_.nodes[std::size_t(index)];
      const glm::mat4 world = parent * localMatrix(node);
      visitNode(index, node, world, ptr);
      for (std::size_t k = node.children.size(); k-- > 0;) {
        const int c = node.children[k];
        if (c < 0 || std::size_t(c) >= m_.nodes.size())
          throw SceneError(pointer(ptr + "/children", k), "child node " + std::to_string(c) + " does not exist");
        stack.emplace_back(c, world);
      }
    }
  }

  void visitNode(int index, const tinygltf::Node& node, const glm::mat4& world, const std::string& ptr) {
    scene_.nodeNames.push_back(node.name);
    if (node.mesh >= 0) {
      if (std::size_t(node.mesh) >= m_.meshes.size())
        throw SceneError(ptr + "/mesh", "mesh " + std::to_string(node.mesh) + " does not exist");
      const auto& mesh = m_.meshes[std::size_t(node.mesh)];
      for (std::size_t p = 0; p < mesh.primitives.size(); ++p)
        addPrimitive(index, node, node.mesh, int(p), world);
    }
    if (node.camera >= 0 && !scene_.camera.fromFile) addCamera(node, world, ptr);
    if (const auto* e = extension(node.extensions, "KHR_lights_punctual")) addLight(*e, world, ptr);
    if (const auto* e = extension(node.extensions, "RADIANT_particle_system")) addParticleSystem(*e, world, ptr);
  }

  // RADIANT_particle_system (api/schema/media.json, "gltf_particles"): the request's particle-system
  // schema with particles as accessors, in node-local space.
  void addParticleSystem(const tinygltf::Value& e, const glm::mat4& world, const std::string& ptr) {
    const std::string eptr = ptr + "/extensions/RADIANT_particle_system";
    nlohmann::json system;
    try {
      system = api::validate(api::gltfMediaSchema(), toJson(e), eptr);
    } catch (const api::ApiError& err) {
      throw SceneError(err.pointer, err.detail());
    }
    api::ParticleColumns columns;
    const bool explicitParticles = system.contains("particles");
    if (explicitParticles) {
      const nlohmann::json& p = system["particles"];
      const std::string pp = eptr + "/particles";
      auto accessor = [&](const char* key) { return p[key].get<int>(); };
      columns.positions = asVec3(readFloats(m_, accessor("positions"), TINYGLTF_TYPE_VEC3, pp + "/positions", maxBytes_));
      columns.radii = readFloats(m_, accessor("radii"), TINYGLTF_TYPE_SCALAR, pp + "/radii", maxBytes_);
      if (p.contains("tau")) columns.tau = readFloats(m_, accessor("tau"), TINYGLTF_TYPE_SCALAR, pp + "/tau", maxBytes_);
      if (p.contains("albedo"))
        columns.albedo = asVec3(readFloats(m_, accessor("albedo"), TINYGLTF_TYPE_VEC3, pp + "/albedo", maxBytes_));
      if (p.contains("temperature"))
        columns.temperature =
            readFloats(m_, accessor("temperature"), TINYGLTF_TYPE_SCALAR, pp + "/temperature", maxBytes_);
      const std::size_t n = columns.positions.size();
      for (const auto& [key, size] : {std::pair<const char*, std::size_t>{"radii", columns.radii.size()},
                                      {"tau", columns.tau.size()}, {"albedo", columns.albedo.size()},
                                      {"temperature", columns.temperature.size()}})
        if (p.contains(key) && size != n)
          throw SceneError(pp + "/" + key, std::string(key) + " has " + std::to_string(size) +
                                               " elements, positions has " + std::to_string(n));
    }
    std::size_t used = 0;
    for (const auto& s : scene_.media) used += s.particles.size();
    api::ParticleSystem ps;
    try {
      ps = api::makeParticleSystem(system, explicitParticles ? &columns : nullptr, eptr,
                                   used < kMaxSceneParticles ? kMaxSceneParticles - used : 0);
    } catch (const api::ApiError& err) {
      throw SceneError(err.pointer, err.detail());
    }
    // Node-local to world: centres through the matrix, radii by its largest axis scale.
    const float scale = std::max({glm::length(glm::vec3(world[0])), glm::length(glm::vec3(world[1])),
                                  glm::length(glm::vec3(world[2]))});
    for (auto& p : ps.particles) {
      p.position = glm::vec3(world * glm::vec4(p.position, 1.f));
      p.radius *= scale;
    }
    if (ps.name.empty()) ps.name = scene_.nodeNames.back();
    scene_.media.push_back(std::move(ps));
  }

  void addCamera(const tinygltf::Node& node, const glm::mat4& world, const std::string& ptr) {
    if (std::size_t(node.camera) >= m_.cameras.size())
      throw SceneError(ptr + "/camera", "camera " + std::to_string(node.camera) + " does not exist");
    const auto& c = m_.cameras[std::size_t(node.camera)];
    const std::string cptr = pointer("/cameras", std::size_t(node.camera));
    Camera cam;
    cam.name = !c.name.empty() ? c.name : node.name;
    if (c.type == "perspective") {
      cam.projection = ProjectionType::Perspective;
      if (!(c.perspective.yfov > 0.0) || !(c.perspective.znear > 0.0))
        throw SceneError(cptr + "/perspective", "a perspective camera needs yfov > 0 and znear > 0");
      cam.yfov = float(c.perspective.yfov);
      cam.aspectRatio = float(c.perspective.aspectRatio);
      cam.znear = float(c.perspective.znear);
      cam.zfar = float(c.perspective.zfar);
    } else if (c.type == "orthographic") {
      cam.projection = ProjectionType::Orthographic;
      if (c.orthographic.xmag == 0.0 || c.orthographic.ymag == 0.0 ||
          !(c.orthographic.zfar > c.orthographic.znear))
        throw SceneError(cptr + "/orthographic",
                         "an orthographic camera needs non-zero xmag and ymag and zfar > znear");
      cam.xmag = float(c.orthographic.xmag);
      cam.ymag = float(c.orthographic.ymag);
      cam.znear = float(c.orthographic.znear);
      cam.zfar = float(c.orthographic.zfar);
    } else {
      throw SceneError(cptr + "/type", "unknown camera type \"" + c.type + "\"");
    }
    cam.world = rigid(world);
    cam.fromFile = true;
    scene_.camera = cam;
  }

  void addLight(const tinygltf::Value& e, const glm::mat4& world, const std::string& ptr) {
    if (!e.Has("light") || !e.Get("light").IsNumber())
      throw SceneError(ptr + "/extensions/KHR_lights_punctual/light", "the node names no light");
    const int li = e.Get("light").GetNumberAsInt();
    if (li < 0 || std::size_t(li) >= m_.lights.size())
      throw SceneError(ptr + "/extensions/KHR_lights_punctual/light",
                       "light " + std::to_string(li) + " does not exist");
    const auto& g = m_.lights[std::size_t(li)];
    const std::string lptr = pointer("/extensions/KHR_lights_punctual/lights", std::size_t(li));
    Light l;
    l.name = g.name;
    if (g.type == "point") l.type = LightType::Point;
    else if (g.type == "spot") l.type = LightType::Spot;
    else if (g.type == "directional") l.type = LightType::Directional;
    else throw SceneError(lptr + "/type", "unknown light type \"" + g.type + "\"");
    if (g.color.size() == 3) l.color = glm::vec3(g.color[0], g.color[1], g.color[2]);
    l.intensity = float(g.intensity);
    l.range = float(g.range);
    if (l.type == LightType::Spot) {
      l.innerConeAngle = float(g.spot.innerConeAngle);
      l.outerConeAngle = float(g.spot.outerConeAngle);
    }
    l.position = glm::vec3(world * glm::vec4(0, 0, 0, 1));
    const glm::vec3 d = glm::mat3(world) * glm::vec3(0, 0, -1);
    l.direction = glm::length(d) > 0.f ? glm::normalize(d) : glm::vec3(0, 0, -1);
    scene_.lights.push_back(l);
  }

  void addPrimitive(int nodeIndex, const tinygltf::Node& node, int meshIndex, int primIndex,
                    const glm::mat4& world) {
    const auto& prim = m_.meshes[std::size_t(meshIndex)].primitives[std::size_t(primIndex)];
    const std::string pptr = primitivePointer(meshIndex, primIndex);
    const std::string where = "mesh " + std::to_string(meshIndex) + " primitive " + std::to_string(primIndex);
    const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
    if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
        mode != TINYGLTF_MODE_TRIANGLE_FAN) {
      static const char* kModes[] = {"POINTS", "LINES", "LINE_LOOP", "LINE_STRIP"};
      throw SceneError(pptr + "/mode", where + " has mode " +
                                           (mode >= 0 && mode < 4 ? kModes[mode] : std::to_string(mode)) +
                                           "; only triangles, triangle strips and fans are supported");
    }
    if (prim.material >= 0 && std::size_t(prim.material) >= scene_.materials.size())
      throw SceneError(pptr + "/material", "material " + std::to_string(prim.material) + " does not exist");
    auto attribute = [&](const char* name) {
      const auto it = prim.attributes.find(name);
      return it == prim.attributes.end() ? -1 : it->second;
    };
    const int posAcc = attribute("POSITION");
    if (posAcc < 0) throw SceneError(pptr + "/attributes", where + " has no POSITION attribute");

    MeshInstance mi;
    mi.name = node.name;
    mi.node = nodeIndex;
    mi.mesh = meshIndex;
    mi.primitive = primIndex;
    mi.material = prim.material;
    mi.world = world;
    mi.extrasJson = node.extras_json_string;

    std::vector<glm::vec3> pos = asVec3(readFloats(m_, posAcc, TINYGLTF_TYPE_VEC3, where + " POSITION", maxBytes_));
    const std::size_t n = pos.size();
    auto sameCount = [&](std::size_t count, const char* name, int acc) {
      if (count != n)
        throw SceneError(pointer("/accessors", std::size_t(acc)) + "/count",
                         where + ": " + name + " has " + std::to_string(count) + " elements but POSITION has " +
                             std::to_string(n));
    };
    std::vector<glm::vec3> nrm;
    if (const int a = attribute("NORMAL"); a >= 0) {
      nrm = asVec3(readFloats(m_, a, TINYGLTF_TYPE_VEC3, where + " NORMAL", maxBytes_));
      sameCount(nrm.size(), "NORMAL", a);
    }
    std::vector<glm::vec2> uv[2];
    for (int k = 0; k < 2; ++k) {
      const std::string name = "TEXCOORD_" + std::to_string(k);
      if (const int a = attribute(name.c_str()); a >= 0) {
        uv[k] = asVec2(readFloats(m_, a, TINYGLTF_TYPE_VEC2, where + " " + name, maxBytes_));
        sameCount(uv[k].size(), name.c_str(), a);
      }
    }
    const Material& mat = scene_.material(prim.material);
    std::vector<glm::vec4> tan;
    if (const int a = attribute("TANGENT"); a >= 0 && mat.hasNormalMap()) {
      tan = asVec4(readFloats(m_, a, TINYGLTF_TYPE_VEC4, where + " TANGENT", maxBytes_));
      sameCount(tan.size(), "TANGENT", a);
    }

    std::vector<std::uint32_t> idx;
    if (prim.indices >= 0) {
      idx = readIndices(m_, prim.indices, where + " indices", maxBytes_);
      for (std::size_t k = 0; k < idx.size(); ++k)
        if (idx[k] >= n)
          throw SceneError(pptr + "/indices", where + ": index " + std::to_string(idx[k]) + " at position " +
                                                  std::to_string(k) + " (accessor " +
                                                  std::to_string(prim.indices) + ") is out of range: the primitive has " +
                                                  std::to_string(n) + " vertices");
    } else {
      idx.resize(n);
      std::iota(idx.begin(), idx.end(), 0u);
    }
    // Triangle lists from strips and fans (glTF spec 3.7.2.1, "Topology types").
    if (mode == TINYGLTF_MODE_TRIANGLES) {
      if (idx.size() % 3 != 0)
        throw SceneError(pptr, where + " has " + std::to_string(idx.size()) +
                                   " indices (vertices), not a multiple of 3");
    } else {
      std::vector<std::uint32_t> list;
      for (std::size_t i = 0; i + 2 < idx.size(); ++i) {
        if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
          // Triangle i is {p_i, p_(i + 1 + i%2), p_(i + 2 - i%2)}: odd triangles swap to keep the winding.
          list.insert(list.end(), {idx[i], idx[i + 1 + i % 2], idx[i + 2 - i % 2]});
        } else {
          list.insert(list.end(), {idx[i + 1], idx[i + 2], idx[0]});  // {p_(i+1), p_(i+2), p_0}
        }
      }
      idx = std::move(list);
    }

    // glTF 3.7.2.1: a normal-mapped primitive without TANGENT gets MikkTSpace tangents, computed in the
    // file's space as an exporter computes them (then transformed below like the file's own). Without
    // the uv set the normal map reads, any frame perpendicular to the normal will do (below).
    // One frame per vertex serves both normal maps: the base's uv set when it has one, else the coat's.
    const TextureRef& normalMap = mat.normalTexture.valid() ? mat.normalTexture : mat.clearcoatNormalTexture;
    if (mat.hasNormalMap() && tan.empty() && !uv[normalMap.texCoord].empty()) {
      nrm = unitNormals(nrm, pos, idx);  // what MikkTSpace sees, kept: split vertices keep their normal
      const TangentSplit split =
          splitVerticesByTangent(gltfMikkTSpaceCornerTangents(pos, nrm, uv[normalMap.texCoord], idx), idx);
      auto copyOf = [&](auto& attribute) {
        if (attribute.empty()) return;
        auto old = std::move(attribute);
        attribute.resize(split.vertexOf.size());
        for (std::size_t v = 0; v < split.vertexOf.size(); ++v) attribute[v] = old[split.vertexOf[v]];
      };
      copyOf(pos), copyOf(nrm), copyOf(uv[0]), copyOf(uv[1]);
      idx = split.indices;
      tan = split.tangents;
    }

    // A mirroring transform turns counter-clockwise into clockwise (glTF spec 3.7.4): swap two
    // corners so that every instance is counter-clockwise front facing in world space.
    const glm::mat3 linear(world);
    const float det = glm::determinant(linear);
    if (det < 0.f)
      for (std::size_t t = 0; t + 2 < idx.size(); t += 3) std::swap(idx[t + 1], idx[t + 2]);

    for (auto& p : pos) p = glm::vec3(world * glm::vec4(p, 1.f));
    // Normals transform by the inverse transpose of the linear part.
    const glm::mat3 normalMatrix = glm::inverseTranspose(linear);
    if (!nrm.empty()) {
      std::vector<glm::vec3> fallback;
      for (std::size_t i = 0; i < nrm.size(); ++i) {
        const glm::vec3 v = normalMatrix * nrm[i];
        const float len = glm::length(v);
        if (len > 0.f && std::isfinite(len)) {
          nrm[i] = v / len;
        } else {
          if (fallback.empty()) fallback = areaWeightedNormals(pos, idx);
          nrm[i] = fallback[i];
        }
      }
    } else {
      nrm = areaWeightedNormals(pos, idx);
    }
    if (mat.hasNormalMap()) {
      if (!tan.empty()) {
        const float handedness = det < 0.f ? -1.f : 1.f;
        for (std::size_t i = 0; i < tan.size(); ++i) {
          glm::vec3 t = linear * glm::vec3(tan[i]);
          t -= nrm[i] * glm::dot(nrm[i], t);
          const float len = glm::length(t);
          t = len > 0.f && std::isfinite(len) ? t / len : anyPerpendicular(nrm[i]);
          tan[i] = glm::vec4(t, (tan[i].w < 0.f ? -1.f : 1.f) * handedness);
        }
      } else {
        tan.resize(nrm.size());
        for (std::size_t i = 0; i < nrm.size(); ++i) tan[i] = glm::vec4(anyPerpendicular(nrm[i]), 1.f);
      }
    }
    for (const auto& p : pos) mi.bounds.extend(p);
    mi.positions = std::move(pos);
    mi.normals = std::move(nrm);
    mi.tangents = std::move(tan);
    mi.uv0 = std::move(uv[0]);
    mi.uv1 = std::move(uv[1]);
    mi.indices = std::move(idx);
    scene_.meshes.push_back(std::move(mi));
  }

  Bounds sceneBounds() const {
    Bounds b;
    for (const auto& m : scene_.meshes) b.extend(m.bounds);
    return b;
  }

  const tinygltf::Model& m_;
  std::size_t maxBytes_;
  Scene scene_;
  std::vector<bool> textureUsable_;  // per glTF texture: false when dropped with a warning
};

// ---- top level ------------------------------------------------------------------------------

std::uint32_t le32(const char* p) {
  const auto* u = reinterpret_cast<const unsigned char*>(p);
  return std::uint32_t(u[0]) | std::uint32_t(u[1]) << 8 | std::uint32_t(u[2]) << 16 | std::uint32_t(u[3]) << 24;
}

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

Scene load(std::string_view bytes, const fs::path& baseDir, const fs::path& root,
           const LoadOptions& options) {
  if (bytes.size() > options.maxBytes)
    throw SceneError("", "the scene is " + std::to_string(bytes.size()) + " bytes, over the limit of " +
                             std::to_string(options.maxBytes));
  if (bytes.size() >= std::numeric_limits<unsigned int>::max())
    throw SceneError("", "the scene is too large");
  api::Sha256 digest;
  digest.update(bytes);
  const bool glb = bytes.size() >= 4 && bytes.substr(0, 4) == "glTF";
  const std::string_view jsonText = glb ? glbJson(bytes) : bytes;
  checkGltfText(jsonText, options);  // before any parser: nesting, UTF-8, overflowing numbers
  json doc;
  try {
    doc = json::parse(jsonText);
  } catch (const json::exception& e) {
    throw SceneError("", std::string(glb ? "the GLB JSON chunk" : "the file") +
                             " is neither valid JSON nor GLB: " + e.what());
  }
  std::vector<std::string> warnings;
  validateDocument(doc, baseDir, root, warnings);
  DecodeBudget budget = checkGltfDocument(doc, options);  // finite transforms; accessor expansion charged
  // EXT_meshopt_compression is decoded into a plain GLB before tinygltf sees the file, KHR_draco_mesh_compression
  // into the model right after (GltfCompression.h).
  std::string decodedBytes;
  std::string_view source = bytes;
  bool sourceGlb = glb;
  const bool meshopt = gltf::usesMeshopt(doc), draco = gltf::usesDraco(doc);
  if (meshopt || draco) {
    try {
      decodedBytes = packGltf(bytes, baseDir, root, options.maxBytes, true).bytes;
    } catch (const PackError& e) {
      throw SceneError(e.pointer, e.what());
    }
    if (meshopt) decodedBytes = gltf::decodeMeshopt(decodedBytes, budget);  // charged against --max-decode-bytes
    if (draco) decodedBytes = gltf::prepareDraco(decodedBytes);
    source = decodedBytes;
    sourceGlb = true;
  }

  FsContext fsContext;
  fsContext.root = root;
  fsContext.baseDir = baseDir;
  fsContext.budget = options.maxBytes - bytes.size();
  fsContext.digest = &digest;
  tinygltf::TinyGLTF loader;
  loader.SetFsCallbacks({&fsFileExists, &fsExpandFilePath, &fsReadWholeFile, &fsWriteWholeFile, &fsContext});
  loader.SetImageLoader(&loadImageData, &budget);
  loader.SetStoreOriginalJSONForExtrasAndExtensions(true);
  tinygltf::Model model;
  std::string err, warn;
  bool ok = false;
  try {
    const std::string base = baseDir.string();
    ok = sourceGlb ? loader.LoadBinaryFromMemory(&model, &err, &warn,
                                                 reinterpret_cast<const unsigned char*>(source.data()),
                                                 static_cast<unsigned int>(source.size()), base)
                   : loader.LoadASCIIFromString(&model, &err, &warn, source.data(),
                                                static_cast<unsigned int>(source.size()), base);
  } catch (const std::exception& e) {
    err += e.what();
    ok = false;
  }
  if (!ok) {
    budget.rethrowImageError();
    while (!err.empty() && (err.back() == '\n' || err.back() == ' ')) err.pop_back();
    for (auto& c : err)
      if (c == '\n') c = ';';
    throw SceneError("", "invalid glTF: " + (err.empty() ? std::string("unknown error") : err));
  }
  gltf::decodeDraco(model, options.maxBytes);
  Scene scene = Converter(model, options.maxBytes).run();
  scene.warnings.insert(scene.warnings.begin(), warnings.begin(), warnings.end());
  checkSceneMagnitudes(scene, doc);  // world-space positions, camera and lights: finite, bounded
  scene.digest = "sha256:" + digest.finishHex();
  scene.features = computeFeatures(scene);
  return scene;
}

fs::path canonicalRoot(const fs::path& root) {
  if (root.empty()) return {};
  std::error_code ec;
  fs::path r = fs::canonical(root, ec);
  if (ec || !fs::is_directory(r))
    throw SceneError("", "the asset root " + root.string() + " is not a directory");
  return r;
}

}  // namespace

Scene loadScene(const fs::path& file, const LoadOptions& options) {
  std::error_code ec;
  const fs::path canon = fs::weakly_canonical(fs::absolute(file, ec), ec);
  if (ec || !fs::is_regular_file(canon))
    throw SceneError("", "scene file " + file.string() + " does not exist or is not a regular file");
  const fs::path root = options.assetRoot.empty() ? canon.parent_path() : canonicalRoot(options.assetRoot);
  if (!pathIsInside(root, canon))
    throw SceneError("", "scene file " + file.string() + " is outside the asset root " + root.string());
  const auto size = fs::file_size(canon, ec);
  if (ec) throw SceneError("", "cannot read " + file.string() + ": " + ec.message());
  if (size > options.maxBytes)
    throw SceneError("", "the scene is " + std::to_string(size) + " bytes, over the limit of " +
                             std::to_string(options.maxBytes));
  std::string bytes(size, '\0');
  std::ifstream in(canon, std::ios::binary);
  if (!in.read(bytes.data(), std::streamsize(size)))
    throw SceneError("", "cannot read " + file.string());
  Scene scene = load(bytes, canon.parent_path(), root, options);
  scene.name = file.stem().string();
  return scene;
}

Scene loadSceneFromMemory(std::string_view bytes, const LoadOptions& options) {
  const fs::path root = canonicalRoot(options.assetRoot);
  return load(bytes, root, root, options);
}

}  // namespace radiant
