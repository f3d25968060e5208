#include "renderer/raytracing/ParticleMedium.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <embree3/rtcore.h>

#include "renderer/raytracing/Media.h"

namespace radiant::rt {

struct ParticleMedium::Embree {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  ~Embree() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
};

namespace {

// rtcIntersect1's context, extended with where the chords go (the Embree 3 idiom for user data).
struct ChordContext {
  RTCIntersectContext context;
  const std::vector<MediumParticle>* particles;
  std::vector<Chord>* out;
};

void particleBounds(const RTCBoundsFunctionArguments* args) {
  const auto& p = (*static_cast<const std::vector<MediumParticle>*>(args->geometryUserPtr))[args->primID];
  RTCBounds* b = args->bounds_o;
  b->lower_x = p.center.x - p.radius, b->lower_y = p.center.y - p.radius, b->lower_z = p.center.z - p.radius;
  b->upper_x = p.center.x + p.radius, b->upper_y = p.center.y + p.radius, b->upper_z = p.center.z + p.radius;
}

// Records the chord and reports no hit, so traversal visits every sphere on the segment.
void particleChord(const RTCIntersectFunctionNArguments* args) {
  if (args->N != 1 || !args->valid[0]) return;
  auto* ctx = reinterpret_cast<ChordContext*>(args->context);
  const RTCRay& ray = reinterpret_cast<RTCRayHit*>(args->rayhit)->ray;
  const MediumParticle& p = (*ctx->particles)[args->primID];
  const glm::vec3 org(ray.org_x, ray.org_y, ray.org_z), dir(ray.dir_x, ray.dir_y, ray.dir_z);
  const glm::vec3 oc = p.center - org;
  const float tc = glm::dot(oc, dir);
  const glm::vec3 perp = oc - tc * dir;  // not |oc|^2 - tc^2, which cancels far from the origin
  const float d2 = glm::dot(perp, perp);
  const float w2 = p.radius * p.radius - d2;
  if (!(w2 > 0.f)) return;
  const float w = std::sqrt(w2);
  const float t0 = std::max(ray.tnear, tc - w), t1 = std::min(ray.tfar, tc + w);
  if (t1 > t0) ctx->out->push_back({t0, t1, static_cast<int>(args->primID)});
}

}  // namespace

ParticleMedium::ParticleMedium(const std::vector<api::ParticleSystem>& systems) : embree_(std::make_unique<Embree>()) {
  for (std::size_t s = 0; s < systems.size(); ++s) {
    const api::ParticleSystem& sys = systems[s];
    for (const api::Particle& q : sys.particles) {
      MediumParticle p;
      p.center = q.position;
      p.radius = q.radius;
      p.tau = q.tau;
      p.albedo = q.albedo;
      p.emission = sys.emits() ? sys.emissionScale * blackbodyRgb(q.temperature) : glm::vec3(0.f);
      p.linear = linearDensity(sys.profile);
      p.phase = sys.phase;
      p.g = sys.g;
      p.system = static_cast<int>(s);
      if (p.tau > 0.f) particles_.push_back(p);  // tau 0 neither absorbs nor emits
    }
  }
  Embree& e = *embree_;
  e.device = rtcNewDevice(nullptr);
  if (!e.device) throw std::runtime_error("ParticleMedium::ParticleMedium(): rtcNewDevice failed");
  e.scene = rtcNewScene(e.device);
  rtcSetSceneFlags(e.scene, RTC_SCENE_FLAG_ROBUST);
  if (!particles_.empty()) {
    RTCGeometry g = rtcNewGeometry(e.device, RTC_GEOMETRY_TYPE_USER);
    rtcSetGeometryUserPrimitiveCount(g, static_cast<unsigned>(particles_.size()));
    rtcSetGeometryUserData(g, &particles_);
    rtcSetGeometryBoundsFunction(g, particleBounds, nullptr);
    rtcSetGeometryIntersectFunction(g, particleChord);
    rtcCommitGeometry(g);
    rtcAttachGeometry(e.scene, g);
    rtcReleaseGeometry(g);
  }
  rtcCommitScene(e.scene);
  if (const RTCError err = rtcGetDeviceError(e.device); err != RTC_ERROR_NONE)
    throw std::runtime_error("ParticleMedium::ParticleMedium(): rtcCommitScene failed: Embree error " +
                             std::to_string(static_cast<int>(err)));
}

ParticleMedium::~ParticleMedium() = default;

void ParticleMedium::chords(const glm::vec3& org, const glm::vec3& dir, float tmin, float tmax,
                            std::vector<Chord>& out) const {
  out.clear();
  if (particles_.empty() || !(tmax > tmin)) return;
  ChordContext ctx;
  rtcInitIntersectContext(&ctx.context);
  ctx.particles = &particles_;
  ctx.out = &out;
  RTCRayHit rh{};
  rh.ray.org_x = org.x, rh.ray.org_y = org.y, rh.ray.org_z = org.z;
  rh.ray.dir_x = dir.x, rh.ray.dir_y = dir.y, rh.ray.dir_z = dir.z;
  rh.ray.tnear = tmin;
  rh.ray.tfar = std::min(tmax, 3.0e38f);
  rh.ray.mask = 0xFFFFFFFFu;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(embree_->scene, &ctx.context, &rh);
}

double ParticleMedium::opticalDepth(int i, const glm::vec3& org, const glm::vec3& dir, float tmin, float tmax) const {
  const MediumParticle& p = particles_[static_cast<std::size_t>(i)];
  const glm::dvec3 oc = glm::dvec3(p.center) - glm::dvec3(org);
  const double tc = glm::dot(oc, glm::dvec3(dir));
  const double d = glm::length(oc - tc * glm::dvec3(dir));
  return sphereOpticalDepth(p.linear, p.tau, p.radius, d, double(tmin) - tc, double(tmax) - tc);
}

double ParticleMedium::opticalDepth(const glm::vec3& org, const glm::vec3& dir, float tmin, float tmax) const {
  thread_local std::vector<Chord> scratch;
  chords(org, dir, tmin, tmax, scratch);
  double sum = 0.0;
  for (const Chord& c : scratch) sum += opticalDepth(c.particle, org, dir, tmin, tmax);
  return sum;
}

float ParticleMedium::density(int i, const glm::vec3& x) const {
  const MediumParticle& p = particles_[static_cast<std::size_t>(i)];
  return particleDensity(p.linear, p.tau, p.radius, glm::length(x - p.center));
}

bool ParticleMedium::sampleCollision(const glm::vec3& org, const glm::vec3& dir, float tmin, float tmax,
                                     Sampler& sampler, float& t, int& particle, std::vector<Chord>& cs) const {
  chords(org, dir, tmin, tmax, cs);
  if (cs.empty()) return false;
  // Break points of the piecewise majorant: between two consecutive chord ends the set of particles
  // is fixed, and the sum of their peak extinctions bounds the density.
  thread_local std::vector<float> ends;
  ends.clear();
  for (const Chord& c : cs) ends.push_back(c.t0), ends.push_back(c.t1);
  std::sort(ends.begin(), ends.end());
  for (std::size_t k = 0; k + 1 < ends.size(); ++k) {
    const float a = ends[k], b = ends[k + 1];
    if (!(b > a)) continue;
    const float mid = 0.5f * (a + b);
    float majorant = 0.f;
    for (const Chord& c : cs)
      if (c.t0 <= mid && mid <= c.t1) majorant += particles_[static_cast<std::size_t>(c.particle)].tau;
    if (!(majorant > 0.f)) continue;
    float s = a;
    for (;;) {
      s -= std::log(1.f - sampler.next()) / majorant;
      if (!(s < b)) break;
      const glm::vec3 x = org + s * dir;
      float sigma = 0.f;
      for (const Chord& c : cs)
        if (c.t0 <= s && s <= c.t1) sigma += density(c.particle, x);
      float u = sampler.next() * majorant;
      if (u >= sigma) continue;  // a null collision
      t = s;
      for (const Chord& c : cs) {
        if (!(c.t0 <= s && s <= c.t1)) continue;
        particle = c.particle;  // the last active one absorbs rounding
        u -= density(c.particle, x);
        if (u < 0.f) break;
      }
      return true;
    }
  }
  return false;
}

}  // namespace radiant::rt
