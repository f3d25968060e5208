#include "renderer/scene/GltfAccessors.h"

#include <algorithm>
#include <cstring>

#include <tiny_gltf.h>

#include "renderer/scene/GltfLoader.h"

namespace radiant::gltf {

std::string pointer(std::string_view base, std::size_t index) {
  return std::string(base) + "/" + std::to_string(index);
}

std::string primitivePointer(int mesh, int prim) {
  return "/meshes/" + std::to_string(mesh) + "/primitives/" + std::to_string(prim);
}

namespace {

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

}  // namespace

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

}  // namespace radiant::gltf
