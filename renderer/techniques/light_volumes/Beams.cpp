#include "renderer/techniques/light_volumes/Beams.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <mutex>
#include <random>

#include "renderer/raytracing/Bsdf.h"
#include "renderer/raytracing/Lights.h"

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
    b.vertexC = v4(t.p[2], 0.f);
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
      const float sigma = sigmaFromRoughness(m.roughnessFactor, cosIn, o.sigmaScale);
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
      const float sigma = sigmaFromRoughness(m.roughnessFactor, cosIn, o.sigmaScale) * std::abs(eta - 1.f) / (2.f * eta);
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

BeamSet buildBeams(const Scene& scene, const BeamOptions& o, const ReceiverDistance& receiverDistance) {
  BeamSet out;
  for (std::size_t li = 0; li < scene.lights.size(); ++li) {
    const Light& light = scene.lights[li];
    for (std::size_t mi = 0; mi < scene.meshes.size(); ++mi) {
      const MeshInstance& mesh = scene.meshes[mi];
      const Material& mat = scene.material(mesh.material);
      if (!mat.scattersNarrowLobe()) continue;
      const std::size_t first = out.beams.size();
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
        in.refract = false;
        appendTriangleBeams(light, in, o, out);
        if (mat.isTransmissive()) {
          in.refract = true;
          appendTriangleBeams(light, in, o, out);
        }
      }
      // The tessellation condition for this scatterer and light.
      if (!receiverDistance) continue;
      std::size_t checked = 0, failed = 0;
      float worst = 0.f;
      for (std::size_t i = first; i < out.beams.size(); ++i) {
        Beam& b = out.beams[i];
        const float sigma = b.fluxSigma.w;
        if (!(sigma > 0.f)) continue;
        const glm::vec3 V[3] = {glm::vec3(b.vertexA), glm::vec3(b.vertexB), glm::vec3(b.vertexC)};
        const glm::vec3 C = (V[0] + V[1] + V[2]) / 3.f;
        const glm::vec3 N = glm::vec3(out.cones[i].axisSlope);
        const float dist = receiverDistance(C, N);
        if (!(dist > 0.f)) continue;
        const float edge = std::max({glm::length(V[1] - V[0]), glm::length(V[2] - V[1]), glm::length(V[0] - V[2])});
        const float ratio = edge / dist / sigma;
        ++checked;
        if (ratio > o.maxTriangleSigma) ++failed;
        worst = std::max(worst, ratio);
      }
      out.worstTriangleSigma = std::max(out.worstTriangleSigma, worst);
      out.tessellationChecked += checked;
      out.tessellationFailed += failed;
      const bool fallback = o.specularFallback && checked > 0 && float(failed) > kFallbackFraction * float(checked);
      if (checked > 0) out.scatterers.push_back({mi, li, mesh.name, checked, failed, worst, fallback});
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
