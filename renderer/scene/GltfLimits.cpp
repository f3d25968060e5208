#include "renderer/scene/GltfLimits.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <set>
#include <vector>

#include <stb/stb_image.h>  // declarations only: libstb (the library tinygltf decodes with) implements them
#include <webp/decode.h>

#include "api/JsonLimits.h"

namespace radiant {

using nlohmann::json;

namespace {

constexpr const char* kDecodeFlag = "--max-decode-bytes";

std::string at(const std::string& base, std::size_t i) { return base + "/" + std::to_string(i); }
std::string at(const std::string& base, const std::string& key) {
  std::string out = base + "/";
  for (char c : key) out += c == '~' ? "~0" : c == '/' ? "~1" : std::string(1, c);
  return out;
}

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

const json* member(const json& o, const char* key) {
  if (!o.is_object()) return nullptr;
  const auto it = o.find(key);
  return it == o.end() ? nullptr : &*it;
}

const json& arrayOf(const json& doc, const char* key) {
  static const json kEmpty = json::array();
  const json* a = member(doc, key);
  return a && a->is_array() ? *a : kEmpty;
}

// Every number that the loader narrows to float or int must survive the conversion. "extras" are
// the application's and are never converted.
void checkNumbersFit(const json& doc) {
  std::vector<std::pair<const json*, std::string>> todo{{&doc, ""}};
  while (!todo.empty()) {
    auto [v, ptr] = std::move(todo.back());
    todo.pop_back();
    if (v->is_object()) {
      for (auto it = v->begin(); it != v->end(); ++it)
        if (it.key() != "extras") todo.emplace_back(&it.value(), at(ptr, it.key()));
    } else if (v->is_array()) {
      for (std::size_t i = 0; i < v->size(); ++i) todo.emplace_back(&(*v)[i], at(ptr, i));
    } else if (v->is_number_float()) {
      const double d = v->get<double>();
      if (!(std::fabs(d) <= std::numeric_limits<float>::max()))
        throw SceneError(ptr, ptr + ": " + number(d) + " does not fit a 32-bit float");
    } else if (v->is_number_integer()) {
      // Indices, counts and byte lengths: 2^32 is beyond any file this loader accepts.
      const bool big = v->is_number_unsigned() ? v->get<std::uint64_t>() > (1ull << 32)
                                               : std::llabs(v->get<std::int64_t>()) > (1ll << 32);
      if (big) throw SceneError(ptr, ptr + ": " + api::truncateUtf8(v->dump(), 30) + " is too large an integer");
    }
  }
}

void checkMagnitude(const json& v, const std::string& ptr, double max, const char* what) {
  if (v.is_number() && !(std::fabs(v.get<double>()) <= max))
    throw SceneError(ptr, ptr + ": " + what + " " + number(v.get<double>()) + " is beyond +-" + number(max));
}

void checkComponents(const json& node, const char* key, const std::string& nodePtr, double max, const char* what) {
  const json* a = member(node, key);
  if (!a || !a->is_array()) return;
  for (std::size_t k = 0; k < a->size(); ++k) checkMagnitude((*a)[k], at(at(nodePtr, key), k), max, what);
}

void checkTransforms(const json& doc) {
  const json& nodes = arrayOf(doc, "nodes");
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const std::string ptr = at("/nodes", i);
    checkComponents(nodes[i], "translation", ptr, kMaxCoordinate, "translation");
    checkComponents(nodes[i], "scale", ptr, kMaxCoordinate, "scale factor");
    checkComponents(nodes[i], "matrix", ptr, kMaxCoordinate, "matrix element");
    checkComponents(nodes[i], "rotation", ptr, kMaxCoordinate, "quaternion component");
    if (const json* r = member(nodes[i], "rotation"); r && r->is_array() && r->size() == 4) {
      double len2 = 0;
      for (const auto& q : *r) len2 += q.is_number() ? q.get<double>() * q.get<double>() : 0.0;
      if (!(len2 > 1e-12))
        throw SceneError(at(ptr, "rotation"), at(ptr, "rotation") + ": a zero quaternion is no rotation");
    }
  }
  const json& cameras = arrayOf(doc, "cameras");
  for (std::size_t i = 0; i < cameras.size(); ++i) {
    const std::string ptr = at("/cameras", i);
    if (const json* p = member(cameras[i], "perspective")) {
      if (const json* y = member(*p, "yfov"); y && y->is_number() && !(y->get<double>() < M_PI))
        throw SceneError(at(at(ptr, "perspective"), "yfov"),
                         at(at(ptr, "perspective"), "yfov") + ": " + number(y->get<double>()) + " rad is not below pi");
      for (const char* k : {"znear", "zfar", "aspectRatio"})
        if (const json* v = member(*p, k)) checkMagnitude(*v, at(at(ptr, "perspective"), k), kMaxCoordinate, k);
    }
    if (const json* o = member(cameras[i], "orthographic"))
      for (const char* k : {"xmag", "ymag", "znear", "zfar"})
        if (const json* v = member(*o, k)) checkMagnitude(*v, at(at(ptr, "orthographic"), k), kMaxCoordinate, k);
  }
  // KHR_lights_punctual: radiometric values are finite and non-negative.
  const json* ext = member(doc, "extensions");
  const json* lp = ext ? member(*ext, "KHR_lights_punctual") : nullptr;
  const json* lights = lp ? member(*lp, "lights") : nullptr;
  if (lights && lights->is_array())
    for (std::size_t i = 0; i < lights->size(); ++i) {
      const std::string ptr = at("/extensions/KHR_lights_punctual/lights", i);
      const json& l = (*lights)[i];
      if (const json* v = member(l, "intensity"); v && v->is_number() && !(v->get<double>() >= 0 && v->get<double>() <= 1e15))
        throw SceneError(at(ptr, "intensity"), at(ptr, "intensity") + ": " + number(v->get<double>()) + " is outside [0, 1e15]");
      if (const json* c = member(l, "color"); c && c->is_array())
        for (std::size_t k = 0; k < c->size(); ++k)
          if ((*c)[k].is_number() && !((*c)[k].get<double>() >= 0 && (*c)[k].get<double>() <= 1e6))
            throw SceneError(at(at(ptr, "color"), k),
                             at(at(ptr, "color"), k) + ": " + number((*c)[k].get<double>()) + " is outside [0, 1e6]");
      if (const json* v = member(l, "range")) checkMagnitude(*v, at(ptr, "range"), kMaxCoordinate, "range");
    }
  const json& materials = arrayOf(doc, "materials");
  for (std::size_t i = 0; i < materials.size(); ++i) {
    const json* e = member(materials[i], "extensions");
    const json* s = e ? member(*e, "KHR_materials_emissive_strength") : nullptr;
    const json* v = s ? member(*s, "emissiveStrength") : nullptr;
    const std::string ptr = at("/materials", i) + "/extensions/KHR_materials_emissive_strength/emissiveStrength";
    if (v && v->is_number() && !(v->get<double>() >= 0 && v->get<double>() <= 1e9))
      throw SceneError(ptr, ptr + ": " + number(v->get<double>()) + " is outside [0, 1e9]");
  }
}

std::uint64_t accessorCount(const json& accessors, const json* index) {
  if (!index || !index->is_number_unsigned() || index->get<std::uint64_t>() >= accessors.size()) return 0;
  const json* c = member(accessors[index->get<std::size_t>()], "count");
  return c && c->is_number_unsigned() ? c->get<std::uint64_t>() : 0;
}

std::uint64_t accessorComponents(const json& accessors, const json* index) {
  if (!index || !index->is_number_unsigned() || index->get<std::uint64_t>() >= accessors.size()) return 0;
  const json* t = member(accessors[index->get<std::size_t>()], "type");
  if (!t || !t->is_string()) return 0;
  static const std::pair<const char*, int> kTypes[] = {{"SCALAR", 1}, {"VEC2", 2}, {"VEC3", 3}, {"VEC4", 4},
                                                        {"MAT2", 4},   {"MAT3", 9}, {"MAT4", 16}};
  for (const auto& [name, n] : kTypes)
    if (*t == name) return std::uint64_t(n);
  return 0;
}

// What the loader allocates for every mesh instance (node x primitive) before it is done with it:
// each attribute it reads as floats plus its typed copy (2 x count x components x 4 bytes), the
// normals and tangents it may generate (28 bytes a vertex), and the index list (twice for a list,
// four times for strips and fans, which become lists of up to 3x the indices). An accessor without
// a bufferView costs the same as one with: the loader fills it with zeros (glTF spec 3.6.2.3).
void chargeAccessorExpansion(const json& doc, DecodeBudget& budget) {
  const json& nodes = arrayOf(doc, "nodes");
  const json& meshes = arrayOf(doc, "meshes");
  const json& accessors = arrayOf(doc, "accessors");
  std::uint64_t total = 0;
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const json* m = member(nodes[i], "mesh");
    if (!m || !m->is_number_unsigned() || m->get<std::uint64_t>() >= meshes.size()) continue;
    const std::size_t mesh = m->get<std::size_t>();
    const json* prims = member(meshes[mesh], "primitives");
    if (!prims || !prims->is_array()) continue;
    for (std::size_t p = 0; p < prims->size(); ++p) {
      const json* attrs = member((*prims)[p], "attributes");
      if (!attrs || !attrs->is_object()) continue;
      const json* pos = member(*attrs, "POSITION");
      const std::uint64_t n = accessorCount(accessors, pos);
      std::uint64_t bytes = n * 28;
      for (const char* a : {"POSITION", "NORMAL", "TEXCOORD_0", "TEXCOORD_1", "TANGENT"}) {
        const json* acc = member(*attrs, a);
        bytes += accessorCount(accessors, acc) * accessorComponents(accessors, acc) * 8;
      }
      const json* mode = member((*prims)[p], "mode");
      const bool list = !mode || (mode->is_number() && mode->get<double>() == 4);
      const json* indices = member((*prims)[p], "indices");
      bytes += (indices ? accessorCount(accessors, indices) : n) * 4 * (list ? 2 : 4);
      total += bytes;
      if (total > budget.remaining()) {
        const std::string where = pos && pos->is_number_unsigned() ? at("/accessors", pos->get<std::size_t>()) + "/count"
                                                                   : at(at(at("/meshes", mesh), "primitives"), p);
        budget.charge(total, where,
                      "node " + std::to_string(i) + " (mesh " + std::to_string(mesh) + " primitive " +
                          std::to_string(p) + ", " + std::to_string(n) +
                          " vertices) brings the scene's expanded geometry to " + std::to_string(total) + " bytes");
      }
    }
  }
  budget.charge(total, "", "the scene's expanded geometry");
}

// The default scene's nodes in the loader's depth-first order (GltfConverter.cpp, walkScene): the
// camera is the first node with one, lights are pushed one per node in this order.
std::vector<std::size_t> depthFirstNodes(const json& doc) {
  const json& nodes = arrayOf(doc, "nodes");
  std::vector<std::size_t> roots;
  const json& scenes = arrayOf(doc, "scenes");
  if (!scenes.empty()) {
    const json* s = member(doc, "scene");
    const std::size_t si = s && s->is_number_unsigned() && s->get<std::size_t>() < scenes.size() ? s->get<std::size_t>() : 0;
    for (const auto& r : arrayOf(scenes[si], "nodes"))
      if (r.is_number_unsigned() && r.get<std::size_t>() < nodes.size()) roots.push_back(r.get<std::size_t>());
  } else {
    std::vector<bool> child(nodes.size(), false);
    for (const auto& n : nodes)
      for (const auto& c : arrayOf(n, "children"))
        if (c.is_number_unsigned() && c.get<std::size_t>() < nodes.size()) child[c.get<std::size_t>()] = true;
    for (std::size_t i = 0; i < nodes.size(); ++i)
      if (!child[i]) roots.push_back(i);
  }
  std::vector<std::size_t> order, stack(roots.rbegin(), roots.rend());
  std::vector<bool> seen(nodes.size(), false);
  while (!stack.empty()) {
    const std::size_t i = stack.back();
    stack.pop_back();
    if (seen[i]) continue;
    seen[i] = true;
    order.push_back(i);
    const json& children = arrayOf(nodes[i], "children");
    for (std::size_t k = children.size(); k-- > 0;)
      if (children[k].is_number_unsigned() && children[k].get<std::size_t>() < nodes.size())
        stack.push_back(children[k].get<std::size_t>());
  }
  return order;
}

int firstCameraNode(const json& doc) {
  const json& nodes = arrayOf(doc, "nodes");
  for (std::size_t i : depthFirstNodes(doc))
    if (member(nodes[i], "camera")) return int(i);
  return -1;
}

// The node of the scene's light number `light` (the loader adds one per node with the extension).
int lightNode(const json& doc, std::size_t light) {
  const json& nodes = arrayOf(doc, "nodes");
  std::size_t n = 0;
  for (std::size_t i : depthFirstNodes(doc)) {
    const json* e = member(nodes[i], "extensions");
    if (e && member(*e, "KHR_lights_punctual") && n++ == light) return int(i);
  }
  return -1;
}

bool finiteWithin(const glm::vec3& v, double max) {
  for (int k = 0; k < 3; ++k)
    if (!(std::fabs(double(v[k])) <= max)) return false;
  return true;
}

std::string show(const glm::vec3& v) { return "(" + number(v.x) + ", " + number(v.y) + ", " + number(v.z) + ")"; }

}  // namespace

void DecodeBudget::charge(std::size_t bytes, const std::string& pointer, const std::string& what) {
  if (bytes > remaining_)
    throw SceneLimitError(pointer,
                          what + ": needs " + std::to_string(bytes) + " bytes of memory, " +
                              std::to_string(remaining_) + " of this server's decode budget of " +
                              std::to_string(limit_) + " bytes are left (radiantd " + kDecodeFlag + ")",
                          kDecodeFlag);
  if (reserve_) reserve_(bytes);
  remaining_ -= bytes;
}

bool isWebp(const unsigned char* bytes, std::size_t size) {
  return size >= 12 && std::memcmp(bytes, "RIFF", 4) == 0 && std::memcmp(bytes + 8, "WEBP", 4) == 0;
}

std::optional<ImageHeader> readImageHeader(const unsigned char* bytes, std::size_t size) {
  if (size == 0 || size > std::size_t(std::numeric_limits<int>::max())) return std::nullopt;
  ImageHeader h;
  if (isWebp(bytes, size)) {
    // Still images only: an animated WebP has no single texture to show.
    WebPBitstreamFeatures f;
    if (WebPGetFeatures(bytes, size, &f) != VP8_STATUS_OK || f.has_animation || f.width <= 0 || f.height <= 0)
      return std::nullopt;
    h.width = f.width;
    h.height = f.height;
    h.channels = 4;
    return h;
  }
  if (!stbi_info_from_memory(bytes, int(size), &h.width, &h.height, &h.channels)) return std::nullopt;
  if (h.width <= 0 || h.height <= 0) return std::nullopt;
  h.sixteenBit = stbi_is_16_bit_from_memory(bytes, int(size)) != 0;
  return h;
}

bool isGltfImageFormat(const unsigned char* bytes, std::size_t size) {
  const bool png = size >= 8 && std::memcmp(bytes, "\x89PNG\r\n\x1a\n", 8) == 0;
  const bool jpeg = size >= 3 && bytes[0] == 0xFF && bytes[1] == 0xD8 && bytes[2] == 0xFF;
  return png || jpeg || isWebp(bytes, size);
}

bool DecodeBudget::chargeImage(const unsigned char* bytes, std::size_t size, int imageIndex, std::string* err) {
  const std::string ptr = "/images/" + std::to_string(imageIndex);
  // glTF 2.0 images are PNG or JPEG (WebP with EXT_texture_webp). stb_image, behind tinygltf, reads
  // more (BMP, TGA, GIF, PSD, HDR, PIC, PNM), and its readers of those are not hardened: a 680-byte GLB
  // holding an 8-pixel Radiance HDR image with a zero RLE run kept its decoder looping for good (found by
  // tests/fuzz/image_fuzzer.cpp, 2026-12-04; tests/data/crashers/gltf/hdr_image_whose_rle_hangs_stb.glb).
  if (!isGltfImageFormat(bytes, size)) {
    imageError_.emplace(ptr, ptr + ": not a PNG, JPEG or WebP image (glTF 2.0 images are PNG or JPEG, WebP with "
                                   "EXT_texture_webp; convert other formats to PNG)", "");
    if (err) *err += imageError_->what() + std::string("\n");
    return false;
  }
  const auto header = readImageHeader(bytes, size);
  if (!header) {
    // stb refuses, while reading the header, a PNG whose pixels would exceed 2^30 bytes; its
    // IHDR still says how large it claims to be.
    const auto be32 = [&](std::size_t i) {
      return std::uint32_t(bytes[i]) << 24 | std::uint32_t(bytes[i + 1]) << 16 | std::uint32_t(bytes[i + 2]) << 8 | bytes[i + 3];
    };
    if (size >= 24 && std::memcmp(bytes, "\x89PNG\r\n\x1a\n", 8) == 0 && be32(16) > 0 && be32(20) > 0)
      imageError_.emplace(ptr,
                          ptr + ": a " + std::to_string(be32(16)) + "x" + std::to_string(be32(20)) +
                              " PNG decodes to more than 2^30 bytes, above this server's decode budget of " +
                              std::to_string(limit_) + " bytes (radiantd " + kDecodeFlag + ")",
                          kDecodeFlag);
    else
      imageError_.emplace(ptr, ptr + ": not an image this loader decodes (PNG, JPEG, still WebP)", "");
    if (err) *err += imageError_->what() + std::string("\n");
    return false;
  }
  // tinygltf expands to RGBA at the file's depth; the Scene keeps an 8-bit RGBA copy.
  const std::uint64_t pixels = std::uint64_t(header->width) * std::uint64_t(header->height);
  const std::uint64_t need = pixels * 4 * (header->sixteenBit ? 2 : 1) + pixels * 4;
  if (need > remaining_) {
    imageError_.emplace(ptr,
                        ptr + ": a " + std::to_string(header->width) + "x" + std::to_string(header->height) +
                            " image needs " + std::to_string(need) + " bytes decoded, " + std::to_string(remaining_) +
                            " of this server's decode budget of " + std::to_string(limit_) +
                            " bytes are left (radiantd " + kDecodeFlag + ")",
                        kDecodeFlag);
    if (err) *err += imageError_->what() + std::string("\n");
    return false;
  }
  if (reserve_) {
    try {
      reserve_(std::size_t(need));
    } catch (...) {  // tinygltf's callback must not throw: rethrown by rethrowImageError()
      reserveError_ = std::current_exception();
      if (err) *err += ptr + ": no decode memory\n";
      return false;
    }
  }
  remaining_ -= std::size_t(need);
  return true;
}

void DecodeBudget::rethrowImageError() const {
  if (reserveError_) std::rethrow_exception(reserveError_);
  if (!imageError_) return;
  if (!imageError_->flag.empty()) throw *imageError_;
  throw SceneError(imageError_->pointer, imageError_->what());
}

void checkGltfText(std::string_view jsonText, const LoadOptions& options) {
  const auto problem = api::scanJson(jsonText, options.maxJsonDepth);
  if (!problem) return;
  if (problem->kind == api::JsonScanProblem::Kind::TooDeep)
    throw SceneLimitError(problem->pointer,
                          problem->detail + "; this server's limit is radiantd --max-json-depth " +
                              std::to_string(options.maxJsonDepth),
                          "--max-json-depth");
  throw SceneError(problem->pointer, problem->detail);
}

DecodeBudget checkGltfDocument(const json& doc, const LoadOptions& options) {
  checkNumbersFit(doc);
  checkTransforms(doc);
  DecodeBudget budget(options.maxDecodedBytes, options.reserveDecoded);
  chargeAccessorExpansion(doc, budget);
  return budget;
}

void checkSceneMagnitudes(const Scene& scene, const json& doc) {
  for (const auto& m : scene.meshes) {
    const std::string prim = "/meshes/" + std::to_string(m.mesh) + "/primitives/" + std::to_string(m.primitive);
    for (const auto& p : m.positions) {
      if (!(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)))
        throw SceneError(prim + "/attributes/POSITION",
                         "mesh " + std::to_string(m.mesh) + " primitive " + std::to_string(m.primitive) + " of node " +
                             std::to_string(m.node) + " has a vertex at " + show(p) +
                             " in world space: positions must be finite");
      if (!finiteWithin(p, kMaxCoordinate))
        throw SceneError("/nodes/" + std::to_string(m.node),
                         "node " + std::to_string(m.node) + " places a vertex of mesh " + std::to_string(m.mesh) +
                             " at " + show(p) + " in world space, beyond +-" + number(kMaxCoordinate));
    }
    const std::vector<glm::vec2>* uvs[] = {&m.uv0, &m.uv1};
    for (int k = 0; k < 2; ++k)
      for (const auto& t : *uvs[k])
        if (!(std::isfinite(t.x) && std::isfinite(t.y)))
          throw SceneError(prim + "/attributes/TEXCOORD_" + std::to_string(k), "texture coordinates must be finite");
  }
  if (scene.camera.fromFile) {
    const glm::mat4& w = scene.camera.world;
    bool ok = true;
    for (int c = 0; c < 4; ++c) ok = ok && finiteWithin(glm::vec3(w[c]), c == 3 ? kMaxCoordinate : 1e3);
    if (!ok) {
      const int node = firstCameraNode(doc);
      throw SceneError(node >= 0 ? "/nodes/" + std::to_string(node) : "",
                       "the camera node's world position " + show(glm::vec3(w[3])) + " is not finite or beyond +-" +
                           number(kMaxCoordinate));
    }
  }
  for (std::size_t i = 0; i < scene.lights.size(); ++i) {
    const Light& l = scene.lights[i];
    if (!finiteWithin(l.position, kMaxCoordinate) || !finiteWithin(l.direction, 2.0)) {
      const int node = lightNode(doc, i);
      throw SceneError(node >= 0 ? "/nodes/" + std::to_string(node) : "",
                       "light \"" + api::truncateUtf8(l.name, 60) + "\" is placed at " + show(l.position) +
                           " in world space: not finite or beyond +-" + number(kMaxCoordinate));
    }
  }
}

}  // namespace radiant
