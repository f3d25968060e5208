#include "renderer/techniques/ambient_occlusion/AmbientOcclusion.h"
#include "params/ambient_occlusion_params.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

#include <glm/gtc/constants.hpp>

#include "renderer/frame/Beauty.h"
#include "renderer/frame/GpuTypes.h"
#include "renderer/frame/PassContext.h"
#include "renderer/shading/ImageBasedLighting.h"
#include "renderer/shading/GBufferInputs.h"

namespace radiant::gpu {
#include "shaders/ambient_occlusion/shared.h"  // the resolve's unit
}  // namespace radiant::gpu

namespace radiant {
namespace ao {
namespace {

// PCG32 (O'Neill): small, fast and specified bit for bit, so kernels are identical everywhere.
struct Pcg32 {
  std::uint64_t state, inc;
  explicit Pcg32(std::uint64_t seed, std::uint64_t seq = 54u) : state(0u), inc((seq << 1u) | 1u) {
    next();
    state += seed;
    next();
  }
  std::uint32_t next() {
    const std::uint64_t old = state;
    state = old * 6364136223846793005ULL + inc;
    const auto xorshifted = static_cast<std::uint32_t>(((old >> 18u) ^ old) >> 27u);
    const auto rot = static_cast<std::uint32_t>(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
  }
  float uniform() { return static_cast<float>(next() >> 8) * (1.f / 16777216.f); }  // [0,1)
};

// Mitchell's best candidate: each new point is the candidate farthest (by `dist2`) from the points
// already placed.
template <class Point, class Draw, class Dist2>
std::vector<Point> bestCandidate(int n, std::uint32_t seed, Draw draw, Dist2 dist2) {
  Pcg32 rng(seed);
  std::vector<Point> pts;
  pts.reserve(static_cast<std::size_t>(std::max(n, 0)));
  const int candidatesPerPoint = 32;
  for (int i = 0; i < n; ++i) {
    Point best = draw(rng);
    float bestD = -1.f;
    const int candidates = i == 0 ? 1 : candidatesPerPoint;
    for (int c = 0; c < candidates; ++c) {
      const Point p = c == 0 ? best : draw(rng);
      float d = std::numeric_limits<float>::max();
      for (const Point& q : pts) d = std::min(d, dist2(p, q));
      if (d > bestD) { bestD = d; best = p; }
    }
    pts.push_back(best);
  }
  return pts;
}

// Shirley & Chiu's concentric map of [0,1)^2 onto the unit disk: area preserving (uniform stays uniform)
// and of low distortion (blue noise stays blue).
glm::vec2 concentricDisk(glm::vec2 u) {
  const glm::vec2 a = 2.f * u - 1.f;
  if (a.x == 0.f && a.y == 0.f) return glm::vec2(0.f);
  float r, phi;
  if (std::abs(a.x) > std::abs(a.y)) {
    r = a.x;
    phi = glm::quarter_pi<float>() * (a.y / a.x);
  } else {
    r = a.y;
    phi = glm::half_pi<float>() - glm::quarter_pi<float>() * (a.x / a.y);
  }
  return r * glm::vec2(std::cos(phi), std::sin(phi));
}

// 4x4 Bayer matrix: rank of cell (x + 4 y); neighbours get ranks far apart.
constexpr int kBayer4[16] = {0, 8, 2, 10, 12, 4, 14, 6, 3, 11, 1, 9, 15, 7, 13, 5};

}  // namespace

std::vector<glm::vec2> poissonDisk(int n, std::uint32_t seed) {
  // Best candidate directly on the disk crowds points onto the rim (no neighbours beyond it), which
  // would break eq. 4.7's "each sample stands for the same area". So: best candidate on the unit square
  // with toroidal distance (no boundary, uniform), then the area-preserving concentric map.
  const auto square = bestCandidate<glm::vec2>(
      n, seed, [](Pcg32& r) { return glm::vec2(r.uniform(), r.uniform()); },
      [](glm::vec2 p, glm::vec2 q) {
        glm::vec2 d = glm::abs(p - q);
        d = glm::min(d, 1.f - d);
        return glm::dot(d, d);
      });
  std::vector<glm::vec2> pts;
  for (const glm::vec2& u : square) pts.push_back(concentricDisk(u));
  return pts;
}

std::vector<glm::vec3> poissonBall(int n, std::uint32_t seed) {
  // Best-candidate placement in the ball itself crowds the points towards its surface (the boundary has
  // no neighbours beyond it); blue-noise directions on the sphere with stratified radii r = cbrt(xi)
  // keep the radial density uniform in volume.
  const auto dirs = bestCandidate<glm::vec3>(
      n, seed,
      [](Pcg32& r) {
        const float z = 2.f * r.uniform() - 1.f, phi = glm::two_pi<float>() * r.uniform();
        const float s = std::sqrt(std::max(0.f, 1.f - z * z));
        return glm::vec3(s * std::cos(phi), s * std::sin(phi), z);
      },
      [](const glm::vec3& p, const glm::vec3& q) { return glm::dot(p - q, p - q); });
  std::vector<int> order(static_cast<std::size_t>(std::max(n, 0)));
  std::iota(order.begin(), order.end(), 0);
  Pcg32 rng(seed ^ 0xba11u);
  for (int i = n - 1; i > 0; --i) std::swap(order[i], order[rng.next() % static_cast<std::uint32_t>(i + 1)]);
  std::vector<glm::vec3> pts;
  for (int i = 0; i < n; ++i)
    pts.push_back(dirs[i] * std::cbrt((static_cast<float>(order[i]) + 0.5f) / static_cast<float>(n)));
  return pts;
}

SampleBlock buildSampleBlock(Method method, Falloff falloff, int samples) {
  if (samples < 1 || samples > kMaxSamples)
    throw std::invalid_argument("ao::buildSampleBlock(): samples " + std::to_string(samples) + " not in [1, 64]");
  SampleBlock b{};
  switch (method) {
    case Method::kVolumetric: {
      const auto disk = poissonDisk(samples);
      for (int i = 0; i < samples; ++i) {
        const glm::vec2 p = disk[i];
        b.samples[i] = glm::vec4(p, std::sqrt(std::max(0.f, 1.f - glm::dot(p, p))), 0.f);
      }
      break;
    }
    case Method::kContainment: {
      const auto disk = poissonDisk(samples);
      // Distances xi_i = (k + 1/2) / n, shuffled against the directions (fixed seed).
      std::vector<int> order(static_cast<std::size_t>(samples));
      std::iota(order.begin(), order.end(), 0);
      Pcg32 rng(0xd157u);
      for (int i = samples - 1; i > 0; --i) std::swap(order[i], order[rng.next() % static_cast<std::uint32_t>(i + 1)]);
      for (int i = 0; i < samples; ++i) {
        const glm::vec2 p = disk[i];
        // Malley: a uniform point on the disk lifted to the hemisphere is cosine distributed.
        const glm::vec3 omega(p, std::sqrt(std::max(0.f, 1.f - glm::dot(p, p))));
        const float xi = (static_cast<float>(order[i]) + 0.5f) / static_cast<float>(samples);
        // r = mu^-1(xi): the step membership's derivative is a Dirac delta at R; (r/R)^3 inverts to
        // R xi^(1/3).
        const float rOverR = falloff == Falloff::kStep ? 1.f : std::cbrt(xi);
        b.samples[i] = glm::vec4(omega * rOverR, 0.f);
      }
      break;
    }
    case Method::kCrytek: {
      // Antithetic pairs (p, -p): the kernel is balanced between the two half-balls of any plane through
      // x, so its open-plane value is the definition's 1/2 and not a property of the particular kernel.
      const auto ball = poissonBall((samples + 1) / 2);
      for (int i = 0; i < samples; ++i) b.samples[i] = glm::vec4(i % 2 ? -ball[i / 2] : ball[i / 2], 0.f);
      break;
    }
    case Method::kGtao: break;
  }
  Pcg32 rng(0x0a7a7e5u);
  for (int j = 0; j < kPatternCells; ++j) {
    const float u = rng.uniform();
    const float jitter = rng.uniform();
    const float alpha = glm::two_pi<float>() * (static_cast<float>(kBayer4[j]) + u) / kPatternCells;
    // z: GTAO slice offset (rank + 1/2) / 16, so the 16 cells of a 4x4 block cover 16 evenly spaced
    // slice angles; w: jitter of GTAO's step positions.
    b.rotations[j] = glm::vec4(std::cos(alpha), std::sin(alpha), (static_cast<float>(kBayer4[j]) + 0.5f) / kPatternCells,
                               std::max(jitter, 1e-3f));
  }
  return b;
}

GtaoLayout gtaoLayout(int samples) {
  const int slices = std::max(1, static_cast<int>(std::sqrt(samples / 8.0)));
  const int steps = std::max(1, samples / (2 * slices));
  return {slices, steps};
}

}  // namespace ao

namespace {
const char* methodDefine(ao::Method m) {
  switch (m) {
    case ao::Method::kVolumetric: return "METHOD_VOLUMETRIC";
    case ao::Method::kContainment: return "METHOD_CONTAINMENT";
    case ao::Method::kCrytek: return "METHOD_CRYTEK";
    case ao::Method::kGtao: return "METHOD_GTAO";
  }
  return "METHOD_VOLUMETRIC";
}
}  // namespace

const TechniqueInfo& AmbientOcclusionPass::info() const {
  static const TechniqueInfo i = describedTechnique("ambient_occlusion");
  return i;
}

Requirements AmbientOcclusionPass::requirements(const Scene&, const api::RenderRequest& request) const {
  const bool ambient = request.ambient.x > 0.f || request.ambient.y > 0.f || request.ambient.z > 0.f ||
                       !request.environment.empty();  // an environment map's average is the ambient
  bool aovWanted = request.compare && request.compare->aov == "ao";
  for (const auto& o : request.outputs)
    aovWanted = aovWanted || std::find(o.aovs.begin(), o.aovs.end(), "ao") != o.aovs.end();
  const bool named = request.passes.count(info().name) != 0;
  if (ambient || aovWanted || named) return Requirements::ok();
  return Requirements::skip("no ambient lighting (ambient or environment) and the ao AOV was not requested");
}

void AmbientOcclusionPass::prepare(const Scene&, const Params& params, FrameResources& res) {
  const AmbientOcclusionParams p = AmbientOcclusionParams::from(params);
  method_ = p.method;
  falloff_ = p.falloff;
  samples_ = p.samples;  // at most ao::kMaxSamples: the schema's maximum (Params.ASchemasRangeIsWhatItsPassCanHold)
  radius_ = static_cast<float>(p.radius);
  interleave_ = p.interleave;
  blur_ = p.blur;
  scale_ = p.resolution_scale == AmbientOcclusionParams::ResolutionScale::kHalf ? 2 : 1;

  // The kernel depends on the method, the falloff and the sample count only: a radius sweep reuses it.
  const std::string digest = std::string(AmbientOcclusionParams::toString(method_)) + "/" + AmbientOcclusionParams::toString(falloff_) +
                             "/" + std::to_string(samples_);
  block_ = &res.cached<ao::SampleBlock>("ambient_occlusion:kernel", digest, [&] {
    return std::make_unique<ao::SampleBlock>(ao::buildSampleBlock(method_, falloff_, samples_));
  });

  const int w = res.view().width, h = res.view().height;
  const int ww = std::max(1, (w + scale_ - 1) / scale_), wh = std::max(1, (h + scale_ - 1) / scale_);
  gl::Texture& raw = res.texture("ao_raw", GL_TEXTURE_2D, GL_R32F, ww, wh);
  raw.setFilter(GL_NEAREST, GL_NEAREST);
  gl::Framebuffer& estimate = res.framebuffer("ao_estimate");
  estimate.attach(GL_COLOR_ATTACHMENT0, raw);
  estimate.setDrawBuffers({GL_COLOR_ATTACHMENT0});
  estimate.checkComplete("AmbientOcclusionPass::prepare (estimate)");

  gl::Texture& out = res.texture("ao");
  out.setFilter(GL_NEAREST, GL_NEAREST);
  // Declared outputs and beauty: allocated by the Renderer (renderer/frame/FrameAllocation.h).
  gl::Framebuffer& resolve = res.framebuffer("ao_resolve");
  resolve.attach(GL_COLOR_ATTACHMENT0, out);
  attachBeauty(res, resolve, GL_COLOR_ATTACHMENT1);
  resolve.setDrawBuffers({GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1});
  resolve.checkComplete("AmbientOcclusionPass::prepare (resolve)");
  res.buffer("ao_samples", sizeof(ao::SampleBlock));
  ibl::prepare(res);  // the SH irradiance and the DFG table's diffuse Fresnel weight
}

void AmbientOcclusionPass::execute(PassContext& ctx) {
  FrameResources& res = ctx.resources;
  const FrameView& view = ctx.view;
  const int w = view.width, h = view.height;
  gl::Texture& raw = res.texture("ao_raw");
  const int ww = raw.width(), wh = raw.height();

  gl::Buffer& ubo = res.buffer("ao_samples");
  ubo.upload(block_, sizeof(ao::SampleBlock));
  ubo.bindBase(GL_UNIFORM_BUFFER, 0);

  const glm::mat3 rot(view.camera.world);
  const glm::vec3 right = glm::normalize(rot[0]), up = glm::normalize(rot[1]), forward = -glm::normalize(rot[2]);
  const ao::GtaoLayout layout = ao::gtaoLayout(samples_);

  glDisable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);

  // 1. Estimate at the working resolution.
  res.framebuffer("ao_estimate").bind();
  glViewport(0, 0, ww, wh);
  using gbuffer::Attachment;
  gbuffer::bind(res, {Attachment::Position, Attachment::Normal, Attachment::GeometricNormal});
  const gl::Program& est = ctx.shaders.program({"common/fullscreen.vert", "ambient_occlusion/ao.frag"},
                                               {{methodDefine(method_), "1"}, {"SAMPLES", std::to_string(samples_)}});
  est.use();
  est.set("u_radius", radius_);
  est.set("u_forward", &forward[0], 3);
  est.set("u_right", &right[0], 3);
  est.set("u_up", &up[0], 3);
  est.set("u_interleave", interleave_ ? 1 : 0);
  est.set("u_scale", scale_);
  const float fullSize[2] = {static_cast<float>(w), static_cast<float>(h)};
  est.set("u_fullSize", fullSize, 2);
  est.set("u_proj11", view.proj[1][1]);
  est.set("u_slices", layout.slices);
  est.set("u_steps", layout.steps);
  glDrawArrays(GL_TRIANGLES, 0, 3);

  // 2. Resolve at full resolution: depth-aware 4x4 filter (or depth-aware upsampling), write `ao` and
  //    add the ambient term to beauty.
  // The sky's direct light goes to beauty only when this pass owns it (photon_gi owns it when it runs:
  // its environment photons see the real visibility, AO only a neighbourhood of radius R).
  const bool addAmbient = res.owns("ambient_occlusion", api::kPathSkyDE) &&
                          (view.ambient.x > 0.f || view.ambient.y > 0.f || view.ambient.z > 0.f);
  gl::Framebuffer& resolve = res.framebuffer("ao_resolve");
  resolve.bind();
  glViewport(0, 0, w, h);
  BeautyWrite beauty = BeautyWrite::drawBuffer(res, 1, addAmbient);
  raw.bindUnit(0);
  // The resolve keeps unit 0 for the estimate: position .. material one unit up, the geometric normal at
  // 5 and the emission at its own unit (ao_resolve.frag).
  gbuffer::bindAt(res, Attachment::Position, 1);
  gbuffer::bindAt(res, Attachment::Normal, 2);
  gbuffer::bindAt(res, Attachment::Albedo, 3);
  gbuffer::bindAt(res, Attachment::Material, 4);
  gbuffer::bindAt(res, Attachment::GeometricNormal, 5);
  const gl::Program& rp = ctx.shaders.program({"common/fullscreen.vert", "ambient_occlusion/ao_resolve.frag"});
  rp.use();
  rp.set("u_scale", scale_);
  rp.set("u_blur", blur_ ? 1 : 0);
  rp.set("u_radius", radius_);
  gbuffer::bindAt(res, Attachment::Emission, gpu::kUnitAoEmission);
  // The layers attenuate the diffuse base (ao_resolve.frag); the sheen's table is an SSBO.
  gbuffer::bind(res, {Attachment::Layers, Attachment::Specular});
  ctx.gpu.sheenAlbedo.bindBase(GL_SHADER_STORAGE_BUFFER, gpu::kBindingSheenAlbedo);
  ibl::bind(res, rp, gpu::kUnitIblDfg, -1);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  beauty.commit();
  res.markWritten("ao");
  const double fetches = method_ == ao::Method::kGtao ? 2.0 * layout.slices * layout.steps : samples_;
  ctx.stats.counters["samples"] = samples_;
  ctx.stats.counters["depth_fetches_per_pixel"] = fetches;
  ctx.stats.counters["ao_pixels"] = static_cast<double>(ww) * wh;
  ctx.stats.counters["filter_taps"] = blur_ ? 16.0 : (scale_ == 2 ? 4.0 : 1.0);
}

GroundTruth AmbientOcclusionPass::groundTruth(const Params& params, const std::string& aov) const {
  const AmbientOcclusionParams p = AmbientOcclusionParams::from(params);
  if (aov != "ao") return GroundTruth::fromAovTable(aov);
  return {nlohmann::json{{"aov", "ao"},
                         {"ao_radius", p.radius},
                         {"ao_definition", p.method == ao::Method::kVolumetric ? "volumetric" : "cosine"}}};
}

}  // namespace radiant
