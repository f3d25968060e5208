#include "renderer/techniques/light_volumes/Beams.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <mutex>
#include <random>

#include "renderer/raytracing/Bsdf.h"
#include "renderer/raytracing/Lights.h"
#include "renderer/raytracing/VolumeInterior.h"

namespace radiant::light_volumes {
namespace {

constexpr float kMaxCullAngle = 1.2f;  // rad: glossy bounds padded further than this are unbounded
// A scatterer (mesh x light) falls back to specular beams when more than this fraction of its glossy
// beams fail the tessellation condition.
constexpr float kFallbackFraction = 0.1f;

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

glm::vec4 v4(const glm::vec3& v, float w) { return {v.x, v.y, v.z, w}; }

// The gathering lays the Gaussian rho over the flat angular domain (|X| = phi) and spreads each beam
// over its flux plane, so on a receiver plane perpendicular to the beam at distance d a point at angle
// phi lies at x = d tan(phi): the beam delivers 2 pi int rho(phi) tan(phi) sec^2(phi) dphi
// = 1 + (4/3) E[phi^2] + O(sigma^4) = 1 + (8/3) sigma^2 of its flux (measured before: ~1 + 3.3 sigma^2
// on the bench's plates). Dividing the flux by it makes the whole glossy beam deliver Phi, as the
// reference's lobe (normalised by its albedo) does.
float planeGain(float sigma) { return 1.f + (8.f / 3.f) * sigma * sigma; }

constexpr int kAlbedoMu = 33, kAlbedoStrata = 64;
using AlbedoRow = std::array<glm::vec2, kAlbedoMu>;

// (A, B) of ggxReflectionAlbedo at mu: VNDF sampling of h about wo (the direction towards the light)
// makes f cos / pdf = F G2 / G1 (Heitz 2018, eq. 19), so A is the mean of G2 / G1 over the reflected
// directions above the horizon and B the mean of G2 / G1 (1 - wo.h)^5.
glm::vec2 albedoAt(float mu, float alpha) {
  mu = std::clamp(mu, 1e-4f, 1.f);
  const glm::vec3 wo(std::sqrt(1.f - mu * mu), 0.f, mu);
  const float g1 = rt::smithG1(mu, alpha);
  double a = 0.0, b = 0.0;
  // Jittered strata with a fixed seed: the strata's midpoints alone are biased by ~0.7% (the map from
  // the unit square to h is singular at the disk's rim, where wi crosses the horizon).
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> jitter(0.f, 1.f);
  for (int i = 0; i < kAlbedoStrata; ++i)
    for (int j = 0; j < kAlbedoStrata; ++j) {
      const glm::vec2 u((i + jitter(rng)) / kAlbedoStrata, (j + jitter(rng)) / kAlbedoStrata);
      const glm::vec3 h = rt::sampleGgxVndf(wo, alpha, u);
      const glm::vec3 wi = rt::reflect(wo, h);
      if (wi.z <= 0.f) continue;
      const double w = rt::smithG2HeightCorrelated(wo.z, wi.z, alpha) / g1;
      a += w;
      b += w * rt::schlickWeight(glm::dot(wo, h));
    }
  const double n = double(kAlbedoStrata) * kAlbedoStrata;
  return {float(a / n), float(b / n)};
}

const AlbedoRow& albedoRow(float alpha) {
  static std::mutex mutex;
  static std::map<float, AlbedoRow> rows;  // a few entries: one per distinct roughness of the scene
  const std::lock_guard<std::mutex> lock(mutex);
  auto it = rows.find(alpha);
  if (it != rows.end()) return it->second;
  AlbedoRow row;
  for (int k = 0; k < kAlbedoMu; ++k) row[k] = albedoAt(float(k) / (kAlbedoMu - 1), alpha);
  return rows.emplace(alpha, row).first->second;
}

}  // namespace

glm::vec2 ggxReflectionAlbedo(float mu, float alpha) {
  mu = std::clamp(mu, 0.f, 1.f);
  if (!(alpha > 0.f)) return {1.f, rt::schlickWeight(mu)};
  const AlbedoRow& row = albedoRow(alpha);
  const float x = mu * (kAlbedoMu - 1);
  const int k = std::min(int(x), kAlbedoMu - 2);
  return glm::mix(row[k], row[k + 1], x - float(k));
}

float solidAngle(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
  const float la = glm::length(a), lb = glm::length(b), lc = glm::length(c);
  const float num = std::abs(glm::dot(a, glm::cross(b, c)));
  const float den = la * lb * lc + glm::dot(a, b) * lc + glm::dot(a, c) * lb + glm::dot(b, c) * la;
  float omega = 2.f * std::atan2(num, den);  // atan2 keeps the branch right when den < 0 (Omega > pi)
  return omega < 0.f ? omega + 4.f * rt::kPi : omega;
}

float sigmaFromRoughness(float roughness, float cosIncidence, float scale) {
  if (!(roughness > 0.f)) return 0.f;
  const float alpha = rt::alphaFromRoughness(roughness);
  return scale * alpha * std::sqrt(std::clamp(cosIncidence, 0.f, 1.f));
}

BeamCone beamCone(const Beam& beam, float cullSigmas) {
  const glm::vec3 V[3] = {glm::vec3(beam.vertexA), glm::vec3(beam.vertexB), glm::vec3(beam.vertexC)};
  const glm::vec3 d[3] = {glm::vec3(beam.dirA), glm::vec3(beam.dirB), glm::vec3(beam.dirC)};
  const glm::vec3 C = (V[0] + V[1] + V[2]) / 3.f;
  glm::vec3 N = d[0] + d[1] + d[2];
  BeamCone cone;
  const float len = glm::length(N);
  if (!(len > 1e-6f)) {
    cone.originRadius = v4(C, 1e30f);
    cone.axisSlope = glm::vec4(0.f, 0.f, 1.f, 1e30f);
    return cone;
  }
  N /= len;
  // A point of ray k at axial s = (X - C).N has t = (s - h_k) / kappa_k and lies within
  // |(V_k - C)_perp| + |t| |d_k perp| of the axis: for s >= 0, radius0 + slope * s bounds all three,
  // and the flux triangle at s (convex) lies within that disk.
  float a = 0.f, b = 0.f, kappaMin = 1.f, edge = 0.f;
  for (int k = 0; k < 3; ++k) {
    const glm::vec3 r = V[k] - C;
    const float h = glm::dot(r, N);
    const float kappa = std::max(glm::dot(d[k], N), 1e-4f);
    const float perp = glm::length(d[k] - glm::dot(d[k], N) * N);
    a = std::max(a, glm::length(r - h * N) + perp * std::abs(h) / kappa);
    b = std::max(b, perp / kappa);
    kappaMin = std::min(kappaMin, kappa);
    edge = std::max(edge, glm::length(V[(k + 1) % 3] - V[k]));
  }
  const float sigma = beam.fluxSigma.w;
  if (sigma > 0.f) {
    // Glossy: light arrives at F from every point of the scatterer within ~cullSigmas * sigma of its
    // specular direction: pad by tan(that angle) times the distance from the scatterer, at most
    // (s + radius0 + edge) / kappa_min.
    const float angle = cullSigmas * sigma;
    if (angle >= kMaxCullAngle) {
      a = 1e30f;
      b = 1e30f;
    } else {
      const float tp = std::tan(angle);
      a += tp * (a + edge) / kappaMin;
      b += tp / kappaMin;
    }
  }
  cone.originRadius = v4(C, a);
  cone.axisSlope = v4(N, b);
  return cone;
}

bool appendTriangleBeams(const Light& light, const TriangleInput& t, const BeamOptions& o, BeamSet& out) {
  const glm::vec3 e1 = t.p[1] - t.p[0], e2 = t.p[2] - t.p[0];
  const glm::vec3 cr = glm::cross(e1, e2);
  const float area2 = glm::length(cr);
  const glm::vec3 centroid = (t.p[0] + t.p[1] + t.p[2]) / 3.f;
  if (!(area2 > 0.f)) { ++out.degenerate; return false; }
  const glm::vec3 ng = cr / area2;

  // Incident light: direction of travel at each vertex and the flux onto the triangle (§4.1:
  // Phi_s = I Omega_light; a directional light delivers E A |cos|).
  glm::vec3 w[3];
  glm::vec3 flux;
  const glm::vec3 radiant = light.color * light.intensity;
  float towardsLight;  // > 0: the front (ng) side is lit
  if (light.type == LightType::Directional) {
    const glm::vec3 dir = glm::normalize(light.direction);
    for (auto& wk : w) wk = dir;
    towardsLight = -glm::dot(ng, dir);
    flux = radiant * (0.5f * area2 * std::abs(towardsLight));
  } else {
    for (int k = 0; k < 3; ++k) w[k] = glm::normalize(t.p[k] - light.position);
    towardsLight = glm::dot(ng, light.position - centroid);
    float falloff = 1.f;
    if (light.type == LightType::Spot) {
      falloff = 0.f;
      const glm::vec3 axis = glm::normalize(light.direction);
      for (int k = 0; k < 3; ++k) falloff += rt::spotFalloff(light, glm::dot(axis, w[k])) / 3.f;
    }
    falloff *= rt::rangeWindow(glm::length(centroid - light.position), light.range);
    flux = radiant * (solidAngle(t.p[0] - light.position, t.p[1] - light.position, t.p[2] - light.position) * falloff);
  }
  if (!(rt::maxComponent(flux) > 0.f) || !finite(flux)) { ++out.degenerate; return false; }
  const float side = towardsLight > 0.f ? 1.f : -1.f;
  const Material& m = t.material;
  if (side < 0.f && !m.doubleSided && !t.refract && !m.isTransmissive()) { ++out.backfacing; return false; }

  glm::vec3 n[3];
  for (int k = 0; k < 3; ++k) n[k] = side * glm::normalize(t.n[k]);
  const glm::vec3 nLit = side * ng;
  const glm::vec3 nc = glm::normalize(n[0] + n[1] + n[2]);
  const glm::vec3 wc = glm::normalize(w[0] + w[1] + w[2]);
  const float cosIn = std::clamp(-glm::dot(wc, nc), 0.f, 1.f);
  const glm::vec3 base(m.baseColorFactor);
  const float metal = m.metallicFactor, trans = m.transmissionFactor;
  // Inside a transmissive solid the light arrives from the back: the relative index flips.
  const float eta = side > 0.f || !m.isTransmissive() ? m.ior : 1.f / m.ior;

  auto push = [&](const glm::vec3 d[3], const glm::vec3& phi, float sigma, const glm::vec3& planeN, bool shadowBeam) {
    Beam b;
    b.vertexA = v4(t.p[0], 0.f);
    b.vertexB = v4(t.p[1], shadowBeam ? 1.f : 0.f);
    // Its light-path class by the material (beam.glsl, kLvClass*): the specular fallback keeps it.
    b.vertexC = v4(t.p[2], shadowBeam ? 0.f : float(m.roughnessFactor > 0.f ? glsl::kLvClassGlossy : glsl::kLvClassSpecular));
    b.dirA = v4(d[0], 0.f);
    b.dirB = v4(d[1], 0.f);
    b.dirC = v4(d[2], 0.f);
    // A glossy beam's flux is divided by its Gaussian's gain on a receiver plane (planeGain).
    b.fluxSigma = v4(phi / planeGain(sigma), sigma);
    b.plane = v4(planeN, -glm::dot(planeN, t.p[0]));
    // The clamp: A_0 is the triangle's cross-section perpendicular to the mean direction.
    const glm::vec3 N = glm::normalize(d[0] + d[1] + d[2]);
    const float a0 = std::max(0.5f * std::abs(glm::dot(cr, N)), 1e-3f * 0.5f * area2);
    b.vertexA.w = o.maxConcentration / a0;
    out.beams.push_back(b);
    out.cones.push_back(beamCone(b, o.cullSigmas));
  };

  bool any = false;
  // Reflection: metal (conductor Fresnel, Schlick with f0 = baseColor), the opaque dielectric's
  // specular layer and, for transmissive materials, the exact dielectric Fresnel (Bsdf.h).
  {
    // Glossy: the lobe's directional albedo (Schlick over the microfacets and the Smith loss), not
    // Fresnel at the mean normal. The transmissive dielectric keeps its exact Fresnel at cos theta_i
    // times the Smith loss A.
    const glm::vec2 ab = m.roughnessFactor > 0.f ? ggxReflectionAlbedo(cosIn, rt::alphaFromRoughness(m.roughnessFactor))
                                                 : glm::vec2(1.f, rt::schlickWeight(cosIn));
    auto schlickAlbedo = [&](const glm::vec3& f0) { return f0 * (ab.x - ab.y) + glm::vec3(ab.y); };
    const glm::vec3 weight = metal * schlickAlbedo(base) +
                             (1.f - metal) * (1.f - trans) * schlickAlbedo(glm::vec3(rt::f0FromIor(m.ior))) +
                             glm::vec3((1.f - metal) * trans * rt::fresnelDielectric(cosIn, eta) * ab.x);
    if (!t.refract && rt::maxComponent(weight) > 0.f) {
      glm::vec3 d[3];
      for (int k = 0; k < 3; ++k) d[k] = rt::reflect(-w[k], n[k]);
      const float sigma = o.sigmaOverride > 0.f ? o.sigmaOverride : sigmaFromRoughness(m.roughnessFactor, cosIn, o.sigmaScale);
      push(d, flux * weight, sigma, nLit, false);
      ++out.scattered;
      out.glossy += sigma > 0.f ? 1 : 0;
      out.flux += glm::dvec3(flux * weight);
      any = true;
    }
  }
  // Refraction (KHR_materials_transmission as the reference reads it: one interface into a solid of
  // index ior), tinted by baseColor, weighted by (1 - m) t (1 - F); importance transport: no eta^2.
  if (t.refract && m.isTransmissive()) {
    glm::vec3 d[3];
    bool tir = false;
    for (int k = 0; k < 3; ++k) tir = tir || !rt::refract(-w[k], n[k], eta, d[k]);
    if (tir) {
      ++out.tirDropped;
    } else {
      const glm::vec3 weight = (1.f - metal) * trans * (1.f - rt::fresnelDielectric(cosIn, eta)) * base;
      // A microfacet tilted by theta_h turns the reflected ray by 2 theta_h but the refracted one by
      // theta_h |eta - 1| / eta (small angles at normal incidence; Walter et al. 2007's half vector
      // h ~ eta wi + wo): the transmitted lobe is narrower by |eta - 1| / (2 eta), 1/6 for glass.
      const float sigma = o.sigmaOverride > 0.f
                              ? o.sigmaOverride
                              : sigmaFromRoughness(m.roughnessFactor, cosIn, o.sigmaScale) * std::abs(eta - 1.f) / (2.f * eta);
      push(d, flux * weight, sigma, -nLit, false);
      ++out.scattered;
      out.glossy += sigma > 0.f ? 1 : 0;
      out.flux += glm::dvec3(flux * weight);
      any = true;
    }
  }
  // The negative shadow beam: the unscattered light behind the triangle, -Phi (§3.1). Once per
  // triangle (with the reflected beam's call).
  if (o.negativeBeams && !t.refract) {
    push(w, -flux, 0.f, -nLit, true);
    ++out.shadow;
    any = true;
  }
  return any;
}

float tessellationRatio(const Beam& b, const ReceiverDistance& receiverDistance) {
  const float sigma = b.fluxSigma.w;
  if (!(sigma > 0.f) || !receiverDistance) return -1.f;
  const glm::vec3 V[3] = {glm::vec3(b.vertexA), glm::vec3(b.vertexB), glm::vec3(b.vertexC)};
  const glm::vec3 d[3] = {glm::vec3(b.dirA), glm::vec3(b.dirB), glm::vec3(b.dirC)};
  const glm::vec3 N = glm::normalize(d[0] + d[1] + d[2]);
  // The receiver distance d of notes A5, bounded from below by the nearest of the four rays that span
  // the beam's specular footprint: a receiver tilted against the beam is nearer at one corner than at
  // the centroid, and the condition must hold where the footprint is nearest.
  float dist = -1.f;
  auto nearest = [&](const glm::vec3& origin, const glm::vec3& dir) {
    if (!finite(dir) || !(glm::dot(dir, dir) > 0.f)) return;
    const float t = receiverDistance(origin, glm::normalize(dir));
    if (t > 0.f && (dist < 0.f || t < dist)) dist = t;
  };
  nearest((V[0] + V[1] + V[2]) / 3.f, N);
  for (int k = 0; k < 3; ++k) nearest(V[k], d[k]);
  if (!(dist > 0.f)) return -1.f;
  const float edge = std::max({glm::length(V[1] - V[0]), glm::length(V[2] - V[1]), glm::length(V[0] - V[2])});
  return edge / dist / sigma;
}

namespace {

// The light's measure of a triangle: the solid angle it subtends from a point or spot light, its area
// (the projected area over a constant cosine) under a directional light.
float lightMeasure(const Light& light, const glm::vec3 p[3]) {
  if (light.type == LightType::Directional) return 0.5f * glm::length(glm::cross(p[1] - p[0], p[2] - p[0]));
  return solidAngle(p[0] - light.position, p[1] - light.position, p[2] - light.position);
}

// The 1-to-4 levels a triangle needs to meet the condition at its own receiver distance (each level
// halves the edges).
int subdivisionLevel(float ratio, float maxTriangleSigma) {
  return std::clamp(int(std::ceil(std::log2(ratio / maxTriangleSigma))), 1, kMaxSubdivisionLevel);
}

// One glossy beam of a scatterer and where it came from.
struct GlossySource {
  std::size_t beam;
  std::size_t triangle;
  bool refract;
  float ratio;  // tessellationRatio; < 0 unchecked
};

// Splits the glossy beam of `parent` (triangle t, its scattered beam `parentBeam`) into children until
// each meets the condition or kMaxSubdivisionLevel. Child triangles are 1-to-4 midpoint splits of the
// flat triangle; their vertex normals are the parent's interpolated barycentrically and renormalised
// (the warped volume's normals between its vertices), their vertex rays reflected or refracted as the
// parent's (appendTriangleBeams). A child keeps the parent's sigma and its flux is the parent's times
// Omega_child / Omega_parent: the split refines where the light lands, not how much there is (the
// children's solid angles add up to the parent's). Returns false when `budget` would be exceeded.
class Subdivider {
public:
  Subdivider(const Light& light, const BeamOptions& o, const ReceiverDistance& rd, std::size_t budget)
      : light_(light), o_(o), rd_(rd), budget_(budget) {
    childOptions_ = o;
    childOptions_.negativeBeams = false;  // shadow beams stay one per original triangle
  }

  // Appends the children of `parentBeam` to `children`; false when the beams added so far (over every
  // call) would exceed the budget.
  bool split(const TriangleInput& t, const Beam& parentBeam, float ratio, std::vector<Beam>& children) {
    parent_ = &t;
    parentBeam_ = &parentBeam;
    parentMeasure_ = lightMeasure(light_, t.p);
    base_ = children.size();
    if (!(parentMeasure_ > 0.f)) return true;
    // The level the parent's own bound asks for: each level halves the edges at about the same
    // receiver distance; children that still fail (a nearer receiver under them) split again.
    const int level = subdivisionLevel(ratio, o_.maxTriangleSigma);
    const glm::vec3 bary[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    if (!recurse(bary, level, 0, children)) return false;
    const std::size_t made = children.size() - base_;
    if (made > 0) used_ += made - 1;  // the children replace one beam
    return true;
  }
  std::size_t used() const { return used_; }
  std::size_t stillFailing = 0, tirDropped = 0;

private:
  glm::vec3 at(const glm::vec3& b) const { return b.x * parent_->p[0] + b.y * parent_->p[1] + b.z * parent_->p[2]; }
  glm::vec3 normalAt(const glm::vec3& b) const {
    const glm::vec3 n = b.x * parent_->n[0] + b.y * parent_->n[1] + b.z * parent_->n[2];
    const float len = glm::length(n);
    return len > 0.f ? n / len : parent_->n[0];
  }
  // Beams added if the parent's children were `extra` more than now.
  bool fits(std::size_t extra, const std::vector<Beam>& children) const {
    return used_ + (children.size() - base_) + extra <= budget_ + 1;
  }

  // The triangle with barycentric corners `b` (in the parent), split `levels` more times; `depth` splits
  // made so far.
  bool recurse(const glm::vec3 b[3], int levels, int depth, std::vector<Beam>& children) {
    if (levels > 0) {
      const glm::vec3 m01 = 0.5f * (b[0] + b[1]), m12 = 0.5f * (b[1] + b[2]), m20 = 0.5f * (b[2] + b[0]);
      const glm::vec3 sub[4][3] = {{b[0], m01, m20}, {m01, b[1], m12}, {m20, m12, b[2]}, {m01, m12, m20}};
      for (const auto& c : sub)
        if (!recurse(c, levels - 1, depth + 1, children)) return false;
      return true;
    }
    TriangleInput in = *parent_;
    for (int k = 0; k < 3; ++k) {
      in.p[k] = at(b[k]);
      in.n[k] = normalAt(b[k]);
    }
    BeamSet one;
    appendTriangleBeams(light_, in, childOptions_, one);
    if (one.beams.empty()) {  // a child vertex past the critical angle, or degenerate: its light is dropped
      tirDropped += one.tirDropped;
      return true;
    }
    Beam child = one.beams.front();  // one scattered beam: shadow beams off, `refract` picks the one
    const float share = lightMeasure(light_, in.p) / parentMeasure_;
    child.fluxSigma = v4(glm::vec3(parentBeam_->fluxSigma) * share, parentBeam_->fluxSigma.w);
    if (tessellationRatio(child, rd_) > o_.maxTriangleSigma) {
      // A nearer receiver under this child: split it once more.
      if (depth < kMaxSubdivisionLevel) return fits(4, children) && recurse(b, 1, depth, children);
      ++stillFailing;
    }
    if (!fits(1, children)) return false;
    children.push_back(child);
    return true;
  }

  const Light& light_;
  const BeamOptions& o_;
  BeamOptions childOptions_;
  const ReceiverDistance& rd_;
  std::size_t budget_, used_ = 0, base_ = 0;
  const TriangleInput* parent_ = nullptr;
  const Beam* parentBeam_ = nullptr;
  float parentMeasure_ = 0.f;
};

}  // namespace

namespace {

// KHR_materials_volume: a beam leaving a scatterer with a medium against its geometric normal (the
// outward side is the front face) travels inside the closed mesh, as rt::VolumeInterior decides for the
// CPU tracers: refracted into it, or reflected inside it. Its flux is multiplied by the Beer-Lambert
// transmittance exp(-sigma_t t) over its chord t inside, the distance from its centroid along its mean
// direction to the first surface (the exit face; no hit: an open mesh, t = infinity, as the tracers
// take it). The beam keeps going after that face (one interface: it is not refracted again).
void attenuateInsideVolume(const std::vector<TriangleInput>& triangles, const ReceiverDistance& receiverDistance,
                           std::size_t first, BeamSet& out) {
  if (triangles.empty() || !triangles.front().material.hasVolume()) return;
  const rt::VolumeInterior inside{triangles.front().material.attenuationCoefficient()};
  if (!inside.absorbs()) return;
  for (std::size_t i = first; i < out.beams.size(); ++i) {
    Beam& b = out.beams[i];
    if (b.vertexB.w == 1.f) continue;  // shadow beams: the unscattered light, outside
    const glm::vec3 V[3] = {glm::vec3(b.vertexA), glm::vec3(b.vertexB), glm::vec3(b.vertexC)};
    const glm::vec3 N = glm::normalize(glm::vec3(b.dirA) + glm::vec3(b.dirB) + glm::vec3(b.dirC));
    const glm::vec3 ng = glm::cross(V[1] - V[0], V[2] - V[0]);
    if (!(glm::dot(N, ng) < 0.f)) continue;
    const float chord = receiverDistance((V[0] + V[1] + V[2]) / 3.f, N);
    const glm::vec3 T = inside.transmittance(chord > 0.f ? chord : rt::kInf);
    out.flux += glm::dvec3(glm::vec3(b.fluxSigma) * (T - glm::vec3(1.f))) * double(planeGain(b.fluxSigma.w));
    b.fluxSigma = v4(glm::vec3(b.fluxSigma) * T, b.fluxSigma.w);
    ++out.volumeAttenuated;
  }
}

}  // namespace

void appendScattererBeams(const Light& light, const std::vector<TriangleInput>& triangles, const BeamOptions& o,
                          const ReceiverDistance& receiverDistance, BeamSet& out, std::size_t mesh,
                          std::size_t lightIndex, const std::string& name) {
  const std::size_t first = out.beams.size();
  std::vector<GlossySource> glossy;
  for (std::size_t ti = 0; ti < triangles.size(); ++ti) {
    if (ti % 256 == 0) o.cancel.check("light_volumes' beam set-up");
    TriangleInput in = triangles[ti];
    for (const bool refract : {false, true}) {
      if (refract && !in.material.isTransmissive()) break;
      in.refract = refract;
      const std::size_t before = out.beams.size();
      appendTriangleBeams(light, in, o, out);
      for (std::size_t i = before; i < out.beams.size(); ++i)
        if (out.beams[i].vertexB.w != 1.f && out.beams[i].fluxSigma.w > 0.f) glossy.push_back({i, ti, refract, -1.f});
    }
  }
  if (!receiverDistance) return;
  attenuateInsideVolume(triangles, receiverDistance, first, out);
  // The tessellation condition for this scatterer and light.
  std::size_t checked = 0, failed = 0;
  float worst = 0.f;
  for (GlossySource& g : glossy) {
    if (checked % 64 == 0) o.cancel.check("light_volumes' tessellation check");
    g.ratio = tessellationRatio(out.beams[g.beam], receiverDistance);
    if (!(g.ratio >= 0.f)) continue;
    ++checked;
    if (g.ratio > o.maxTriangleSigma) ++failed;
    worst = std::max(worst, g.ratio);
  }
  out.worstTriangleSigma = std::max(out.worstTriangleSigma, worst);
  out.tessellationChecked += checked;
  out.tessellationFailed += failed;
  if (checked == 0) return;
  BeamSet::Scatterer record{mesh, lightIndex, name, checked, failed, worst, false};

  // Subdivision of the failing triangles, all of them or (budget exceeded) none.
  std::size_t failingAfter = failed;
  const std::size_t left = o.maxSubdivisionBeams > out.subdivisionBeamsAdded ? o.maxSubdivisionBeams - out.subdivisionBeamsAdded : 0;
  // What the parents' own bounds ask for is a lower bound of the beams the subdivision adds (children
  // with a nearer receiver split further): when it exceeds the budget, do not start.
  double leastAdded = 0.0;
  for (const GlossySource& g : glossy)
    if (g.ratio > o.maxTriangleSigma)
      leastAdded += std::pow(4.0, subdivisionLevel(g.ratio, o.maxTriangleSigma)) - 1.0;
  if (failed > 0 && left > 0 && leastAdded > double(left)) {
    record.budgetExhausted = true;
    ++out.subdivisionBudgetExhausted;
  } else if (failed > 0 && left > 0) {
    Subdivider subdivider(light, o, receiverDistance, left);
    std::vector<Beam> children;
    std::vector<std::pair<std::size_t, std::pair<std::size_t, std::size_t>>> replaced;  // beam, [begin, end)
    bool fits = true;
    for (const GlossySource& g : glossy) {
      if (!(g.ratio > o.maxTriangleSigma)) continue;
      o.cancel.check("light_volumes' beam subdivision");
      TriangleInput in = triangles[g.triangle];
      in.refract = g.refract;
      const std::size_t begin = children.size();
      if (!subdivider.split(in, out.beams[g.beam], g.ratio, children)) {
        fits = false;
        break;
      }
      replaced.push_back({g.beam, {begin, children.size()}});
    }
    if (!fits) {
      record.budgetExhausted = true;
      ++out.subdivisionBudgetExhausted;
    } else {
      // The first child takes its parent's slot, the others go to the end.
      std::vector<bool> dropped(out.beams.size(), false);
      for (const auto& [beam, range] : replaced) {
        const Beam parent = out.beams[beam];
        glm::dvec3 childFlux(0.0);
        for (std::size_t c = range.first; c < range.second; ++c) childFlux += glm::dvec3(glm::vec3(children[c].fluxSigma));
        // The stored flux is divided by planeGain(sigma); the children share the parent's sigma.
        out.flux += (childFlux - glm::dvec3(glm::vec3(parent.fluxSigma))) * double(planeGain(parent.fluxSigma.w));
        if (range.first == range.second) {
          dropped[beam] = true;
          continue;
        }
        out.beams[beam] = children[range.first];
        out.cones[beam] = beamCone(children[range.first], o.cullSigmas);
        for (std::size_t c = range.first + 1; c < range.second; ++c) {
          out.beams.push_back(children[c]);
          out.cones.push_back(beamCone(children[c], o.cullSigmas));
        }
      }
      for (std::size_t i = dropped.size(); i-- > first;)
        if (dropped[i]) {
          out.beams.erase(out.beams.begin() + std::ptrdiff_t(i));
          out.cones.erase(out.cones.begin() + std::ptrdiff_t(i));
        }
      // Children replace their parents (a parent without children, all its children past the critical
      // angle, is removed).
      out.scattered += children.size();
      out.scattered -= replaced.size();
      out.glossy += children.size();
      out.glossy -= replaced.size();
      out.tirDropped += subdivider.tirDropped;
      out.subdivisionBeamsAdded += subdivider.used();
      out.subdividedBeams += replaced.size();
      out.subdivisionStillFailing += subdivider.stillFailing;
      ++out.subdividedScatterers;
      record.subdividedBeams = replaced.size();
      record.beamsAdded = subdivider.used();
      record.stillFailing = subdivider.stillFailing;
      failingAfter = subdivider.stillFailing;
    }
  }

  const bool fallback = o.specularFallback && float(failingAfter) > kFallbackFraction * float(checked);
  record.specularFallback = fallback;
  out.scatterers.push_back(record);
  if (fallback) {
    ++out.specularFallbacks;
    for (std::size_t i = first; i < out.beams.size(); ++i) {
      if (out.beams[i].fluxSigma.w > 0.f) --out.glossy;
      const glm::vec3 phi = glm::vec3(out.beams[i].fluxSigma) * planeGain(out.beams[i].fluxSigma.w);
      out.beams[i].fluxSigma = v4(phi, 0.f);
      out.cones[i] = beamCone(out.beams[i], o.cullSigmas);
    }
  }
}

double beamCountBound(const Scene& scene) {
  double perLight = 0;
  for (const MeshInstance& m : scene.meshes) {
    const Material& mat = scene.material(m.material);
    if (mat.scattersNarrowLobe()) perLight += double(m.triangleCount()) * (mat.isTransmissive() ? 2.0 : 1.0);
  }
  return perLight * double(scene.lights.size());
}

BeamSet buildBeams(const Scene& scene, const BeamOptions& o, const ReceiverDistance& receiverDistance) {
  BeamSet out;
  std::vector<TriangleInput> triangles;
  for (std::size_t li = 0; li < scene.lights.size(); ++li) {
    const Light& light = scene.lights[li];
    for (std::size_t mi = 0; mi < scene.meshes.size(); ++mi) {
      const MeshInstance& mesh = scene.meshes[mi];
      const Material& mat = scene.material(mesh.material);
      if (!mat.scattersNarrowLobe()) continue;
      triangles.clear();
      TriangleInput in;
      in.material = mat;
      for (std::size_t tri = 0; tri < mesh.triangleCount(); ++tri) {
        for (int k = 0; k < 3; ++k) {
          const std::uint32_t i = mesh.indices[tri * 3 + k];
          in.p[k] = mesh.positions[i];
          in.n[k] = i < mesh.normals.size() ? mesh.normals[i] : glm::vec3(0.f);
        }
        const glm::vec3 ng = glm::cross(in.p[1] - in.p[0], in.p[2] - in.p[0]);
        for (auto& nk : in.n)
          if (!(glm::dot(nk, nk) > 0.f)) nk = ng;
        triangles.push_back(in);
      }
      appendScattererBeams(light, triangles, o, receiverDistance, out, mi, li, mesh.name);
    }
  }
  return out;
}

glm::vec3 gatherIrradiance(const std::vector<Beam>& beams, const glm::vec3& F, const glm::vec3& n, Split split) {
  glm::dvec3 E(0.0);
  for (const Beam& b : beams)
    E += glm::dvec3(glm::vec3(b.fluxSigma)) * double(glsl::beamIrradianceFactor(b, F, n, static_cast<int>(split)));
  return glm::vec3(E);
}

}  // namespace radiant::light_volumes
