#include "renderer/techniques/depth_impostors/Blocks.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "renderer/raytracing/Bsdf.h"

namespace radiant::impostors {
namespace {

constexpr double kPiD = 3.14159265358979323846;

void split(std::vector<gpu::MediaParticle>& p, std::size_t begin, std::size_t end, std::size_t blocks,
           std::vector<std::pair<std::size_t, std::size_t>>& out) {
  if (blocks <= 1 || end - begin <= 1) {
    out.emplace_back(begin, end);
    return;
  }
  glm::vec3 lo(1e30f), hi(-1e30f);
  for (std::size_t i = begin; i < end; ++i) {
    lo = glm::min(lo, glm::vec3(p[i].centerRadius));
    hi = glm::max(hi, glm::vec3(p[i].centerRadius));
  }
  const glm::vec3 ext = hi - lo;
  const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : ext.y >= ext.z ? 1 : 2;
  const std::size_t left = blocks / 2;
  const std::size_t cut = begin + (end - begin) * left / blocks;
  std::nth_element(p.begin() + begin, p.begin() + cut, p.begin() + end,
                   [axis](const gpu::MediaParticle& a, const gpu::MediaParticle& b) {
                     return a.centerRadius[axis] < b.centerRadius[axis];
                   });
  split(p, begin, cut, left, out);
  split(p, cut, end, blocks - left, out);
}

}  // namespace

BlockSet buildBlocks(const std::vector<gpu::MediaParticle>& particles, const std::vector<int>& systemOf, int b) {
  BlockSet set;
  b = std::max(1, b);
  // Stable grouping by system first, so that a block never mixes phase functions.
  std::vector<std::size_t> order(particles.size());
  std::iota(order.begin(), order.end(), std::size_t(0));
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t c) { return systemOf[a] < systemOf[c]; });
  set.particles.reserve(particles.size());
  for (std::size_t i : order) set.particles.push_back(particles[i]);
  std::vector<std::pair<std::size_t, std::size_t>> ranges;
  for (std::size_t s = 0; s < order.size();) {
    std::size_t e = s;
    while (e < order.size() && systemOf[order[e]] == systemOf[order[s]]) ++e;
    const std::size_t n = e - s;
    split(set.particles, s, e, (n + b - 1) / b, ranges);
    s = e;
  }
  for (const auto& [begin, end] : ranges) {
    Block blk;
    blk.first = static_cast<int>(begin);
    blk.count = static_cast<int>(end - begin);
    glm::dvec3 c(0.0), src(0.0), alb(0.0);
    double mass = 0.0;
    for (std::size_t i = begin; i < end; ++i) {
      const auto& q = set.particles[i];
      c += glm::dvec3(glm::vec3(q.centerRadius));
      const double r = q.centerRadius.w, m = std::max(1e-30, double(q.sourceTau.w) * r * r * r);
      src += m * glm::dvec3(glm::vec3(q.sourceTau));
      alb += m * glm::dvec3(glm::vec3(q.albedoG));
      mass += m;
    }
    blk.center = glm::vec3(c / double(blk.count));
    for (std::size_t i = begin; i < end; ++i) {
      const auto& q = set.particles[i];
      blk.radius = std::max(blk.radius, glm::length(glm::vec3(q.centerRadius) - blk.center) + q.centerRadius.w);
    }
    // A little margin so that the rasterised particle quads never reach the tile's border texels' outside.
    blk.radius *= 1.0001f;
    blk.source = glm::vec3(src / mass);
    blk.albedo = glm::vec3(alb / mass);
    blk.g = set.particles[begin].albedoG.w;
    blk.phaseModel = set.particles[begin].models.y;
    const int index = static_cast<int>(set.blocks.size());
    for (std::size_t i = begin; i < end; ++i) set.particles[i].models.z = index;
    set.blocks.push_back(blk);
  }
  return set;
}

int SliceFrame::group(const glm::vec3& c) const {
  return std::clamp(static_cast<int>(std::floor(knot(c))), 0, K - 1);
}

float SliceFrame::knot(const glm::vec3& x) const {
  return std::clamp((glm::dot(x - center, axis) - dmin) / std::max(dmax - dmin, 1e-30f) * float(K), 0.f, float(K));
}

float SliceFrame::fourierDepth(const glm::vec3& x) const {
  return std::clamp((glm::dot(x - center, axis) - zNear) / std::max(zFar - zNear, 1e-30f), 0.f, 1.f);
}

glm::vec2 SliceFrame::uv(const glm::vec3& x) const {
  const glm::vec3 rel = x - center;
  return glm::vec2(glm::dot(rel, u), glm::dot(rel, v)) / halfSize * 0.5f + 0.5f;
}

SliceFrame fitSliceFrame(const std::vector<Block>& blocks, const glm::vec3& axis, int K) {
  SliceFrame f;
  f.axis = glm::normalize(axis);
  f.K = std::max(1, K);
  impostorBasis(f.axis, f.u, f.v);
  glm::vec3 lo(1e30f), hi(-1e30f);
  for (const Block& b : blocks) lo = glm::min(lo, b.center - b.radius), hi = glm::max(hi, b.center + b.radius);
  if (blocks.empty()) lo = hi = glm::vec3(0.f);
  f.center = 0.5f * (lo + hi);
  float half = 0.f, dmin = 1e30f, dmax = -1e30f, zNear = 1e30f, zFar = -1e30f;
  for (const Block& b : blocks) {
    const glm::vec3 rel = b.center - f.center;
    half = std::max({half, std::abs(glm::dot(rel, f.u)) + b.radius, std::abs(glm::dot(rel, f.v)) + b.radius});
    dmin = std::min(dmin, glm::dot(rel, f.axis));
    dmax = std::max(dmax, glm::dot(rel, f.axis));
    zNear = std::min(zNear, glm::dot(rel, f.axis) - b.radius);
    zFar = std::max(zFar, glm::dot(rel, f.axis) + b.radius);
  }
  f.zNear = blocks.empty() ? -1.f : zNear;
  f.zFar = blocks.empty() ? 1.f : std::max(zFar, zNear + 1e-6f * std::max(1.f, half));
  f.halfSize = std::max(half, 1e-6f);
  f.dmin = blocks.empty() ? 0.f : dmin;
  f.dmax = blocks.empty() ? 1.f : std::max(dmax, dmin + 1e-6f * std::max(1.f, f.halfSize));
  return f;
}

float interpolateSlices(const float* slices, int K, float s) {
  s = std::clamp(s, 0.f, float(K));
  const int i = std::min(static_cast<int>(std::floor(s)), K - 1);
  const float f = s - float(i);
  const float a = i == 0 ? 1.f : slices[i - 1], b = slices[i];
  return a + (b - a) * f;
}

int fourierChannels(int M) { return 2 * M + 1; }

double fourierDamping(int k, int M, bool damped) {
  if (!damped || k == 0) return 1.0;
  // Jackson kernel, N = M + 1 moments: g_k = ((N - k + 1) cos(pi k / (N + 1)) + sin(pi k / (N + 1)) cot(pi / (N + 1))) / (N + 1).
  const double n1 = M + 2.0, q = kPiD / n1;
  return ((n1 - k) * std::cos(q * k) + std::sin(q * k) * std::cos(q) / std::sin(q)) / n1;
}

void addFourierBox(float* c, int M, double tau, double d0, double d1) {
  c[0] += static_cast<float>(2.0 * tau);
  const double w = d1 - d0;
  for (int k = 1; k <= M; ++k) {
    const double o = 2.0 * kPiD * k;
    double ak, bk;
    if (w > 1e-5) {
      ak = 2.0 * tau * (std::sin(o * d1) - std::sin(o * d0)) / (o * w);
      bk = 2.0 * tau * (std::cos(o * d0) - std::cos(o * d1)) / (o * w);
    } else {  // a delta at the middle
      const double m = 0.5 * (d0 + d1);
      ak = 2.0 * tau * std::cos(o * m), bk = 2.0 * tau * std::sin(o * m);
    }
    c[2 * k - 1] += static_cast<float>(ak);
    c[2 * k] += static_cast<float>(bk);
  }
}

double fourierOpticalDepth(const float* c, int M, double d, bool damped) {
  double D = 0.5 * c[0] * d;
  for (int k = 1; k <= M; ++k) {
    const double o = 2.0 * kPiD * k;
    D += fourierDamping(k, M, damped) * (c[2 * k - 1] * std::sin(o * d) + c[2 * k] * (1.0 - std::cos(o * d))) / o;
  }
  return D;
}

double fourierTransmittance(const float* c, int M, double d) {
  const double D = std::clamp(fourierOpticalDepth(c, M, d), 0.0, std::max(0.0, 0.5 * double(c[0])));
  return std::clamp(std::exp(-D), 0.0, 1.0);
}

void impostorBasis(const glm::vec3& axis, glm::vec3& u, glm::vec3& v) {
  const rt::ShadingFrame f = rt::ShadingFrame::fromNormal(axis);
  u = f.t, v = f.b;
}

}  // namespace radiant::impostors
