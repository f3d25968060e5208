#include "renderer/techniques/illumination_network/Network.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <numeric>

#include "renderer/raytracing/Media.h"
#include "renderer/raytracing/ParticleMedium.h"
#include "renderer/raytracing/Sampler.h"

namespace radiant::network {

namespace {

constexpr double kPiD = 3.14159265358979323846;

glm::vec3 uniformSphere(float u1, float u2) {
  const float z = 1.f - 2.f * u1, phi = 2.f * rt::kPi * u2;
  const float r = std::sqrt(std::max(0.f, 1.f - z * z));
  return {r * std::cos(phi), r * std::sin(phi), z};
}

// A uniformly distributed rotation (Shoemake, "Uniform random rotations", Graphics Gems III).
glm::mat3 randomRotation(rt::Sampler& s) {
  const double u1 = s.next(), u2 = s.next(), u3 = s.next();
  const double a = std::sqrt(1.0 - u1), b = std::sqrt(u1);
  const double x = a * std::sin(2 * kPiD * u2), y = a * std::cos(2 * kPiD * u2);
  const double z = b * std::sin(2 * kPiD * u3), w = b * std::cos(2 * kPiD * u3);
  return glm::mat3(glm::dmat3(1 - 2 * (y * y + z * z), 2 * (x * y + z * w), 2 * (x * z - y * w),
                              2 * (x * y - z * w), 1 - 2 * (x * x + z * z), 2 * (y * z + x * w),
                              2 * (x * z + y * w), 2 * (y * z - x * w), 1 - 2 * (x * x + y * y)));
}

}  // namespace

NodeSet sampleNodes(const rt::ParticleMedium& medium, int count, std::uint64_t seed) {
  NodeSet out;
  const auto& ps = medium.particles();
  if (ps.empty() || count <= 0) return out;
  glm::vec3 lo(1e30f), hi(-1e30f);
  std::vector<double> cdf;
  double mass = 0.0;
  bool phaseSet = false;
  for (const rt::MediumParticle& p : ps) {
    lo = glm::min(lo, p.center - p.radius), hi = glm::max(hi, p.center + p.radius);
    // \int tau dV: constant 4/3 pi r^3 tau, linear falloff pi r^3 tau / 3.
    const double r3 = double(p.radius) * p.radius * p.radius;
    mass += (p.linear ? kPiD / 3.0 : 4.0 * kPiD / 3.0) * r3 * p.tau;
    cdf.push_back(mass);
    if (!phaseSet && glm::max(p.albedo.x, glm::max(p.albedo.y, p.albedo.z)) > 0.f)
      out.phase = p.phase, out.g = p.g, phaseSet = true;
  }
  out.center = 0.5f * (lo + hi);
  for (const rt::MediumParticle& p : ps) out.radius = std::max(out.radius, glm::length(p.center - out.center) + p.radius);
  out.mass = mass;
  std::vector<rt::Chord> chords;
  out.nodes.reserve(static_cast<std::size_t>(count));
  for (int k = 0; k < count; ++k) {
    rt::Sampler s(static_cast<std::uint64_t>(k), 0, seed);
    const double pick = s.next() * mass;
    const std::size_t j = std::min<std::size_t>(
        static_cast<std::size_t>(std::upper_bound(cdf.begin(), cdf.end(), pick) - cdf.begin()), ps.size() - 1);
    const rt::MediumParticle& p = ps[j];
    // A radius with density s^2 (uniform in the ball), times (1 - s/r) by rejection for the falloff.
    float rad;
    do rad = p.radius * std::cbrt(s.next());
    while (p.linear && s.next() > 1.f - rad / p.radius);
    const glm::vec3 x = p.center + rad * uniformSphere(s.next(), s.next());
    // Every particle covering x: the chords of a short segment through it.
    const float eps = 1e-4f * out.radius;
    medium.chords(x - glm::vec3(0, 0, eps), glm::vec3(0, 0, 1), 0.f, 2.f * eps, chords);
    Node n;
    n.position = x;
    glm::vec3 albedoSum(0.f), emissionSum(0.f);
    for (const rt::Chord& c : chords) {
      const float t = medium.density(c.particle, x);
      const rt::MediumParticle& q = ps[static_cast<std::size_t>(c.particle)];
      n.tau += t;
      albedoSum += t * q.albedo;
      emissionSum += t * (1.f - q.albedo) * q.emission;
    }
    if (!(n.tau > 0.f)) {  // on a particle's rim (density 0 there): its own values
      n.tau = 0.f, albedoSum = p.albedo, emissionSum = (1.f - p.albedo) * p.emission;
      n.albedo = p.albedo, n.emission = emissionSum;
    } else {
      n.albedo = albedoSum / n.tau, n.emission = emissionSum / n.tau;
    }
    out.nodes.push_back(n);
  }
  return out;
}

Direction directionBasis(glm::vec3 w) {
  w = glm::normalize(w);
  // Duff et al. 2017, "Building an orthonormal basis, revisited".
  const float sign = std::copysign(1.f, w.z);
  const float a = -1.f / (sign + w.z), b = w.x * w.y * a;
  return {w, glm::vec3(1.f + sign * w.x * w.x * a, sign * b, -sign * w.x), glm::vec3(b, sign + w.y * w.y * a, -w.y)};
}

std::vector<Direction> makeDirections(int count, bool fibonacci, std::uint64_t seed) {
  std::vector<Direction> out;
  rt::Sampler s(0x5EED, 0, seed);
  const glm::mat3 rot = randomRotation(s);
  const double golden = kPiD * (3.0 - std::sqrt(5.0));
  for (int k = 0; k < count; ++k) {
    glm::vec3 w;
    if (fibonacci) {
      const double z = 1.0 - (2.0 * k + 1.0) / count, r = std::sqrt(std::max(0.0, 1.0 - z * z));
      w = rot * glm::vec3(glm::dvec3(r * std::cos(golden * k), r * std::sin(golden * k), z));
    } else {
      w = uniformSphere(s.next(), s.next());
    }
    out.push_back(directionBasis(w));
  }
  return out;
}

std::vector<float> phaseWeights(const std::vector<Direction>& dirs, api::PhaseModel phase, float g) {
  const std::size_t D = dirs.size();
  std::vector<float> W(D * D);
  for (std::size_t i = 0; i < D; ++i) {
    const std::vector<double> col = phaseColumn(dirs, phase, g, dirs[i].w);
    for (std::size_t d = 0; d < D; ++d) W[d * D + i] = static_cast<float>(col[d]);
  }
  return W;
}

std::vector<double> phaseColumn(const std::vector<Direction>& dirs, api::PhaseModel phase, float g, glm::vec3 out) {
  std::vector<double> col(dirs.size());
  double sum = 0.0;
  for (std::size_t d = 0; d < dirs.size(); ++d) sum += col[d] = rt::phaseValue(phase, g, glm::dot(dirs[d].w, out));
  for (double& c : col) c = sum > 0.0 ? c / sum : 1.0 / double(dirs.size());
  return col;
}

double quadratureDeviation(const std::vector<Direction>& dirs, api::PhaseModel phase, float g) {
  double worst = 0.0;
  for (const Direction& o : dirs) {
    double sum = 0.0;
    for (const Direction& d : dirs) sum += rt::phaseValue(phase, g, glm::dot(d.w, o.w));
    worst = std::max(worst, std::abs(4.0 * kPiD / double(dirs.size()) * sum - 1.0));
  }
  return worst;
}

int binOf(const Direction& d, glm::vec3 center, float radius, int window, glm::vec3 x) {
  const glm::vec3 r = x - center;
  const float scale = float(window) / (2.f * radius);
  const int bu = std::clamp(static_cast<int>(std::floor((glm::dot(r, d.u) + radius) * scale)), 0, window - 1);
  const int bv = std::clamp(static_cast<int>(std::floor((glm::dot(r, d.v) + radius) * scale)), 0, window - 1);
  return bv * window + bu;
}

float boundaryDistance(const Direction& d, glm::vec3 center, float radius, glm::vec3 x) {
  const glm::vec3 r = x - center;
  const float b = glm::dot(r, d.w);
  return b + std::sqrt(std::max(0.f, b * b - glm::dot(r, r) + radius * radius));
}

double Visibility::occupancy() const {
  if (upstream.empty()) return 0.0;
  return double(std::count(upstream.begin(), upstream.end(), -1)) / double(upstream.size());
}

int Visibility::longestChain() const {
  int longest = 0;
  for (int i = 0; i < directions; ++i)
    for (int p = 0; p < nodes; ++p) {
      int len = 1;
      for (int q = upstream[std::size_t(p) * directions + i]; q >= 0; q = upstream[std::size_t(q) * directions + i]) ++len;
      longest = std::max(longest, len);
    }
  return longest;
}

Visibility buildVisibility(const NodeSet& ns, const std::vector<Direction>& dirs, int window) {
  Visibility v;
  const int N = static_cast<int>(ns.nodes.size()), D = static_cast<int>(dirs.size());
  v.nodes = N, v.directions = D;
  v.upstream.assign(std::size_t(N) * D, -1);
  v.alpha.assign(std::size_t(N) * D, 0.f);
  std::vector<int> bin(N), order(N);
  std::vector<float> depth(N);
  for (int i = 0; i < D; ++i) {
    const Direction& d = dirs[i];
    for (int p = 0; p < N; ++p) {
      bin[p] = binOf(d, ns.center, ns.radius, window, ns.nodes[p].position);
      depth[p] = depthAlong(d, ns.center, ns.nodes[p].position);
    }
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](int a, int b) {
      if (bin[a] != bin[b]) return bin[a] < bin[b];
      if (depth[a] != depth[b]) return depth[a] < depth[b];
      return a < b;
    });
    for (int k = 0; k < N; ++k) {
      const int p = order[k];
      const std::size_t at = std::size_t(p) * D + i;
      const Node& np = ns.nodes[p];
      if (k > 0 && bin[order[k - 1]] == bin[p]) {
        const int q = order[k - 1];
        v.upstream[at] = q;
        v.alpha[at] = 1.f - std::exp(-0.5f * (np.tau + ns.nodes[q].tau) * (depth[p] - depth[q]));
      } else {
        v.alpha[at] = 1.f - std::exp(-np.tau * boundaryDistance(d, ns.center, ns.radius, np.position));
      }
    }
  }
  return v;
}

std::vector<float> exactLinkOpacity(const NodeSet& ns, const std::vector<Direction>& dirs, const Visibility& V,
                                    const rt::ParticleMedium& medium) {
  const std::size_t D = dirs.size();
  std::vector<float> alpha(V.alpha.size());
  for (std::size_t at = 0; at < alpha.size(); ++at) {
    const Direction& d = dirs[at % D];
    const glm::vec3 x = ns.nodes[at / D].position;
    const int q = V.upstream[at];
    const float length = q >= 0 ? depthAlong(d, ns.center, x) - depthAlong(d, ns.center, ns.nodes[std::size_t(q)].position)
                                : boundaryDistance(d, ns.center, ns.radius, x);
    alpha[at] = length > 0.f ? static_cast<float>(1.0 - std::exp(-medium.opticalDepth(x - length * d.w, d.w, 0.f, length)))
                             : 0.f;
  }
  return alpha;
}

std::vector<float> skyTransmittance(const Visibility& V) {
  const std::size_t D = static_cast<std::size_t>(V.directions);
  std::vector<float> T(V.upstream.size(), -1.f);
  std::vector<std::size_t> chain;
  for (std::size_t at = 0; at < T.size(); ++at) {
    // Walk up to the first link already known (or the boundary), then multiply back down.
    chain.clear();
    for (std::size_t k = at; T[k] < 0.f;) {
      chain.push_back(k);
      const int q = V.upstream[k];
      if (q < 0) break;
      k = std::size_t(q) * D + at % D;
    }
    for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
      const int q = V.upstream[*it];
      T[*it] = (1.f - V.alpha[*it]) * (q < 0 ? 1.f : T[std::size_t(q) * D + at % D]);
    }
  }
  return T;
}

std::vector<double> lightTransmittance(const NodeSet& ns, const std::vector<DirectionalLight>& lights, int window) {
  const std::size_t N = ns.nodes.size(), L = lights.size();
  std::vector<double> T(N * L, 1.0);
  for (std::size_t l = 0; l < L; ++l) {
    const Visibility v = buildVisibility(ns, {directionBasis(lights[l].w)}, window);
    for (std::size_t p = 0; p < N; ++p) {
      double t = 1.0;
      for (int q = static_cast<int>(p); q >= 0; q = v.upstream[std::size_t(q)]) t *= 1.0 - v.alpha[std::size_t(q)];
      T[p * L + l] = t;
    }
  }
  return T;
}

std::vector<double> lightTransmittance(const NodeSet& ns, const std::vector<DirectionalLight>& lights,
                                       const rt::ParticleMedium& medium) {
  const std::size_t N = ns.nodes.size(), L = lights.size();
  std::vector<double> T(N * L, 1.0);
  for (std::size_t p = 0; p < N; ++p)
    for (std::size_t l = 0; l < L; ++l)
      T[p * L + l] = std::exp(-medium.opticalDepth(ns.nodes[p].position, -lights[l].w, 0.f, 1e30f));
  return T;
}

glm::dvec3 nodeSource(const Problem& pb, int p, glm::vec3 w) {
  const Node& n = pb.nodes->nodes[std::size_t(p)];
  glm::dvec3 e(n.emission);
  const std::size_t L = pb.lights.size();
  for (std::size_t l = 0; l < L; ++l) {
    const double P = rt::phaseValue(pb.nodes->phase, pb.nodes->g, glm::dot(pb.lights[l].w, w));
    e += glm::dvec3(n.albedo) * P * glm::dvec3(pb.lights[l].irradiance) * pb.transmittance[std::size_t(p) * L + l];
  }
  return e;
}

double linearSourceWeight(double alpha) {
  if (!(alpha < 1.0)) return 1.0;
  const double u = -std::log1p(-alpha);
  return u > 1e-6 ? 1.0 - alpha / u : 0.5 * u;
}

double iterate(const Problem& pb, const std::vector<glm::dvec3>& in, std::vector<glm::dvec3>& out) {
  const Visibility& V = *pb.visibility;
  const int N = V.nodes, D = V.directions;
  const std::vector<float>& W = *pb.weights;
  out.resize(in.size());
  // Every node's source towards every direction: e_p(w_i) + a_p sum_d W[d,i] I[p,d].
  std::vector<glm::dvec3> src(in.size());
  for (int p = 0; p < N; ++p)
    for (int i = 0; i < D; ++i) {
      glm::dvec3 S(0.0);
      for (int d = 0; d < D; ++d) S += double(W[std::size_t(d) * D + i]) * in[std::size_t(p) * D + d];
      src[std::size_t(p) * D + i] =
          nodeSource(pb, p, (*pb.dirs)[std::size_t(i)].w) + glm::dvec3(pb.nodes->nodes[std::size_t(p)].albedo) * S;
    }
  double residual = 0.0;
  for (int p = 0; p < N; ++p)
    for (int i = 0; i < D; ++i) {
      const std::size_t at = std::size_t(p) * D + i;
      const int up = V.upstream[at];
      const double alpha = V.alpha[at];
      const glm::dvec3 upstreamI = up >= 0 ? in[std::size_t(up) * D + i] : pb.sky;
      const glm::dvec3 Sq = src[up >= 0 ? std::size_t(up) * D + i : at];
      out[at] = (1.0 - alpha) * upstreamI + alpha * Sq;
      if (pb.linearSource) out[at] += linearSourceWeight(alpha) * (src[at] - Sq);
      const glm::dvec3 diff = glm::abs(out[at] - in[at]);
      residual = std::max(residual, std::max(diff.x, std::max(diff.y, diff.z)));
    }
  return residual;
}

double contractionFactor(const Problem& pb) {
  const Visibility& V = *pb.visibility;
  double q = 0.0;
  for (int p = 0; p < V.nodes; ++p)
    for (int i = 0; i < V.directions; ++i) {
      const std::size_t at = std::size_t(p) * V.directions + i;
      const int up = V.upstream[at];
      const glm::vec3 a = pb.nodes->nodes[std::size_t(up >= 0 ? up : p)].albedo;
      q = std::max(q, 1.0 - double(V.alpha[at]) * (1.0 - double(std::max(a.x, std::max(a.y, a.z)))));
    }
  return q;
}

glm::dvec3 cameraSource(const Problem& pb, const std::vector<glm::dvec3>& I, int p, glm::vec3 w) {
  const std::vector<double> col = phaseColumn(*pb.dirs, pb.nodes->phase, pb.nodes->g, w);
  glm::dvec3 S(0.0);
  const std::size_t D = col.size();
  for (std::size_t d = 0; d < D; ++d) S += col[d] * I[std::size_t(p) * D + d];
  return nodeSource(pb, p, w) + glm::dvec3(pb.nodes->nodes[std::size_t(p)].albedo) * S;
}

long long shaderLoopBudget(std::string_view glRenderer) {
  auto contains = [&](std::string_view word) {
    if (glRenderer.size() < word.size()) return false;
    for (std::size_t i = 0; i + word.size() <= glRenderer.size(); ++i) {
      bool match = true;
      for (std::size_t k = 0; k < word.size() && match; ++k)
        match = std::tolower(static_cast<unsigned char>(glRenderer[i + k])) == word[k];
      if (match) return true;
    }
    return false;
  };
  return contains("llvmpipe") || contains("softpipe") ? kSoftwareLoopBudget : kHardwareLoopBudget;
}

long long marchPieceLoops(long long particles, long long nodes, long long lights, long long directions, bool skyExact) {
  return 1 + particles + nodes + lights * (1 + particles) + (skyExact ? directions * (1 + particles) : 0);
}

}  // namespace radiant::network
