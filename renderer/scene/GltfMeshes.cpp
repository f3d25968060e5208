#include "renderer/scene/GltfConverter.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <glm/gtc/matrix_inverse.hpp>

#include "renderer/scene/GltfAccessors.h"
#include "renderer/scene/GltfLoader.h"
#include "renderer/scene/MikkTSpace.h"

namespace radiant::gltf {

namespace {

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

}  // namespace

glm::vec3 anyPerpendicular(const glm::vec3& n) {
  const glm::vec3 a = std::abs(n.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
  return glm::normalize(glm::cross(a, n));
}

void Converter::addPrimitive(int nodeIndex, const tinygltf::Node& node, int meshIndex, int primIndex,
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

}  // namespace radiant::gltf
