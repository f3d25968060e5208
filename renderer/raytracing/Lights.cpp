#include "renderer/raytracing/Lights.h"

namespace radiant::rt {
namespace {

float meanChannel(const glm::vec3& c) { return (c.r + c.g + c.b) / 3.f; }

// A unit vector's orthonormal complement (the plane a disk of emission lies in).
void planeOf(const glm::vec3& d, glm::vec3& t, glm::vec3& b) {
  const ShadingFrame f = ShadingFrame::fromNormal(d);
  t = f.t;
  b = f.b;
}

// Uniform direction in the cone of half-angle acos(cosMax) around +z: p = 1 / (2 pi (1 - cosMax)).
glm::vec3 sampleUniformCone(glm::vec2 u, float cosMax) {
  const float cosTheta = 1.f - u.x * (1.f - cosMax);
  const float sinTheta = safeSqrt(1.f - cosTheta * cosTheta);
  const float phi = 2.f * kPi * u.y;
  return {sinTheta * std::cos(phi), sinTheta * std::sin(phi), cosTheta};
}

}  // namespace

glm::vec3 punctualPower(const Light& light) {
  const glm::vec3 I = light.color * light.intensity;
  switch (light.type) {
    case LightType::Point: return 4.f * kPi * I;
    case LightType::Spot: {
      const float cosOuter = std::cos(light.outerConeAngle), cosInner = std::cos(light.innerConeAngle);
      return 2.f * kPi * I * ((1.f - cosInner) + std::max(0.f, cosInner - cosOuter) / 3.f);
    }
    default: return glm::vec3(0.f);  // directional: see SceneLights
  }
}

bool punctualLi(const Light& light, const glm::vec3& p, glm::vec3& wi, float& distance, glm::vec3& Li) {
  Li = light.color * light.intensity;
  distance = kInf;
  if (light.type == LightType::Directional) {
    const float len = glm::length(light.direction);
    if (!(len > 0.f)) return false;
    wi = -light.direction / len;  // directional intensity is the irradiance normal to the beam (lux)
  } else {
    const glm::vec3 d = light.position - p;
    const float d2 = glm::dot(d, d);
    if (!(d2 > 0.f)) return false;
    distance = std::sqrt(d2);
    wi = d / distance;
    Li *= rangeWindow(distance, light.range) / d2;
    if (light.type == LightType::Spot) {
      const float len = glm::length(light.direction);
      if (!(len > 0.f)) return false;
      Li *= spotFalloff(light, glm::dot(light.direction / len, -wi));
    }
  }
  return maxComponent(Li) > 0.f;
}

SceneLights::SceneLights(const RayScene& rays, const Image* environmentMap, glm::vec3 skyRadiance,
                         std::shared_ptr<const EnvironmentDistribution> environmentDistribution)
    : rays_(rays), environment_(environmentMap, skyRadiance, std::move(environmentDistribution)) {
  const Scene& scene = rays.scene();
  Bounds bounds;
  for (const MeshInstance& m : scene.meshes) bounds.extend(m.bounds);
  center_ = bounds.center();
  radius_ = std::max(bounds.radius(), 1e-30f);
  const float diskArea = kPi * radius_ * radius_;

  for (std::size_t i = 0; i < scene.lights.size(); ++i) {
    const Light& l = scene.lights[i];
    glm::vec3 power = l.type == LightType::Directional ? l.color * l.intensity * diskArea : punctualPower(l);
    if (l.type == LightType::Directional && !(glm::length(l.direction) > 0.f)) power = glm::vec3(0.f);
    emitters_.push_back({Kind::Punctual, static_cast<int>(i), power});
  }
  triangleCdf_.push_back(0.f);
  const auto& tris = rays.triangleLights();
  for (std::size_t t = 0; t < tris.size(); ++t) {
    const Material& mat = rays.materialOf(tris[t].mesh);
    const float sides = mat.doubleSided ? 2.f : 1.f;
    // NEE: power ~ area * emitted radiance (max channel, so no coloured emitter gets probability 0).
    triangleCdf_.push_back(triangleCdf_.back() + sides * tris[t].area * maxComponent(mat.emission()));
    emitters_.push_back({Kind::Triangle, static_cast<int>(t), kPi * sides * tris[t].area * mat.emission()});
  }
  triangleTotal_ = triangleCdf_.back();
  if (environment_.active()) emitters_.push_back({Kind::Environment, -1, diskArea * environment_.integral()});

  emitterCdf_.push_back(0.f);
  for (const Emitter& e : emitters_) {
    const float w = meanChannel(e.power);
    emitterCdf_.push_back(emitterCdf_.back() + (std::isfinite(w) && w > 0.f ? w : 0.f));
  }
  total_ = emitterCdf_.back();
}

bool SceneLights::sampleTriangle(float uSelect, glm::vec2 uPoint, SurfaceHit& point, float& pSelect) const {
  if (!(triangleTotal_ > 0.f)) return false;
  const auto& tris = rays_.triangleLights();
  const int li = findInterval(triangleCdf_.data(), static_cast<int>(tris.size()), uSelect * triangleTotal_);
  pSelect = (triangleCdf_[li + 1] - triangleCdf_[li]) / triangleTotal_;
  if (!(pSelect > 0.f)) return false;
  point = rays_.pointOn(tris[li].mesh, tris[li].prim, sampleUniformTriangle(uPoint));
  return true;
}

float SceneLights::trianglePdf(const SurfaceHit& hit, const glm::vec3& dir) const {
  const int offset = rays_.emissiveOffset(hit.mesh);
  if (!(triangleTotal_ > 0.f) || offset < 0) return 0.f;
  const int li = offset + hit.prim;
  const TriangleLight& tl = rays_.triangleLights()[li];
  const float pSelect = (triangleCdf_[li + 1] - triangleCdf_[li]) / triangleTotal_;
  const float cosL = std::abs(glm::dot(hit.ng, dir));
  if (pSelect <= 0.f || cosL <= 0.f || tl.area <= 0.f) return 0.f;
  return pSelect * hit.distance * hit.distance / (tl.area * cosL);
}

bool SceneLights::sampleLe(Sampler& sampler, Emission& out) const {
  if (!(total_ > 0.f)) return false;
  const float uSelect = sampler.next();
  const glm::vec2 u1 = sampler.next2();
  const glm::vec2 u2 = sampler.next2();
  const int i = findInterval(emitterCdf_.data(), static_cast<int>(emitters_.size()), uSelect * total_);
  const float pSelect = (emitterCdf_[i + 1] - emitterCdf_[i]) / total_;
  if (!(pSelect > 0.f)) return false;
  LeSample s;
  if (!sampleLe(i, u1, u2, s)) return false;
  out = Emission{};
  out.light = i;
  out.ray = s.ray;
  out.flux = s.L * (s.cosine / (s.pdfPos * s.pdfDir * pSelect));
  const Emitter& e = emitters_[i];
  if (e.kind == Kind::Punctual && rays_.scene().lights[e.index].type != LightType::Directional)
    out.windowRange = rays_.scene().lights[e.index].range;
  return maxComponent(out.flux) > 0.f;
}

bool SceneLights::sampleLe(int i, glm::vec2 u1, glm::vec2 u2, LeSample& out) const {
  const Emitter& e = emitters_.at(i);
  out = LeSample{};
  const float diskPdf = 1.f / (kPi * radius_ * radius_);
  switch (e.kind) {
    case Kind::Punctual: {
      const Light& l = rays_.scene().lights[e.index];
      const glm::vec3 I = l.color * l.intensity;
      if (l.type == LightType::Directional) {
        // Parallel rays through a disk of the bounding sphere's radius, perpendicular to the beam.
        if (!(glm::length(l.direction) > 0.f)) return false;
        const glm::vec3 d = glm::normalize(l.direction);
        glm::vec3 t, b;
        planeOf(d, t, b);
        const glm::vec2 disk = sampleConcentricDisk(u1) * radius_;
        out.ray = Ray{center_ - 1.01f * radius_ * d + disk.x * t + disk.y * b, d, 0.f, kInf};
        out.L = I;
        out.pdfPos = diskPdf;
        out.pdfDir = 1.f;
        return maxComponent(I) > 0.f;
      }
      out.pdfPos = 1.f;
      if (l.type == LightType::Point) {
        out.ray = Ray{l.position, sampleUniformSphere(u1), 0.f, kInf};
        out.L = I;
        out.pdfDir = uniformSpherePdf();
        return maxComponent(I) > 0.f;
      }
      if (!(glm::length(l.direction) > 0.f)) return false;
      const glm::vec3 axis = glm::normalize(l.direction);
      const float cosOuter = std::cos(l.outerConeAngle);
      const glm::vec3 local = sampleUniformCone(u1, cosOuter);
      const ShadingFrame f = ShadingFrame::fromNormal(axis);
      out.ray = Ray{l.position, glm::normalize(f.toWorld(local)), 0.f, kInf};
      out.L = I * spotFalloff(l, local.z);
      out.pdfDir = 1.f / (2.f * kPi * (1.f - cosOuter));
      return maxComponent(out.L) > 0.f;
    }
    case Kind::Triangle: {
      // A point uniform by area, a direction cosine-weighted about the emitting side (Stürzlinger &
      // Bastos say "uniform" for diffuse emitters; for a Lambertian emitter the flux leaves
      // cosine-distributed, which this samples exactly): flux = Le pi A sides.
      const TriangleLight& tl = rays_.triangleLights()[e.index];
      const Material& mat = rays_.materialOf(tl.mesh);
      const SurfaceHit p = rays_.pointOn(tl.mesh, tl.prim, sampleUniformTriangle(u1));
      glm::vec3 n = p.ng;
      float sides = 1.f;
      if (mat.doubleSided) {
        sides = 2.f;
        if (u2.x < 0.5f) n = -n;
        u2.x = u2.x < 0.5f ? 2.f * u2.x : 2.f * u2.x - 1.f;
      }
      const glm::vec3 local = sampleCosineHemisphere(u2);
      const glm::vec3 dir = glm::normalize(ShadingFrame::fromNormal(n).toWorld(local));
      out.ray = Ray{RayScene::offsetOrigin(p.p, p.ng, p.offsetScale, dir), dir, 0.f, kInf};
      out.L = rays_.emissionAt(p, -dir);
      out.cosine = std::abs(glm::dot(n, dir));
      out.pdfPos = 1.f / tl.area;
      out.pdfDir = cosineHemispherePdf(out.cosine) / sides;
      return out.pdfDir > 0.f && tl.area > 0.f && maxComponent(out.L) > 0.f;
    }
    case Kind::Environment: {
      float pdf = 0.f;
      const glm::vec3 wi = environment_.sample(u1, pdf);  // towards the sky
      if (!(pdf > 0.f)) return false;
      glm::vec3 t, b;
      planeOf(wi, t, b);
      const glm::vec2 disk = sampleConcentricDisk(u2) * radius_;
      out.ray = Ray{center_ + 1.01f * radius_ * wi + disk.x * t + disk.y * b, -wi, 0.f, kInf};
      out.L = environment_.radiance(wi);
      out.pdfPos = diskPdf;
      out.pdfDir = pdf;
      return maxComponent(out.L) > 0.f;
    }
  }
  return false;
}

void SceneLights::pdfLe(int i, const Ray& ray, float& pdfPos, float& pdfDir) const {
  const Emitter& e = emitters_.at(i);
  pdfPos = pdfDir = 0.f;
  // The bounding disk across `axis`: the origin's distance from the line through the centre.
  auto onDisk = [&](const glm::vec3& axis) {
    const glm::vec3 r = ray.org - center_;
    const glm::vec3 across = r - glm::dot(r, axis) * axis;
    return glm::dot(across, across) <= radius_ * radius_ * (1.f + 1e-4f);
  };
  switch (e.kind) {
    case Kind::Punctual: {
      const Light& l = rays_.scene().lights[e.index];
      if (!(glm::length(l.direction) > 0.f) && l.type != LightType::Point) return;
      if (l.type == LightType::Directional) {
        if (onDisk(glm::normalize(l.direction))) pdfPos = 1.f / (kPi * radius_ * radius_);
        return;  // pdfDir: a delta
      }
      if (l.type == LightType::Point) {
        pdfDir = uniformSpherePdf();
        return;
      }
      const float cosOuter = std::cos(l.outerConeAngle);
      if (glm::dot(glm::normalize(l.direction), ray.dir) >= cosOuter) pdfDir = 1.f / (2.f * kPi * (1.f - cosOuter));
      return;
    }
    case Kind::Triangle: {
      const TriangleLight& tl = rays_.triangleLights()[e.index];
      const Material& mat = rays_.materialOf(tl.mesh);
      const glm::vec3 ng = rays_.pointOn(tl.mesh, tl.prim, glm::vec2(1.f / 3.f)).ng;
      const float c = glm::dot(ng, ray.dir);
      pdfPos = tl.area > 0.f ? 1.f / tl.area : 0.f;
      pdfDir = mat.doubleSided ? cosineHemispherePdf(std::abs(c)) / 2.f : cosineHemispherePdf(c);
      return;
    }
    case Kind::Environment: {
      const glm::vec3 wi = -ray.dir;
      if (onDisk(wi)) pdfPos = 1.f / (kPi * radius_ * radius_);
      pdfDir = environment_.pdf(wi);
      return;
    }
  }
}

}  // namespace radiant::rt
