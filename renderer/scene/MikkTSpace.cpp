#include "renderer/scene/MikkTSpace.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <unordered_map>

namespace radiant {
namespace {

// mikktspace.c's test for "not zero": beyond the smallest normal float.
bool notZero(float x) { return std::abs(x) > std::numeric_limits<float>::min(); }
bool notZero(const glm::vec3& v) { return notZero(v.x) || notZero(v.y) || notZero(v.z); }
// Unit length unless zero (then unchanged), by the reciprocal as mikktspace.c scales.
glm::vec3 normalizeIfNotZero(const glm::vec3& v) { return notZero(v) ? v * (1.f / glm::length(v)) : v; }
// The component of v in the plane perpendicular to the unit normal n, unit length unless zero.
glm::vec3 projectUnit(const glm::vec3& v, const glm::vec3& n) { return normalizeIfNotZero(v - n * glm::dot(n, v)); }

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// The welding maps' keys: 32-bit words (float bit patterns, indices), hashed with FNV-1a.
struct WordsHash {
  template <std::size_t N>
  std::size_t operator()(const std::array<std::uint32_t, N>& k) const {
    std::size_t h = 1469598103934665603ull;
    for (std::uint32_t x : k) h = (h ^ x) * 1099511628211ull;
    return h;
  }
};
std::uint32_t floatBits(float f) {
  std::uint32_t u = 0;
  std::memcpy(&u, &f, sizeof u);
  return u;
}

// Step 1: one id per set of vertices with bit-identical position, normal and uv (+0 and -0 compare
// equal, as floats do); a vertex with a non-finite attribute equals nothing else.
std::vector<std::uint32_t> weldIds(const std::vector<glm::vec3>& p, const std::vector<glm::vec3>& n,
                                   const std::vector<glm::vec2>& uv) {
  using Key = std::array<std::uint32_t, 8>;
  auto bits = [](float f) { return floatBits(f == 0.f ? 0.f : f); };  // -0 -> +0
  std::unordered_map<Key, std::uint32_t, WordsHash> firstOf;
  firstOf.reserve(p.size());
  std::vector<std::uint32_t> id(p.size());
  for (std::size_t v = 0; v < p.size(); ++v) {
    id[v] = static_cast<std::uint32_t>(v);
    if (!finite(p[v]) || !finite(n[v]) || !std::isfinite(uv[v].x) || !std::isfinite(uv[v].y)) continue;
    const Key k{bits(p[v].x), bits(p[v].y), bits(p[v].z), bits(n[v].x), bits(n[v].y), bits(n[v].z), bits(uv[v].x), bits(uv[v].y)};
    id[v] = firstOf.emplace(k, static_cast<std::uint32_t>(v)).first->second;
  }
  return id;
}

struct TriangleInfo {
  glm::vec3 os{0.f}, ot{0.f};  // normalised dP/ds, dP/dt, turned by the orientation's sign
  float magS = 0.f, magT = 0.f;
  bool orientationPreserving = false;
  bool groupWithAny = true;  // zero uv area or a zero derivative: joins any group
  bool degenerate = false;
  std::array<int, 3> neighbour{-1, -1, -1};  // across edge k (corner k to corner k + 1)
  std::array<int, 3> group{-1, -1, -1};      // per corner
};

struct Group {
  std::uint32_t vertex;  // the welded vertex the group is around
  bool orientationPreserving;
  std::vector<int> triangles;
};

struct TangentSpace {
  glm::vec3 os{1.f, 0.f, 0.f};
  bool orientationPreserving = false;
};

}  // namespace

std::vector<glm::vec4> mikkTSpaceCornerTangents(const std::vector<glm::vec3>& positions,
                                                const std::vector<glm::vec3>& normals,
                                                const std::vector<glm::vec2>& uvs,
                                                const std::vector<std::uint32_t>& indices) {
  const std::size_t triangles = indices.size() / 3;
  std::vector<TangentSpace> corner(triangles * 3);
  auto result = [&] {
    std::vector<glm::vec4> out(corner.size());
    for (std::size_t c = 0; c < corner.size(); ++c) {
      const glm::vec3 t = finite(corner[c].os) && notZero(corner[c].os) ? corner[c].os : glm::vec3(1.f, 0.f, 0.f);
      out[c] = glm::vec4(t, corner[c].orientationPreserving ? 1.f : -1.f);
    }
    return out;
  };
  if (triangles == 0 || normals.size() != positions.size() || uvs.size() != positions.size()) return result();
  for (std::uint32_t i : indices)
    if (i >= positions.size()) return result();

  const std::vector<std::uint32_t> weldOf = weldIds(positions, normals, uvs);
  auto weld = [&](std::size_t t, int k) { return weldOf[indices[3 * t + std::size_t(k)]]; };
  auto pos = [&](std::size_t t, int k) { return positions[indices[3 * t + std::size_t(k)]]; };
  auto nrm = [&](std::size_t t, int k) { return normals[indices[3 * t + std::size_t(k)]]; };
  auto tex = [&](std::size_t t, int k) { return uvs[indices[3 * t + std::size_t(k)]]; };

  // Step 2: degenerate triangles; the healthy ones in order.
  std::vector<TriangleInfo> info(triangles);
  std::vector<int> healthy;
  for (std::size_t t = 0; t < triangles; ++t) {
    const glm::vec3 p0 = pos(t, 0), p1 = pos(t, 1), p2 = pos(t, 2);
    info[t].degenerate = p0 == p1 || p0 == p2 || p1 == p2;
    if (!info[t].degenerate) healthy.push_back(static_cast<int>(t));
  }

  // Step 3: the uv map's first-order derivatives (paper eq. 18, 19) and its orientation.
  for (int t : healthy) {
    TriangleInfo& ti = info[std::size_t(t)];
    const glm::vec2 t1 = tex(std::size_t(t), 0), t2 = tex(std::size_t(t), 1), t3 = tex(std::size_t(t), 2);
    const glm::vec3 d1 = pos(std::size_t(t), 1) - pos(std::size_t(t), 0), d2 = pos(std::size_t(t), 2) - pos(std::size_t(t), 0);
    const float t21x = t2.x - t1.x, t21y = t2.y - t1.y, t31x = t3.x - t1.x, t31y = t3.y - t1.y;
    const float signedAreaTimes2 = t21x * t31y - t21y * t31x;
    const glm::vec3 os = t31y * d1 - t21y * d2;   // eq. 18
    const glm::vec3 ot = -t31x * d1 + t21x * d2;  // eq. 19
    ti.orientationPreserving = signedAreaTimes2 > 0.f;
    if (notZero(signedAreaTimes2)) {
      const float area = std::abs(signedAreaTimes2), lenS = glm::length(os), lenT = glm::length(ot);
      const float sign = ti.orientationPreserving ? 1.f : -1.f;
      if (notZero(lenS)) ti.os = (sign / lenS) * os;
      if (notZero(lenT)) ti.ot = (sign / lenT) * ot;
      ti.magS = lenS / area;
      ti.magT = lenT / area;
      if (notZero(ti.magS) && notZero(ti.magT)) ti.groupWithAny = false;
    }
  }

  // Neighbours across shared edges: an edge pairs with the first unpaired opposite edge (welded ids)
  // of a later triangle, edges taken in the order of (edge, triangle).
  {
    struct Edge {
      std::uint32_t lo, hi;
      int t, k;
    };
    std::vector<Edge> edges;
    edges.reserve(healthy.size() * 3);
    for (int t : healthy)
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t a = weld(std::size_t(t), k), b = weld(std::size_t(t), (k + 1) % 3);
        edges.push_back({std::min(a, b), std::max(a, b), t, k});
      }
    std::sort(edges.begin(), edges.end(), [](const Edge& x, const Edge& y) {
      return x.lo != y.lo ? x.lo < y.lo : x.hi != y.hi ? x.hi < y.hi : x.t != y.t ? x.t < y.t : x.k < y.k;
    });
    for (std::size_t i = 0; i < edges.size(); ++i) {
      const Edge& a = edges[i];
      if (info[std::size_t(a.t)].neighbour[std::size_t(a.k)] != -1) continue;
      const std::uint32_t a0 = weld(std::size_t(a.t), a.k), a1 = weld(std::size_t(a.t), (a.k + 1) % 3);
      for (std::size_t j = i + 1; j < edges.size() && edges[j].lo == a.lo && edges[j].hi == a.hi; ++j) {
        const Edge& b = edges[j];
        const std::uint32_t b0 = weld(std::size_t(b.t), b.k), b1 = weld(std::size_t(b.t), (b.k + 1) % 3);
        if (a0 == b1 && a1 == b0 && info[std::size_t(b.t)].neighbour[std::size_t(b.k)] == -1) {
          info[std::size_t(a.t)].neighbour[std::size_t(a.k)] = b.t;
          info[std::size_t(b.t)].neighbour[std::size_t(b.k)] = a.t;
          break;
        }
      }
    }
  }

  // Step 4: groups around each welded vertex, grown depth-first (left neighbour's side first) from
  // each healthy triangle's unassigned corners in order. A "group with any" triangle takes the
  // orientation of the first group that reaches it.
  std::vector<Group> groups;
  auto cornerOf = [&](int t, std::uint32_t vertex) {
    for (int k = 0; k < 3; ++k)
      if (weld(std::size_t(t), k) == vertex) return k;
    return -1;
  };
  std::vector<int> stack;
  for (int f : healthy)
    for (int k = 0; k < 3; ++k) {
      TriangleInfo& fi = info[std::size_t(f)];
      if (fi.groupWithAny || fi.group[std::size_t(k)] != -1) continue;
      const int g = static_cast<int>(groups.size());
      groups.push_back({weld(std::size_t(f), k), fi.orientationPreserving, {f}});
      fi.group[std::size_t(k)] = g;
      stack.clear();
      for (int side : {fi.neighbour[std::size_t((k + 2) % 3)], fi.neighbour[std::size_t(k)]})
        if (side >= 0) stack.push_back(side);
      while (!stack.empty()) {
        const int t = stack.back();
        stack.pop_back();
        TriangleInfo& ti = info[std::size_t(t)];
        const int c = cornerOf(t, groups[std::size_t(g)].vertex);
        if (c < 0 || ti.group[std::size_t(c)] != -1) continue;
        if (ti.groupWithAny && ti.group[0] == -1 && ti.group[1] == -1 && ti.group[2] == -1)
          ti.orientationPreserving = groups[std::size_t(g)].orientationPreserving;
        if (ti.orientationPreserving != groups[std::size_t(g)].orientationPreserving) continue;
        groups[std::size_t(g)].triangles.push_back(t);
        ti.group[std::size_t(c)] = g;
        for (int side : {ti.neighbour[std::size_t((c + 2) % 3)], ti.neighbour[std::size_t(c)]})
          if (side >= 0) stack.push_back(side);
      }
    }

  // Step 5: per group, subgroups of triangles whose projected derivatives agree (threshold 180 degrees:
  // cos > -1), and per subgroup the corner-angle-weighted mean of its projected derivatives.
  const float thresholdCos = -1.f;
  for (std::size_t g = 0; g < groups.size(); ++g) {
    const Group& group = groups[g];
    const glm::vec3 n = [&] {
      const int t = group.triangles.front();
      return nrm(std::size_t(t), cornerOf(t, group.vertex));
    }();
    const std::size_t size = group.triangles.size();
    std::vector<glm::vec3> os(size), ot(size);
    for (std::size_t i = 0; i < size; ++i) {
      os[i] = projectUnit(info[std::size_t(group.triangles[i])].os, n);
      ot[i] = projectUnit(info[std::size_t(group.triangles[i])].ot, n);
    }
    auto evaluate = [&](const std::vector<int>& members) {  // mikktspace.c's EvalTspace
      glm::vec3 sumS(0.f);
      for (int t : members) {
        const TriangleInfo& ti = info[std::size_t(t)];
        if (ti.groupWithAny) continue;
        const int k = cornerOf(t, group.vertex);
        const glm::vec3 p1 = pos(std::size_t(t), k);
        const glm::vec3 v1 = projectUnit(pos(std::size_t(t), (k + 2) % 3) - p1, n);
        const glm::vec3 v2 = projectUnit(pos(std::size_t(t), (k + 1) % 3) - p1, n);
        // acos in double, as mikktspace.c's C call.
        const float angle = static_cast<float>(std::acos(static_cast<double>(std::clamp(glm::dot(v1, v2), -1.f, 1.f))));
        sumS += angle * projectUnit(ti.os, n);
      }
      TangentSpace ts;
      ts.os = normalizeIfNotZero(sumS);
      ts.orientationPreserving = group.orientationPreserving;
      return ts;
    };
    std::vector<std::pair<std::vector<int>, TangentSpace>> subgroups;
    for (std::size_t i = 0; i < size; ++i) {
      const int f = group.triangles[i];
      std::vector<int> members;
      if (size > kMikkTSpaceMaxExactGroup) {
        members = group.triangles;
      } else {
        for (std::size_t j = 0; j < size; ++j) {
          const int t = group.triangles[j];
          const bool any = info[std::size_t(f)].groupWithAny || info[std::size_t(t)].groupWithAny;
          if (any || t == f || (glm::dot(os[i], os[j]) > thresholdCos && glm::dot(ot[i], ot[j]) > thresholdCos))
            members.push_back(t);
        }
      }
      std::sort(members.begin(), members.end());
      auto found = std::find_if(subgroups.begin(), subgroups.end(), [&](const auto& s) { return s.first == members; });
      if (found == subgroups.end()) {
        const TangentSpace ts = evaluate(members);
        subgroups.emplace_back(std::move(members), ts);
        found = subgroups.end() - 1;
      }
      const int k = cornerOf(f, group.vertex);
      corner[3 * std::size_t(f) + std::size_t(k)] = found->second;
    }
  }

  // Step 6: a degenerate triangle's corners copy the first healthy corner welded to them.
  std::unordered_map<std::uint32_t, std::size_t> firstHealthyCorner;
  for (int t : healthy)
    for (int k = 0; k < 3; ++k) firstHealthyCorner.emplace(weld(std::size_t(t), k), 3 * std::size_t(t) + std::size_t(k));
  for (std::size_t t = 0; t < triangles; ++t) {
    if (!info[t].degenerate) continue;
    for (int k = 0; k < 3; ++k)
      if (auto it = firstHealthyCorner.find(weld(t, k)); it != firstHealthyCorner.end())
        corner[3 * t + std::size_t(k)] = corner[it->second];
  }
  return result();
}

std::vector<glm::vec4> gltfMikkTSpaceCornerTangents(const std::vector<glm::vec3>& positions,
                                                    const std::vector<glm::vec3>& normals,
                                                    const std::vector<glm::vec2>& uvs,
                                                    const std::vector<std::uint32_t>& indices) {
  std::vector<glm::vec2> flipped(uvs.size());
  for (std::size_t i = 0; i < uvs.size(); ++i) flipped[i] = glm::vec2(uvs[i].x, 1.f - uvs[i].y);
  return mikkTSpaceCornerTangents(positions, normals, flipped, indices);
}

TangentSplit splitVerticesByTangent(const std::vector<glm::vec4>& cornerTangents,
                                    const std::vector<std::uint32_t>& indices) {
  using Key = std::array<std::uint32_t, 5>;
  const auto bits = floatBits;
  TangentSplit out;
  out.indices.resize(indices.size());
  std::unordered_map<Key, std::uint32_t, WordsHash> vertexFor;
  vertexFor.reserve(indices.size());
  for (std::size_t c = 0; c < indices.size() && c < cornerTangents.size(); ++c) {
    const glm::vec4& t = cornerTangents[c];
    const Key k{indices[c], bits(t.x), bits(t.y), bits(t.z), bits(t.w)};
    const auto [it, added] = vertexFor.emplace(k, static_cast<std::uint32_t>(out.vertexOf.size()));
    if (added) {
      out.vertexOf.push_back(indices[c]);
      out.tangents.push_back(t);
    }
    out.indices[c] = it->second;
  }
  return out;
}

}  // namespace radiant
