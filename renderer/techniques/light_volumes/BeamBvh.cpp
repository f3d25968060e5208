#include "renderer/techniques/light_volumes/BeamBvh.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace radiant::light_volumes {
namespace {

struct Primitive {
  Bounds box;
  glm::vec3 centre;
  glm::vec4 record;
};

// The box of beam b's part s0 <= s <= s1 (s = (F - C).N along its cone's axis). The flux triangle at
// s has the vertices X_k(s) = V_k + ((s - h_k) / kappa_k) d_k, linear in s, so the part lies in the
// convex hull of the six end vertices; glossy beams add the cone's padding (its radius minus the
// specular radius, at each end). Cones that are unbounded (a glossy padding past kMaxCullAngle) use
// the disks of the cone itself, clamped to the scene by the caller.
Bounds segmentBox(const Beam& beam, const BeamCone& c, float s0, float s1) {
  const glm::vec3 C(c.originRadius), N(c.axisSlope);
  Bounds box;
  if (c.originRadius.w >= 1e29f) {
    box.extend(glm::vec3(-1e30f));
    box.extend(glm::vec3(1e30f));
    return box;
  }
  const glm::vec3 V[3] = {glm::vec3(beam.vertexA), glm::vec3(beam.vertexB), glm::vec3(beam.vertexC)};
  const glm::vec3 d[3] = {glm::vec3(beam.dirA), glm::vec3(beam.dirB), glm::vec3(beam.dirC)};
  const BeamCone specular = beamCone([&] { Beam b = beam; b.fluxSigma.w = 0.f; return b; }(), 0.f);
  for (float s : {s0, s1}) {
    const float pad = std::max(0.f, (c.originRadius.w + c.axisSlope.w * std::abs(s)) -
                                        (specular.originRadius.w + specular.axisSlope.w * std::abs(s)));
    for (int k = 0; k < 3; ++k) {
      const float kappa = std::max(glm::dot(d[k], N), 1e-4f);
      const glm::vec3 X = V[k] + ((s - glm::dot(V[k] - C, N)) / kappa) * d[k];
      box.extend(X - glm::vec3(pad));
      box.extend(X + glm::vec3(pad));
    }
  }
  return box;
}

int build(std::vector<Primitive>& prims, int begin, int end, int depth, BeamBvh& out) {
  out.depth = std::max(out.depth, depth);
  Bounds box, centres;
  for (int i = begin; i < end; ++i) {
    box.extend(prims[i].box);
    centres.extend(prims[i].centre);
  }
  const int index = static_cast<int>(out.nodes.size());
  out.nodes.push_back({});
  BeamBvhNode node;
  node.lo = glm::vec4(box.min, 0.f);
  node.hi = glm::vec4(box.max, 0.f);
  if (end - begin <= kBvhLeafSize || depth >= kBvhMaxDepth) {
    node.meta = glm::ivec4(-1, static_cast<int>(out.primitives.size()), end - begin, 0);
    for (int i = begin; i < end; ++i) out.primitives.push_back(prims[i].record);
    out.nodes[index] = node;
    return index;
  }
  const glm::vec3 ext = centres.extent();
  const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
  const int mid = (begin + end) / 2;
  std::nth_element(prims.begin() + begin, prims.begin() + mid, prims.begin() + end,
                   [axis](const Primitive& p, const Primitive& q) { return p.centre[axis] < q.centre[axis]; });
  build(prims, begin, mid, depth + 1, out);
  const int right = build(prims, mid, end, depth + 1, out);
  node.meta = glm::ivec4(right, 0, 0, 0);
  out.nodes[index] = node;
  return index;
}

}  // namespace

BeamBvh buildBeamBvh(const std::vector<Beam>& beams, const std::vector<BeamCone>& cones, const Bounds& boundsIn,
                     const rt::Cancel& cancel) {
  BeamBvh out;
  Bounds bounds = boundsIn;
  const glm::vec3 pad(1e-3f * std::max(bounds.radius(), 1e-6f));
  bounds.min -= pad;
  bounds.max += pad;
  const glm::vec3 corners[8] = {
      {bounds.min.x, bounds.min.y, bounds.min.z}, {bounds.max.x, bounds.min.y, bounds.min.z},
      {bounds.min.x, bounds.max.y, bounds.min.z}, {bounds.max.x, bounds.max.y, bounds.min.z},
      {bounds.min.x, bounds.min.y, bounds.max.z}, {bounds.max.x, bounds.min.y, bounds.max.z},
      {bounds.min.x, bounds.max.y, bounds.max.z}, {bounds.max.x, bounds.max.y, bounds.max.z}};
  const int count = static_cast<int>(cones.size());
  for (int g0 = 0; g0 < count; g0 += kBeamsPerGroup) {
    const int g1 = std::min(count, g0 + kBeamsPerGroup);
    cancel.check("light_volumes' beam BVH");
    std::vector<Primitive> prims;
    for (int i = g0; i < g1; ++i) {
      const BeamCone& c = cones[i];
      const glm::vec3 C(c.originRadius), N(c.axisSlope);
      // The axial range the scene's bounds span.
      float sMin = 1e30f, sMax = -1e30f;
      for (const auto& p : corners) {
        const float s = glm::dot(p - C, N);
        sMin = std::min(sMin, s);
        sMax = std::max(sMax, s);
      }
      const float a = c.originRadius.w, b = c.axisSlope.w;
      // Long thin cones get more segments (about one per diameter), at most kMaxSegmentsPerBeam.
      const float rMax = a + b * std::max(std::abs(sMin), std::abs(sMax));
      const float len = sMax - sMin;
      const int n = std::clamp(static_cast<int>(std::ceil(len / std::max(2.f * rMax, 1e-6f * len))), 1, kMaxSegmentsPerBeam);
      for (int k = 0; k < n; ++k) {
        const float s0 = sMin + len * k / n, s1 = k + 1 == n ? sMax : sMin + len * (k + 1) / n;
        Bounds box = segmentBox(beams[i], c, s0, s1);
        box.min = glm::max(box.min, bounds.min);
        box.max = glm::min(box.max, bounds.max);
        if (box.empty()) continue;
        // Fragments inside the bounds have sMin <= s <= sMax; the last segment is open upwards so that
        // one at exactly sMax is not lost.
        prims.push_back({box, box.center(), glm::vec4(s0, k + 1 == n ? 1e30f : s1, static_cast<float>(i), 0.f)});
      }
    }
    out.groupBeams.push_back(g1 - g0);
    if (prims.empty()) {
      out.roots.push_back(-1);
      continue;
    }
    out.roots.push_back(build(prims, 0, static_cast<int>(prims.size()), 0, out));
  }
  return out;
}

}  // namespace radiant::light_volumes
