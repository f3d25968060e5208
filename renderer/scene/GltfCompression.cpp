#include "renderer/scene/GltfCompression.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <vector>

#include <draco/compression/decode.h>
#include <meshoptimizer.h>
#include <tiny_gltf.h>  // shared library: no TINYGLTF_IMPLEMENTATION

#include "api/JsonLimits.h"
#include "renderer/scene/GltfLimits.h"
#include "renderer/scene/GltfLoader.h"

namespace radiant::gltf {
namespace {

using json = nlohmann::json;

std::uint32_t le32(const char* p) {
  const auto* u = reinterpret_cast<const unsigned char*>(p);
  return std::uint32_t(u[0]) | std::uint32_t(u[1]) << 8 | std::uint32_t(u[2]) << 16 | std::uint32_t(u[3]) << 24;
}
void put32(std::string& s, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) s.push_back(char((v >> (8 * i)) & 255));
}

std::uint64_t unsignedAt(const json& o, const char* key, const std::string& ptr, bool required = true) {
  const auto it = o.find(key);
  if (it == o.end() || !it->is_number_unsigned()) {
    if (!required) return 0;
    throw SceneError(ptr + "/" + key, std::string(key) + " must be a non-negative integer");
  }
  return it->get<std::uint64_t>();
}

std::pair<json, std::string> splitGlb(std::string_view glb) {
  if (glb.size() < 20 || glb.substr(0, 4) != "glTF") throw SceneError("", "expected a GLB");
  const std::uint32_t jsonLength = le32(glb.data() + 12);
  json doc = json::parse(glb.substr(20, jsonLength));
  const std::size_t binHeader = 20 + ((jsonLength + 3) & ~3u);
  std::string bin;
  if (binHeader + 8 <= glb.size())
    bin = std::string(glb.substr(binHeader + 8, std::min<std::size_t>(le32(glb.data() + binHeader), glb.size() - binHeader - 8)));
  return {std::move(doc), std::move(bin)};
}

std::string joinGlb(const json& doc, std::string bin) {
  bin.resize((bin.size() + 3) & ~std::size_t(3), '\0');
  std::string text = doc.dump();
  text.resize((text.size() + 3) & ~std::size_t(3), ' ');
  std::string result = "glTF";
  put32(result, 2);
  put32(result, std::uint32_t(28 + text.size() + bin.size()));
  put32(result, std::uint32_t(text.size()));
  put32(result, 0x4E4F534Au);
  result += text;
  put32(result, std::uint32_t(bin.size()));
  put32(result, 0x004E4942u);
  result += bin;
  return result;
}

// Reads the header and connectivity counts of a KHR_draco_mesh_compression stream before libdraco sees
// it, and returns the bytes libdraco will allocate for them. libdraco sizes its corner table and point
// arrays from these counts alone (a 150-byte stream asked it for 5.4 GB, tests/data/crashers/draco), so
// they are bounded here against the decode budget. The extension is written against Draco bitstream 2.2
// (KHR_draco_mesh_compression, "Overview"); older versions are refused, which also keeps libdraco's
// backwards-compatibility paths (fixed-width counts, 1.x edgebreaker) away from hostile input.
// Layout (draco/compression/point_cloud/point_cloud_decoder.cc, mesh/mesh_edgebreaker_decoder*.cc,
// mesh/mesh_sequential_decoder.cc): "DRACO", major, minor, encoder type, method, u16 flags, metadata when
// flags & 0x8000, then for edgebreaker: u8 traversal, varint vertices, varint faces, u8 attribute data,
// varint symbols, varint split symbols; for sequential: varint faces, varint points.
class DracoReader {
 public:
  DracoReader(const unsigned char* p, std::size_t n, const std::string& ptr) : p_(p), n_(n), ptr_(ptr) {}
  std::size_t remaining() const { return n_ - at_; }
  std::uint8_t byte() {
    if (at_ >= n_) fail("the Draco stream ends inside its header");
    return p_[at_++];
  }
  void skip(std::size_t bytes) {
    if (bytes > remaining()) fail("the Draco stream ends inside its metadata");
    at_ += bytes;
  }
  // LEB128 as draco/core/varint_decoding.h reads a uint32: at most 5 bytes, truncated to 32 bits.
  std::uint32_t varint() {
    std::uint64_t v = 0;
    for (int i = 0; i < 5; ++i) {
      const std::uint8_t b = byte();
      v |= std::uint64_t(b & 127u) << (7 * i);
      if (!(b & 128u)) return std::uint32_t(v);
    }
    fail("a Draco varint is longer than 5 bytes");
  }
  // draco/metadata/metadata_decoder.cc: metadata = varint entries {u8 name length, name, varint size > 0,
  // bytes}, varint sub-metadata {u8 name length, name, metadata}; geometry metadata = varint attribute
  // metadata {varint id, metadata}, then the geometry's metadata.
  // The stream holds each sub-metadata whole, in order, so reading them one after the other consumes
  // what libdraco's stack-ordered reader does.
  void skipMetadata() {
    std::uint64_t pending = 1;  // metadata still to read; each costs at least two bytes, so the loop is bounded
    for (bool first = true; pending > 0; first = false, --pending) {
      if (!first) skip(byte());  // a sub-metadata's name
      const std::uint32_t entries = varint();
      for (std::uint32_t e = 0; e < entries; ++e) {
        skip(byte());
        const std::uint32_t size = varint();
        if (size == 0) fail("a Draco metadata entry is empty");
        skip(size);
      }
      const std::uint32_t subs = varint();
      if (subs > remaining()) fail("the Draco metadata names more sub-metadata than the stream holds");
      pending += subs;
    }
  }
  [[noreturn]] void fail(const std::string& why) const { throw SceneError(ptr_, why); }

 private:
  const unsigned char* p_;
  std::size_t n_, at_ = 0;
  const std::string& ptr_;
};

std::size_t dracoDecodeBytes(const unsigned char* data, std::size_t size, std::size_t attributes,
                             const std::string& ptr) {
  DracoReader r(data, size, ptr);
  if (size < 5 || std::memcmp(data, "DRACO", 5) != 0) r.fail("the bufferView does not hold a Draco stream");
  r.skip(5);
  const int major = r.byte(), minor = r.byte();
  if (major != 2 || minor != 2)
    r.fail("Draco bitstream version " + std::to_string(major) + "." + std::to_string(minor) +
           " is not 2.2, the version KHR_draco_mesh_compression specifies");
  const std::uint8_t encoder = r.byte(), method = r.byte();
  if (encoder != 1) r.fail("the Draco stream holds a point cloud, not a triangle mesh");
  const std::uint16_t flags = std::uint16_t(r.byte() | r.byte() << 8);
  if (flags & 0x8000u) {
    const std::uint32_t attributeMetadata = r.varint();
    if (attributeMetadata > r.remaining()) r.fail("the Draco metadata names more attributes than the stream holds");
    for (std::uint32_t i = 0; i < attributeMetadata; ++i) {
      r.varint();
      r.skipMetadata();
    }
    r.skipMetadata();
  }
  // Bytes per face and per vertex libdraco holds while it decodes: edgebreaker's corner table (two ints
  // per corner, one per vertex), its processed-corner lists, and the mesh's faces; 16 bytes per point per
  // attribute for the decoded values.
  const std::uint64_t perPoint = 16 * std::max<std::size_t>(attributes, 1);
  std::uint64_t faces = 0, vertices = 0;
  if (method == 1) {
    r.byte();  // traversal decoder
    vertices = r.varint();
    faces = r.varint();
    r.byte();  // attribute data
    r.varint();  // symbols (libdraco checks faces against them)
    vertices += r.varint();  // split symbols add vertices
    return std::size_t(faces * 44 + vertices * (8 + perPoint));
  }
  if (method != 0) r.fail("unknown Draco encoder method " + std::to_string(method));
  faces = r.varint();
  vertices = r.varint();
  return std::size_t(faces * 12 + vertices * perPoint);
}

}  // namespace

bool usesDraco(const json& doc) {
  const auto meshes = doc.find("meshes");
  if (meshes == doc.end() || !meshes->is_array()) return false;
  for (const auto& m : *meshes)
    if (m.is_object() && m.contains("primitives") && m["primitives"].is_array())
      for (const auto& p : m["primitives"])
        if (p.is_object() && p.contains("extensions") && p["extensions"].is_object() &&
            p["extensions"].contains("KHR_draco_mesh_compression"))
          return true;
  return false;
}

std::string prepareDraco(std::string_view glb) {
  auto [doc, bin] = splitGlb(glb);
  for (auto& m : doc["meshes"])
    if (m.is_object() && m.contains("primitives"))
      for (auto& p : m["primitives"])
        if (p.is_object() && p.contains("extensions") && p["extensions"].is_object() &&
            p["extensions"].contains("KHR_draco_mesh_compression"))
          p.erase("indices");
  return joinGlb(doc, std::move(bin));
}

bool usesMeshopt(const json& doc) {
  const auto views = doc.find("bufferViews");
  if (views == doc.end() || !views->is_array()) return false;
  for (const auto& v : *views)
    if (v.is_object() && v.contains("extensions") && v["extensions"].is_object() &&
        v["extensions"].contains("EXT_meshopt_compression"))
      return true;
  return false;
}

namespace {

enum class MeshoptMode { Attributes, Triangles, Indices };
enum class MeshoptFilter { None, Octahedral, Quaternion, Exponential };

// One EXT_meshopt_compression bufferView, every field meshoptimizer relies on checked.
struct MeshoptView {
  std::size_t index = 0;
  std::string ptr;  // "/bufferViews/<index>/extensions/EXT_meshopt_compression"
  std::uint64_t offset = 0, length = 0, stride = 0, count = 0;
  MeshoptMode mode = MeshoptMode::Attributes;
  MeshoptFilter filter = MeshoptFilter::None;
};

// The extension's validity rules (EXT_meshopt_compression README, "JSON schema updates") are also
// meshoptimizer 0.18's preconditions, which Debian builds with assert() enabled: a stride that does
// not fit the mode or the filter aborts the process (meshopt_decodeFilterQuat: 'stride == 8'), so every
// one is checked here, before any meshopt_decode* call.
MeshoptView readMeshoptView(const json& v, std::size_t index, std::size_t binSize) {
  MeshoptView m;
  m.index = index;
  const std::string viewPtr = "/bufferViews/" + std::to_string(index);
  m.ptr = viewPtr + "/extensions/EXT_meshopt_compression";
  const json& e = v.at("extensions").at("EXT_meshopt_compression");
  if (!e.is_object()) throw SceneError(m.ptr, "EXT_meshopt_compression must be an object");
  if (unsignedAt(e, "buffer", m.ptr) != 0)
    throw SceneError(m.ptr + "/buffer", "the compressed bytes must be in a buffer with data");
  m.offset = unsignedAt(e, "byteOffset", m.ptr, false);
  m.length = unsignedAt(e, "byteLength", m.ptr);
  m.stride = unsignedAt(e, "byteStride", m.ptr);
  m.count = unsignedAt(e, "count", m.ptr);

  const auto mode = e.find("mode");
  if (mode == e.end() || !mode->is_string())
    throw SceneError(m.ptr + "/mode", "mode must be one of the strings ATTRIBUTES, TRIANGLES, INDICES");
  const std::string& modeName = mode->get_ref<const std::string&>();
  if (modeName == "ATTRIBUTES") m.mode = MeshoptMode::Attributes;
  else if (modeName == "TRIANGLES") m.mode = MeshoptMode::Triangles;
  else if (modeName == "INDICES") m.mode = MeshoptMode::Indices;
  else throw SceneError(m.ptr + "/mode", "unknown mode \"" + api::truncateUtf8(modeName, 40) + "\" (ATTRIBUTES, TRIANGLES or INDICES)");

  std::string filterName = "NONE";
  if (const auto filter = e.find("filter"); filter != e.end()) {
    if (!filter->is_string())
      throw SceneError(m.ptr + "/filter", "filter must be one of the strings NONE, OCTAHEDRAL, QUATERNION, EXPONENTIAL");
    filterName = filter->get<std::string>();
  }
  if (filterName == "NONE") m.filter = MeshoptFilter::None;
  else if (filterName == "OCTAHEDRAL") m.filter = MeshoptFilter::Octahedral;
  else if (filterName == "QUATERNION") m.filter = MeshoptFilter::Quaternion;
  else if (filterName == "EXPONENTIAL") m.filter = MeshoptFilter::Exponential;
  else throw SceneError(m.ptr + "/filter", "unknown filter \"" + api::truncateUtf8(filterName, 40) + "\" (NONE, OCTAHEDRAL, QUATERNION or EXPONENTIAL)");

  const std::string stride = std::to_string(m.stride);
  if (m.mode == MeshoptMode::Attributes) {
    if (m.stride == 0 || m.stride > 256 || m.stride % 4 != 0)  // meshopt_decodeVertexBuffer: 'vertex_size % 4 == 0'
      throw SceneError(m.ptr + "/byteStride", "ATTRIBUTES needs a byteStride that is a multiple of 4 from 4 to 256, not " + stride);
  } else {
    if (m.stride != 2 && m.stride != 4)  // meshopt_decodeIndex*: 'index_size == 2 || index_size == 4'
      throw SceneError(m.ptr + "/byteStride", modeName + " needs a byteStride of 2 or 4, not " + stride);
    if (m.filter != MeshoptFilter::None)
      throw SceneError(m.ptr + "/filter", "filter " + filterName + " applies to ATTRIBUTES only; " + modeName + " needs NONE");
    if (m.mode == MeshoptMode::Triangles && m.count % 3 != 0)  // meshopt_decodeIndexBuffer: 'index_count % 3 == 0'
      throw SceneError(m.ptr + "/count", "TRIANGLES needs a count that is a multiple of 3, not " + std::to_string(m.count));
  }
  // meshopt_decodeFilterOct: 'stride == 4 || stride == 8'; Quat: 'stride == 8'; Exp: 'stride % 4 == 0'.
  if ((m.filter == MeshoptFilter::Octahedral && m.stride != 4 && m.stride != 8) ||
      (m.filter == MeshoptFilter::Quaternion && m.stride != 8))
    throw SceneError(m.ptr + "/byteStride", "filter " + filterName + " needs a byteStride of " +
                                                (m.filter == MeshoptFilter::Quaternion ? "8" : "4 or 8") + ", not " + stride);
  if (m.count == 0) throw SceneError(m.ptr + "/count", "count must be at least 1");

  if (m.offset > binSize || m.length > binSize - m.offset)
    throw SceneError(m.ptr, "the compressed bytes [" + std::to_string(m.offset) + ", " + std::to_string(m.offset + m.length) +
                                ") lie outside the buffer of " + std::to_string(binSize) + " bytes");
  // The parent view must describe the decoded layout (the README's first two rules); count x stride
  // cannot overflow once byteLength equals it.
  const auto parentLength = v.find("byteLength");
  if (parentLength == v.end() || !parentLength->is_number_unsigned() || m.count > UINT64_MAX / m.stride ||
      parentLength->get<std::uint64_t>() != m.count * m.stride)
    throw SceneError(viewPtr + "/byteLength", "the bufferView's byteLength must be count x byteStride = " +
                                                  std::to_string(m.count) + " x " + stride);
  if (const auto parentStride = v.find("byteStride");
      parentStride != v.end() && !(parentStride->is_number_unsigned() && parentStride->get<std::uint64_t>() == m.stride))
    throw SceneError(viewPtr + "/byteStride", "the bufferView's byteStride must equal the extension's byteStride " + stride);
  return m;
}

std::vector<unsigned char> decode(const MeshoptView& m, const unsigned char* src) {
  std::vector<unsigned char> decoded(m.count * m.stride);
  const int rc = m.mode == MeshoptMode::Attributes ? meshopt_decodeVertexBuffer(decoded.data(), m.count, m.stride, src, m.length)
                 : m.mode == MeshoptMode::Triangles ? meshopt_decodeIndexBuffer(decoded.data(), m.count, m.stride, src, m.length)
                                                    : meshopt_decodeIndexSequence(decoded.data(), m.count, m.stride, src, m.length);
  if (rc != 0) throw SceneError(m.ptr, "the meshopt stream is corrupt (meshoptimizer error " + std::to_string(rc) + ")");
  switch (m.filter) {
    case MeshoptFilter::None: break;
    case MeshoptFilter::Octahedral: meshopt_decodeFilterOct(decoded.data(), m.count, m.stride); break;
    case MeshoptFilter::Quaternion: meshopt_decodeFilterQuat(decoded.data(), m.count, m.stride); break;
    case MeshoptFilter::Exponential: meshopt_decodeFilterExp(decoded.data(), m.count, m.stride); break;
  }
  return decoded;
}

}  // namespace

std::string decodeMeshopt(std::string_view glb, DecodeBudget& budget) {
  if (glb.size() < 20 || glb.substr(0, 4) != "glTF") throw SceneError("", "EXT_meshopt_compression: expected a GLB");
  const std::uint32_t jsonLength = le32(glb.data() + 12);
  json doc = json::parse(glb.substr(20, jsonLength));
  const std::size_t binHeader = 20 + ((jsonLength + 3) & ~3u);
  std::string_view bin;
  if (binHeader + 8 <= glb.size()) bin = glb.substr(binHeader + 8, std::min<std::size_t>(le32(glb.data() + binHeader), glb.size() - binHeader - 8));
  json& views = doc["bufferViews"];
  // Every view is checked and its decoded size charged before the first is decoded.
  std::vector<MeshoptView> compressed;
  for (std::size_t i = 0; i < views.size(); ++i) {
    const json& v = views[i];
    if (!v.is_object() || !v.contains("extensions") || !v["extensions"].is_object() ||
        !v["extensions"].contains("EXT_meshopt_compression"))
      continue;
    compressed.push_back(readMeshoptView(v, i, bin.size()));
    const MeshoptView& m = compressed.back();
    budget.charge(std::size_t(m.count * m.stride), m.ptr + "/count",
                  "EXT_meshopt_compression bufferView " + std::to_string(i) + " decodes to " + std::to_string(m.count) +
                      " x " + std::to_string(m.stride) + " bytes");
  }
  std::string out(bin);
  for (const MeshoptView& m : compressed) {
    const std::vector<unsigned char> decoded = decode(m, reinterpret_cast<const unsigned char*>(bin.data() + m.offset));
    json& v = views[m.index];
    out.resize((out.size() + 15) & ~std::size_t(15), '\0');
    const std::size_t at = out.size();
    out.append(reinterpret_cast<const char*>(decoded.data()), decoded.size());
    v["buffer"] = 0;
    v["byteOffset"] = at;
    v["byteLength"] = decoded.size();
    if (m.mode == MeshoptMode::Attributes) v["byteStride"] = m.stride;
    else v.erase("byteStride");
    v["extensions"].erase("EXT_meshopt_compression");
    if (v["extensions"].empty()) v.erase("extensions");
  }
  // Only buffer 0 holds data now; fallback buffers are referenced by nothing.
  out.resize((out.size() + 3) & ~std::size_t(3), '\0');
  doc["buffers"] = json::array({{{"byteLength", out.size()}}});
  for (const char* key : {"extensionsUsed", "extensionsRequired"})
    if (doc.contains(key) && doc[key].is_array()) {
      json kept = json::array();
      for (const auto& e : doc[key])
        if (e != "EXT_meshopt_compression") kept.push_back(e);
      doc[key] = kept;
    }
  return joinGlb(doc, std::move(out));
}

void decodeDraco(tinygltf::Model& model, std::size_t maxBytes) {
  std::size_t budget = maxBytes;
  for (std::size_t mi = 0; mi < model.meshes.size(); ++mi)
    for (std::size_t pi = 0; pi < model.meshes[mi].primitives.size(); ++pi) {
      tinygltf::Primitive& prim = model.meshes[mi].primitives[pi];
      const auto ext = prim.extensions.find("KHR_draco_mesh_compression");
      if (ext == prim.extensions.end()) continue;
      const std::string ptr = "/meshes/" + std::to_string(mi) + "/primitives/" + std::to_string(pi) +
                              "/extensions/KHR_draco_mesh_compression";
      const tinygltf::Value& e = ext->second;
      if (!e.IsObject() || !e.Has("bufferView") || !e.Get("bufferView").IsNumber() || !e.Has("attributes"))
        throw SceneError(ptr, "needs bufferView and attributes");
      const int viewIndex = e.Get("bufferView").GetNumberAsInt();
      if (viewIndex < 0 || std::size_t(viewIndex) >= model.bufferViews.size())
        throw SceneError(ptr + "/bufferView", "bufferView " + std::to_string(viewIndex) + " does not exist");
      const tinygltf::BufferView& view = model.bufferViews[std::size_t(viewIndex)];
      if (view.buffer < 0 || std::size_t(view.buffer) >= model.buffers.size() ||
          view.byteOffset + view.byteLength > model.buffers[std::size_t(view.buffer)].data.size())
        throw SceneError(ptr + "/bufferView", "bufferView " + std::to_string(viewIndex) + " lies outside its buffer");
      const unsigned char* stream = model.buffers[std::size_t(view.buffer)].data.data() + view.byteOffset;
      const std::size_t expect = dracoDecodeBytes(stream, view.byteLength, e.Get("attributes").Keys().size(), ptr);
      if (expect > budget)
        throw SceneLimitError(ptr, "the Draco stream's counts need " + std::to_string(expect) +
                                       " bytes to decode, over the size limit (" + std::to_string(budget) + " left)",
                              "--max-decode-bytes");
      draco::DecoderBuffer buffer;
      buffer.Init(reinterpret_cast<const char*>(model.buffers[std::size_t(view.buffer)].data.data() + view.byteOffset),
                  view.byteLength);
      draco::Decoder decoder;
      auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
      if (!decoded.ok()) throw SceneError(ptr, std::string("the Draco bitstream cannot be decoded: ") + decoded.status().error_msg());
      const std::unique_ptr<draco::Mesh> mesh = std::move(decoded).value();
      const std::size_t points = mesh->num_points(), faces = mesh->num_faces();
      const std::size_t need = faces * 3 * 4 + points * 16 * e.Get("attributes").Keys().size();
      if (need > budget)
        throw SceneLimitError(ptr, "the decoded mesh (" + std::to_string(need) + " bytes) is over the size limit",
                              "--max-decode-bytes");
      budget -= need;

      // One new buffer per primitive holding the decoded attributes (float) and indices (u32).
      tinygltf::Buffer out;
      auto addView = [&](const void* data, std::size_t bytes) {
        while (out.data.size() % 4) out.data.push_back(0);
        tinygltf::BufferView v;
        v.buffer = int(model.buffers.size());
        v.byteOffset = out.data.size();
        v.byteLength = bytes;
        const auto* p = static_cast<const unsigned char*>(data);
        out.data.insert(out.data.end(), p, p + bytes);
        model.bufferViews.push_back(v);
        return int(model.bufferViews.size()) - 1;
      };
      const tinygltf::Value& attrs = e.Get("attributes");
      for (const std::string& name : attrs.Keys()) {
        const auto it = prim.attributes.find(name);
        if (it == prim.attributes.end()) continue;  // Draco may carry attributes the primitive does not use
        const int accIndex = it->second;
        if (accIndex < 0 || std::size_t(accIndex) >= model.accessors.size())
          throw SceneError(ptr + "/attributes/" + name, "accessor " + std::to_string(accIndex) + " does not exist");
        const draco::PointAttribute* a = attrs.Get(name).IsNumber()
                                             ? mesh->GetAttributeByUniqueId(std::uint32_t(attrs.Get(name).GetNumberAsInt()))
                                             : nullptr;
        if (!a) throw SceneError(ptr + "/attributes/" + name, "the Draco stream has no attribute with this id");
        tinygltf::Accessor& acc = model.accessors[std::size_t(accIndex)];
        const int comps = tinygltf::GetNumComponentsInType(std::uint32_t(acc.type));
        if (comps <= 0 || comps > 4) throw SceneError(ptr + "/attributes/" + name, "unsupported accessor type");
        // Validated before any value is read (issue 30): the stream's type must be one of glTF's component
        // types (a DT_BOOL attribute with bytes other than 0 and 1 is undefined behaviour inside Draco's
        // conversion, found by tests/fuzz/draco_fuzzer.cpp) and its component count the accessor's.
        switch (a->data_type()) {
          case draco::DT_INT8: case draco::DT_UINT8: case draco::DT_INT16: case draco::DT_UINT16:
          case draco::DT_UINT32: case draco::DT_FLOAT32: break;
          default:
            throw SceneError(ptr + "/attributes/" + name, "the Draco attribute's data type (" +
                                                             std::to_string(int(a->data_type())) +
                                                             ") is not a glTF component type");
        }
        if (a->num_components() != comps)
          throw SceneError(ptr + "/attributes/" + name, "the Draco attribute has " + std::to_string(int(a->num_components())) +
                                                           " components, its accessor " + std::to_string(comps));
        std::vector<float> values(points * std::size_t(comps), 0.f);
        for (std::size_t i = 0; i < points; ++i)
          if (!a->ConvertValue<float>(a->mapped_index(draco::PointIndex(std::uint32_t(i))), std::int8_t(comps),
                                      &values[i * std::size_t(comps)]))
            throw SceneError(ptr + "/attributes/" + name, "the Draco attribute cannot be converted to float");
        // Normalised integer attributes come back in [0, 1] / [-1, 1] from ConvertValue: store them as floats.
        acc.bufferView = addView(values.data(), values.size() * sizeof(float));
        acc.byteOffset = 0;
        acc.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
        acc.normalized = false;
        acc.count = points;
        acc.sparse.isSparse = false;
      }
      std::vector<std::uint32_t> indices(faces * 3);
      for (std::size_t f = 0; f < faces; ++f) {
        const auto& face = mesh->face(draco::FaceIndex(std::uint32_t(f)));
        for (int k = 0; k < 3; ++k) indices[f * 3 + std::size_t(k)] = face[k].value();
      }
      tinygltf::Accessor idx;
      idx.bufferView = addView(indices.data(), indices.size() * 4);
      idx.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
      idx.type = TINYGLTF_TYPE_SCALAR;
      idx.count = indices.size();
      model.accessors.push_back(idx);
      prim.indices = int(model.accessors.size()) - 1;
      prim.mode = TINYGLTF_MODE_TRIANGLES;
      model.buffers.push_back(std::move(out));
    }
}

}  // namespace radiant::gltf
