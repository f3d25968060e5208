#include "renderer/techniques/illumination_network/IlluminationNetwork.h"
#include "params/illumination_network_params.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>

#include "renderer/frame/PassContext.h"
#include "renderer/raytracing/ParticleMedium.h"
#include "renderer/shading/MediaLayer.h"
#include "renderer/shading/GBufferInputs.h"

namespace radiant {

namespace {
constexpr int kMaxLights = 8;
constexpr std::size_t kMaxLinks = std::size_t(1) << 20;  // N x D: 16 MiB per radiance buffer
constexpr std::size_t kMaxBins = std::size_t(1) << 22;   // D x M^2: 16 MiB per bin table (three of them)
constexpr std::size_t kSkyExactBudget = 8192;            // particles x D per march step for sky_single_scatter auto
// particles x D per march step that sky_single_scatter exact may ask for (422 beyond): the one product of
// request values in the march's work that no server cap bounds (every other term of a piece is linear
// in nodes or particles, and the pieces are march_steps, all capped: network::marchPieceLoops).
constexpr std::size_t kSkyExactMax = 65536;
}  // namespace

struct IlluminationNetworkPass::Network {
  std::unique_ptr<rt::ParticleMedium> medium;  // for the exact light transmittance
  network::NodeSet nodes;
  std::vector<network::Direction> dirs;
  std::unique_ptr<network::NetworkGpu> gpu;
  double occupancy = 0.0, contraction = 0.0, splatRadius = 0.0;
  int longestChain = 0;
  // The GPU radiance: `stateIterations` iterations of eq. 9.1 from 0 under the sources `stateKey` (the
  // lights, their transmittance, the sky, the link source), or nothing usable (stateIterations < 0).
  // A request resumes only from a state it would itself pass through (the same sources, no more
  // iterations than it asks for), so its frame is bitwise the cold frame whatever came before.
  std::string stateKey;
  int stateIterations = -1;
  std::vector<double> residuals;  // ||I^{n+1} - I^n|| of iterations 1..stateIterations
};

namespace {

// Everything the iteration's result depends on beyond the cached network: the directional lights
// (direction and irradiance, exactly), how they reach the nodes, the sky and the link source.
std::string sourcesKey(const std::vector<network::DirectionalLight>& lights, bool networkTransmittance,
                       glm::vec3 sky, bool linearSource) {
  std::string key;
  char buf[64];
  auto put = [&](float v) {
    std::snprintf(buf, sizeof buf, "%a,", double(v));
    key += buf;
  };
  for (const auto& l : lights) {
    put(l.w.x), put(l.w.y), put(l.w.z);
    put(l.irradiance.x), put(l.irradiance.y), put(l.irradiance.z);
    key += ';';
  }
  put(sky.x), put(sky.y), put(sky.z);
  key += networkTransmittance ? "network" : "exact";
  key += linearSource ? "|linear" : "|upstream";
  return key;
}

}  // namespace

const TechniqueInfo& IlluminationNetworkPass::info() const {
  static const TechniqueInfo i = describedTechnique("illumination_network");
  return i;
}

GroundTruth IlluminationNetworkPass::groundTruth(const Params&, const std::string& aov) const {
  if (aov != "media" && aov != "media_transmittance") return {};
  return {nlohmann::json{{"aov", aov}, {"media_mode", "full"}}};
}

Requirements IlluminationNetworkPass::requirements(const Scene& scene, const api::RenderRequest& request) const {
  return mediaRequirements(scene, request);
}

int IlluminationNetworkPass::autoWindow(int nodes) {
  return std::max(1, static_cast<int>(std::lround(std::cbrt(4.0 * nodes / 3.14159265358979))));
}

void IlluminationNetworkPass::validate(const Scene&, const FrameView& view, const Params& params) const {
  const IlluminationNetworkParams p = IlluminationNetworkParams::from(params);
  const int N = p.nodes, D = p.directions;
  int M = p.window;
  if (M == 0) M = autoWindow(N);
  if (std::size_t(N) * std::size_t(D) > kMaxLinks)
    throw api::ApiError(422, "invalid-value", "Network too large",
                        "nodes x directions = " + std::to_string(std::size_t(N) * D) + " exceeds " +
                            std::to_string(kMaxLinks) + " links",
                        "/passes/illumination_network/nodes");
  if (std::size_t(D) * std::size_t(M) * std::size_t(M) > kMaxBins)
    throw api::ApiError(422, "invalid-value", "Network window too large",
                        "directions x window^2 = " + std::to_string(std::size_t(D) * M * M) + " exceeds " +
                            std::to_string(kMaxBins) + " bins",
                        "/passes/illumination_network/window");
  // The sky scattered once exactly costs D x particles chords per step of the march: the one product in
  // the march's work that no server cap bounds. "exact" above kSkyExactMax is refused ("auto" leaves it
  // to the network beyond kSkyExactBudget: prepare()).
  using Sky = IlluminationNetworkParams::SkySingleScatter;
  if (p.final_render == IlluminationNetworkParams::FinalRender::kMarch && p.sky_single_scatter == Sky::kExact) {
    const std::size_t chords = mediaParticleCount(view.media) * std::size_t(D);
    if (chords > kSkyExactMax)
      throw api::ApiError(422, "invalid-value", "Exact sky single scattering too costly",
                          "sky_single_scatter exact sums particles x directions = " + std::to_string(chords) +
                              " chords per step of the march, above " + std::to_string(kSkyExactMax) +
                              " (use auto or network, or fewer directions)",
                          "/passes/illumination_network/sky_single_scatter");
  }
}

void IlluminationNetworkPass::prepare(const Scene& scene, const Params& params, FrameResources& res) {
  const IlluminationNetworkParams p = IlluminationNetworkParams::from(params);
  const FrameView& view = res.view();
  const int N = p.nodes, D = p.directions;
  int M = p.window;
  if (M == 0) M = autoWindow(N);  // validate() has bounded N x D and D x M^2
  const auto seed = static_cast<std::uint64_t>(p.seed);
  const bool fibonacci = p.sampling == IlluminationNetworkParams::Sampling::kFibonacci;
  const float splatScale = static_cast<float>(p.splat_radius);
  march_ = p.final_render == IlluminationNetworkParams::FinalRender::kMarch;
  marchFallback_ = false;
  marchSteps_ = p.march_steps;
  const float kernelScale = static_cast<float>(p.march_kernel);
  const std::string digest = view.mediaKey + "|" + std::to_string(N) + "|" + std::to_string(D) + "|" +
                             std::to_string(M) + "|" + cacheKey(p.seed, p.sampling, p.link_opacity);
  fresh_ = false;
  net_ = &res.cached<Network>("illumination_network", digest, [&] {
    auto n = std::make_unique<Network>();
    n->medium = std::make_unique<rt::ParticleMedium>(view.media);
    n->nodes = network::sampleNodes(*n->medium, N, seed);
    n->dirs = network::makeDirections(D, fibonacci, seed);
    const auto W = network::phaseWeights(n->dirs, n->nodes.phase, n->nodes.g);
    n->gpu = std::make_unique<network::NetworkGpu>(n->nodes, n->dirs, W, M, kMaxLights);
    fresh_ = true;
    return n;
  });
  iterations_ = p.iterations;
  linearSource_ = p.link_source == IlluminationNetworkParams::LinkSource::kLinear;
  exactLinks_ = p.link_opacity == IlluminationNetworkParams::LinkOpacity::kMedium;

  // Directional lights (the network's lights) and their transmittance to every node, recomputed per
  // frame since lights move: exact through the medium, or from the network's chains along each light.
  lights_.clear();
  ignoredLights_ = 0;
  for (const Light& l : scene.lights) {
    if (l.type != LightType::Directional || !(glm::length(l.direction) > 0.f) ||
        static_cast<int>(lights_.size()) == kMaxLights) {
      ++ignoredLights_;
      continue;
    }
    lights_.push_back({glm::normalize(l.direction), l.color * l.intensity});
  }
  const bool networkTransmittance = p.light_transmittance == IlluminationNetworkParams::LightTransmittance::kNetwork;
  transmittance_ = networkTransmittance ? network::lightTransmittance(net_->nodes, lights_, M)
                                       : network::lightTransmittance(net_->nodes, lights_, *net_->medium);
  // Warm start (a render service returns the same frame for the same request): resume only from a
  // state this request would itself pass through, i.e. iterated from 0 under the same sources for at
  // most `iterations` iterations, and run the rest. The result is then bitwise the cold start's (the
  // iteration is deterministic); moved lights or a changed sky start from 0.
  stateKey_ = sourcesKey(lights_, networkTransmittance, view.ambient, linearSource_);
  warm_ = p.warm_start && net_->stateIterations >= 0 && net_->stateKey == stateKey_ &&
          net_->stateIterations <= iterations_;
  resumedFrom_ = warm_ ? net_->stateIterations : 0;

  // Splats: each node a linear-falloff sphere carrying mass / N of the optical mass, of radius
  // splat_radius times the mean node spacing (V / N)^(1/3), V = mass / (mean node extinction).
  const auto& nodes = net_->nodes.nodes;
  double meanTau = 0.0;
  for (const auto& n : nodes) meanTau += n.tau / double(nodes.size());
  const double volume = meanTau > 0.0 ? net_->nodes.mass / meanTau : 0.0;
  const double r = splatScale * std::cbrt(volume / double(std::max<std::size_t>(1, nodes.size())));
  const double m = net_->nodes.mass / double(std::max<std::size_t>(1, nodes.size()));
  const float tauSplat = r > 0.0 ? static_cast<float>(3.0 * m / (3.14159265358979 * r * r * r)) : 0.f;
  net_->splatRadius = r;
  kernel_ = kernelScale * static_cast<float>(r / splatScale);
  const glm::vec3 forward = viewForward(view);
  const bool ortho = view.camera.projection == ProjectionType::Orthographic;
  std::vector<float> key(nodes.size());
  for (std::size_t p = 0; p < nodes.size(); ++p)
    key[p] = ortho ? glm::dot(nodes[p].position - view.eye, forward) : glm::length(nodes[p].position - view.eye);
  order_.resize(nodes.size());
  std::iota(order_.begin(), order_.end(), 0);
  std::stable_sort(order_.begin(), order_.end(), [&](int a, int b) { return key[std::size_t(a)] > key[std::size_t(b)]; });
  splats_.resize(nodes.size());
  for (std::size_t s = 0; s < nodes.size(); ++s)
    splats_[s] = {glm::vec4(nodes[std::size_t(order_[s])].position, static_cast<float>(r)), glm::vec4(0.f, 0.f, 0.f, tauSplat),
                  glm::vec4(0.f), glm::ivec4(gpu::kProfileLinearExact, gpu::kPhaseIsotropic, 0, 0)};

  // The march reads the medium's own particles (exact extinction along the view ray and to the lights).
  particles_.clear();
  if (march_) particles_ = mediaParticles(view.media, glm::vec3(0.f), view.eye, forward, ortho, /*sort=*/false);
  // The sky scattered once exactly costs D x particles chords per step of the march: "auto" affords it
  // up to kSkyExactBudget of them (a few big particles, the thesis' homogeneous cloud) and leaves it to
  // the network beyond.
  // validate() refused "exact" above kSkyExactMax.
  using Sky = IlluminationNetworkParams::SkySingleScatter;
  const Sky sky = p.sky_single_scatter;
  skyExact_ = march_ && (sky == Sky::kExact || (sky == Sky::kAuto && particles_.size() * std::size_t(D) <= kSkyExactBudget));
  // The driver's loop budget per invocation and draw (network::shaderLoopBudget), read once per context.
  if (loopBudget_ == 0) {
    const auto* name = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    loopBudget_ = network::shaderLoopBudget(name ? name : "");
  }
  piecesLoops_ = 0;
  if (march_) {
    // Loop iterations of one march.frag invocation: the particles met by the ray once, then per piece
    // network::marchPieceLoops. A draw marches as many pieces as the budget allows (or march_stretch);
    // when one piece alone exceeds it (llvmpipe: e.g. > 30000 particles), the splats stand in.
    const long long P = static_cast<long long>(particles_.size()), L = static_cast<long long>(lights_.size());
    piecesLoops_ = network::marchPieceLoops(P, N, L, D, skyExact_);
    const int asked = p.march_stretch;
    marchStretch_ = static_cast<int>(std::min<long long>(marchSteps_, (loopBudget_ - P - 64) / piecesLoops_));
    if (asked > 0) marchStretch_ = std::min(marchStretch_, asked);
    if (marchStretch_ < 1) march_ = false, skyExact_ = false, marchFallback_ = true;  // too big for one piece
  }

  if (vao_.id() == 0) vao_ = gl::VertexArray("illumination_network");
  declareMediaLayer(res, view.width, view.height);
  res.buffer("network_particles", std::max<std::size_t>(1, particles_.size()) * sizeof(gpu::MediaParticle));
  res.buffer("network_splats", std::max<std::size_t>(1, splats_.size()) * sizeof(gpu::MediaParticle));
  res.buffer("network_order", std::max<std::size_t>(1, order_.size()) * sizeof(int));
}

void IlluminationNetworkPass::execute(PassContext& ctx) {
  FrameResources& res = ctx.resources;
  const FrameView& view = ctx.view;
  network::NetworkGpu& gpu = *net_->gpu;
  const bool build = !gpu.visibilityBuilt();
  if (build) {
    gpu.buildVisibility(ctx.shaders, ctx.cancel);
    // Link statistics, once per network.
    network::Visibility V = gpu.downloadVisibility();
    if (exactLinks_) {
      V.alpha = network::exactLinkOpacity(net_->nodes, net_->dirs, V, *net_->medium);
      gpu.uploadAlpha(V.alpha);
    }
    net_->occupancy = V.occupancy();
    net_->longestChain = V.longestChain();
    double q = 0.0;
    for (int p = 0; p < V.nodes; ++p)
      for (int i = 0; i < V.directions; ++i) {
        const std::size_t at = std::size_t(p) * V.directions + i;
        const int up = V.upstream[at];
        const glm::vec3 a = net_->nodes.nodes[std::size_t(up >= 0 ? up : p)].albedo;
        q = std::max(q, 1.0 - double(V.alpha[at]) * (1.0 - double(std::max(a.x, std::max(a.y, a.z)))));
      }
    net_->contraction = q;
    gpu.setSkyTransmittance(network::skyTransmittance(V));
  }
  gpu.setLights(lights_, transmittance_);
  if (!warm_) {
    gpu.clearRadiance();
    net_->residuals.clear();
  }
  net_->residuals.resize(std::size_t(resumedFrom_));
  net_->stateKey = stateKey_;
  const std::vector<double> run =
      gpu.iterate(ctx.shaders, iterations_ - resumedFrom_, view.ambient, linearSource_,
                  [&ctx] { return ctx.cancel.requested(); });
  iterationsRun_ = static_cast<int>(run.size());
  // A cancelled request still leaves a valid state: its first resumedFrom_ + run.size() iterations.
  net_->residuals.insert(net_->residuals.end(), run.begin(), run.end());
  net_->stateIterations = static_cast<int>(net_->residuals.size());
  const std::vector<double>& residuals = net_->residuals;  // iterations 1..iterations_, whatever the start
  if (static_cast<int>(residuals.size()) < iterations_)
    throw api::ApiError(409, "canceled", "Render canceled",
                        "the render was cancelled during illumination_network's iteration " +
                            std::to_string(residuals.size() + 1) + " of " + std::to_string(iterations_));

  gl::Buffer& splats = res.buffer("network_splats");
  gl::Buffer& order = res.buffer("network_order");
  if (!splats_.empty()) {
    splats.upload(splats_.data(), splats_.size() * sizeof(gpu::MediaParticle));
    order.upload(order_.data(), order_.size() * sizeof(int));
  }
  const glm::vec3 toCamera = glm::normalize(glm::vec3(view.camera.world[2]));
  gpu.cameraSources(ctx.shaders, order, splats, view.camera.projection == ProjectionType::Orthographic, view.eye,
                    toCamera, /*includeLights=*/!march_, /*excludeSky=*/skyExact_, view.ambient);

  const bool hasDepth = gbuffer::written(res, gbuffer::Attachment::Position);
  vao_.bind();
  beginMediaLayer(res.framebuffer("media"), view.width, view.height);
  if (hasDepth) gbuffer::bind(res, {gbuffer::Attachment::Position});
  if (march_) {
    // The view ray marched through the medium's exact extinction, the lights scattered once exactly,
    // the network's J_ms interpolated from the nodes (march.frag).
    gl::Buffer& particles = res.buffer("network_particles");
    if (!particles_.empty()) particles.upload(particles_.data(), particles_.size() * sizeof(gpu::MediaParticle));
    const gl::Program& prog = ctx.shaders.program({"common/fullscreen.vert", "illumination_network/march.frag"});
    gpu.bindForRender(prog);
    setMediaCameraUniforms(prog, view, hasDepth, view.width, view.height);
    prog.set("u_particleCount", static_cast<int>(particles_.size()));
    prog.set("u_steps", marchSteps_);
    prog.set("u_kernel", kernel_);
    prog.set("u_skyExact", skyExact_ ? 1 : 0);
    prog.set("u_sky", &view.ambient.x, 3);
    particles.bindBase(GL_SHADER_STORAGE_BUFFER, gpu::kBindingMediaParticles);
    splats.bindBase(GL_SHADER_STORAGE_BUFFER, 15);
    // Stretches of marchStretch_ pieces, back to front (march.frag). Each is finished before the next
    // one starts when there is a next one, and a cancelled or timed-out request stops there: within one
    // stretch of GPU work (the iteration's poll is every kCancelPollIterations iterations).
    const int stretches = (marchSteps_ + marchStretch_ - 1) / marchStretch_;
    int drawn = 0;
    ctx.progress(0.5);
    for (int end = marchSteps_; end > 0 && !particles_.empty() && !splats_.empty(); end -= marchStretch_) {
      if (drawn > 0) {
        glFinish();
        ctx.progress(0.5 + 0.5 * drawn / stretches);
        if (ctx.cancel.requested()) {
          glDisable(GL_BLEND);
          throw api::ApiError(409, "canceled", "Render canceled",
                              "the render was cancelled during illumination_network's march after stretch " +
                                  std::to_string(drawn) + " of " + std::to_string(stretches));
        }
      }
      prog.set("u_stepBegin", std::max(0, end - marchStretch_));
      prog.set("u_stepEnd", end);
      glDrawArrays(GL_TRIANGLES, 0, 3);
      ++drawn;
    }
    marchDraws_ = drawn;
    glDisable(GL_BLEND);
    res.markWritten("media");
    res.markWritten("media_transmittance");
    composeMediaIntoBeauty(ctx);
    reportStats(ctx, build, residuals);
    return;
  }

  // The splats as spherical billboards (exact chords, no lights: the source is the network's).
  splats.bindBase(GL_SHADER_STORAGE_BUFFER, gpu::kBindingMediaParticles);
  ctx.gpu.lights.bindBase(GL_SHADER_STORAGE_BUFFER, gpu::kBindingLights);
  const gl::Program& prog = ctx.shaders.program({"spherical_billboards/particle.vert", "spherical_billboards/particle.frag"});
  prog.use();
  setMediaCameraUniforms(prog, view, hasDepth, view.width, view.height);
  prog.set("u_method", 0);
  prog.set("u_chord", 0);
  prog.set("u_softScale", 1.f);
  prog.set("u_lightCount", 0);
  if (!splats_.empty()) glDrawArraysInstanced(GL_TRIANGLES, 0, 6, static_cast<GLsizei>(splats_.size()));
  glDisable(GL_BLEND);
  res.markWritten("media");
  res.markWritten("media_transmittance");

  // The planner runs this exclusive pass only when it owns the media light path.
  composeMediaIntoBeauty(ctx);
  reportStats(ctx, build, residuals);
}

void IlluminationNetworkPass::reportStats(PassContext& ctx, bool build, const std::vector<double>& residuals) const {
  const network::NetworkGpu& gpu = *net_->gpu;
  auto& c = ctx.stats.counters;
  c["nodes"] = gpu.nodes();
  c["directions"] = gpu.directions();
  c["window"] = gpu.window();
  c["link_occupancy"] = net_->occupancy;  // fraction of links that see the sky
  c["longest_chain"] = net_->longestChain;
  c["contraction_factor"] = net_->contraction;
  c["visibility_built"] = build ? 1 : 0;
  c["warm_start"] = warm_ ? 1 : 0;
  c["resumed_from_iteration"] = resumedFrom_;  // iterations taken from the cached state
  c["iterations_run"] = iterationsRun_;        // iterations run by this request
  c["iterations"] = iterations_;
  c["directional_lights"] = static_cast<double>(lights_.size());
  c["ignored_lights"] = ignoredLights_;
  c["splat_radius"] = net_->splatRadius;
  c["march_steps"] = march_ ? marchSteps_ : 0;  // 0: the splatted final render
  c["sky_single_scatter_exact"] = skyExact_ ? 1 : 0;
  c["march_stretch"] = march_ ? marchStretch_ : 0;  // pieces per draw (the driver's loop budget, or march_stretch)
  c["march_draws"] = march_ ? marchDraws_ : 0;      // stretches drawn (each a cancel point)
  c["march_piece_loops"] = static_cast<double>(piecesLoops_);  // loop iterations per piece and pixel
  c["loop_budget"] = static_cast<double>(loopBudget_);         // per invocation and draw (shaderLoopBudget)
  c["march_fallback"] = marchFallback_ ? 1 : 0;     // march asked for but too big for one piece: splatted
  for (std::size_t n = 0; n < residuals.size(); ++n) {
    char name[32];
    std::snprintf(name, sizeof name, "residual_%03zu", n + 1);
    c[name] = residuals[n];
  }
  if (!residuals.empty()) c["residual_last"] = residuals.back();
}

}  // namespace radiant
