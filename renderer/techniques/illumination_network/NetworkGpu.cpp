#include "renderer/techniques/illumination_network/NetworkGpu.h"

#include <algorithm>
#include <cstring>

#include "renderer/frame/GpuTypes.h"
#include "renderer/shading/Stretches.h"

namespace radiant::network {

namespace {

constexpr int kMaxIterationsPerBatch = 256;  // the residual buffer's length
constexpr int kVisibilityInvocationsPerStretch = 1 << 16;  // node-direction pairs per stretch of the build
constexpr int kCancelPollIterations = 4;     // how often iterate() asks whether the request was cancelled

int phaseCode(api::PhaseModel m) {
  return m == api::PhaseModel::HenyeyGreenstein ? gpu::kPhaseHenyeyGreenstein
         : m == api::PhaseModel::CornetteShanks ? gpu::kPhaseCornetteShanks
                                                : gpu::kPhaseIsotropic;
}

GLuint groups(int n) { return static_cast<GLuint>((n + 63) / 64); }

}  // namespace

NetworkGpu::NetworkGpu(const NodeSet& ns, const std::vector<Direction>& dirs, const std::vector<float>& weights,
                       int window, int maxLights)
    : N_(static_cast<int>(ns.nodes.size())),
      D_(static_cast<int>(dirs.size())),
      M_(window),
      maxLights_(std::max(1, maxLights)),
      center_(ns.center),
      radius_(ns.radius),
      phaseModel_(phaseCode(ns.phase)),
      g_(ns.g) {
  const std::size_t links = std::size_t(N_) * D_, bins = std::size_t(D_) * M_ * M_;
  std::vector<gpu::NetworkNode> nodes(static_cast<std::size_t>(N_));
  for (int p = 0; p < N_; ++p) {
    const Node& n = ns.nodes[std::size_t(p)];
    nodes[std::size_t(p)] = {glm::vec4(n.position, n.tau), glm::vec4(n.albedo, 0.f), glm::vec4(n.emission, 0.f)};
  }
  std::vector<gpu::NetworkDirection> d(dirs.size());
  for (std::size_t i = 0; i < dirs.size(); ++i)
    d[i] = {glm::vec4(dirs[i].w, 0.f), glm::vec4(dirs[i].u, 0.f), glm::vec4(dirs[i].v, 0.f)};
  nodes_ = gl::Buffer("network nodes", nodes.size() * sizeof(gpu::NetworkNode), nodes.data(), 0);
  dirs_ = gl::Buffer("network directions", d.size() * sizeof(gpu::NetworkDirection), d.data(), 0);
  weights_ = gl::Buffer("network phase weights", weights.size() * sizeof(float), weights.data(), 0);
  binCount_ = gl::Buffer("network bin counts", bins * sizeof(std::uint32_t));
  binStart_ = gl::Buffer("network bin starts", bins * sizeof(std::uint32_t));
  binFill_ = gl::Buffer("network bin fill", bins * sizeof(std::uint32_t));
  binItems_ = gl::Buffer("network bin items", links * sizeof(std::int32_t));
  nodeBin_ = gl::Buffer("network node bins", links * sizeof(std::int32_t));
  upstream_ = gl::Buffer("network upstream", links * sizeof(std::int32_t));
  alpha_ = gl::Buffer("network link opacity", links * sizeof(float));
  lightBuf_ = gl::Buffer("network lights", std::size_t(maxLights_) * sizeof(gpu::NetworkLight));
  transmittance_ = gl::Buffer("network light transmittance", std::size_t(N_) * maxLights_ * sizeof(float));
  residual_ = gl::Buffer("network residuals", kMaxIterationsPerBatch * sizeof(std::uint32_t));
  source_ = gl::Buffer("network sources", links * sizeof(glm::vec4));
  for (int k = 0; k < 2; ++k) radiance_[k] = gl::Buffer(k ? "network radiance B" : "network radiance A", links * sizeof(glm::vec4));
  clearRadiance();
}

void NetworkGpu::bindCommon(const gl::Program& p) const {
  p.use();
  p.set("u_nodes", N_);
  p.set("u_directions", D_);
  p.set("u_window", M_);
  p.set("u_center", &center_.x, 3);
  p.set("u_radius", radius_);
}

void NetworkGpu::uploadAlpha(const std::vector<float>& alpha) {
  alpha_.upload(alpha.data(), alpha.size() * sizeof(float));
}

void NetworkGpu::setSkyTransmittance(const std::vector<float>& T0) {
  skyTransmittance_ = gl::Buffer("network sky transmittance", T0.size() * sizeof(float), T0.data(), 0);
}

void NetworkGpu::bindForRender(const gl::Program& p) const {
  bindCommon(p);
  p.set("u_lightCount", lights_);
  p.set("u_phaseModel", phaseModel_);
  p.set("u_phaseG", g_);
  lightBuf_.bindBase(GL_SHADER_STORAGE_BUFFER, 12);
  dirs_.bindBase(GL_SHADER_STORAGE_BUFFER, 1);
}

void NetworkGpu::buildVisibility(gl::ShaderLibrary& shaders, const rt::Cancel& cancel) {
  const std::uint32_t zero = 0;
  glClearNamedBufferData(binCount_.id(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
  nodes_.bindBase(GL_SHADER_STORAGE_BUFFER, 0);
  dirs_.bindBase(GL_SHADER_STORAGE_BUFFER, 1);
  binCount_.bindBase(GL_SHADER_STORAGE_BUFFER, 2);
  binStart_.bindBase(GL_SHADER_STORAGE_BUFFER, 3);
  binFill_.bindBase(GL_SHADER_STORAGE_BUFFER, 4);
  binItems_.bindBase(GL_SHADER_STORAGE_BUFFER, 5);
  nodeBin_.bindBase(GL_SHADER_STORAGE_BUFFER, 6);
  upstream_.bindBase(GL_SHADER_STORAGE_BUFFER, 7);
  alpha_.bindBase(GL_SHADER_STORAGE_BUFFER, 8);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
  // Every step reads and writes one direction's data only, so the build runs in stretches of
  // directions, about kVisibilityInvocationsPerStretch node-direction pairs each, with a cancel check
  // between them (renderer/shading/Stretches.h; one dispatch over N x D ran 1.5 s on llvmpipe at
  // 8192 x 128, deaf to the flag). Only these four programs read u_directionFirst, and every stretch
  // sets it.
  const gl::Program* steps[4] = {&shaders.program({"illumination_network/bin_count.comp"}),
                                 &shaders.program({"illumination_network/bin_scan.comp"}),
                                 &shaders.program({"illumination_network/bin_scatter.comp"}),
                                 &shaders.program({"illumination_network/link.comp"})};
  const int perStretch = std::clamp(kVisibilityInvocationsPerStretch / std::max(N_, 1), 1, std::max(D_, 1));
  StretchGate gate(cancel);
  for (int first = 0; first < D_; first += perStretch) {
    if (first > 0) gate.check("illumination_network's visibility build");
    const GLuint count = static_cast<GLuint>(std::min(perStretch, D_ - first));
    for (int k = 0; k < 4; ++k) {
      bindCommon(*steps[k]);
      steps[k]->set("u_directionFirst", first);
      if (k == 1) glDispatchCompute(groups(static_cast<int>(count)), 1, 1);
      else glDispatchCompute(groups(N_), count, 1);
      glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    }
    if (first + perStretch < D_) gate.issued();
  }
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
  gl::checkError("NetworkGpu::buildVisibility()");
  built_ = true;
}

Visibility NetworkGpu::downloadVisibility() const {
  Visibility v;
  v.nodes = N_, v.directions = D_;
  v.upstream.resize(std::size_t(N_) * D_);
  v.alpha.resize(v.upstream.size());
  upstream_.download(v.upstream.data(), v.upstream.size() * sizeof(int));
  alpha_.download(v.alpha.data(), v.alpha.size() * sizeof(float));
  return v;
}

void NetworkGpu::setLights(const std::vector<DirectionalLight>& lights, const std::vector<double>& T) {
  lights_ = std::min<int>(static_cast<int>(lights.size()), maxLights_);
  std::vector<gpu::NetworkLight> l(static_cast<std::size_t>(maxLights_));
  std::vector<float> t(static_cast<std::size_t>(N_) * maxLights_, 1.f);
  for (int k = 0; k < lights_; ++k) {
    l[std::size_t(k)] = {glm::vec4(lights[std::size_t(k)].w, 0.f), glm::vec4(lights[std::size_t(k)].irradiance, 0.f)};
    for (int p = 0; p < N_; ++p)
      t[std::size_t(p) * lights_ + k] = static_cast<float>(T[std::size_t(p) * lights.size() + std::size_t(k)]);
  }
  lightBuf_.upload(l.data(), l.size() * sizeof(gpu::NetworkLight));
  transmittance_.upload(t.data(), t.size() * sizeof(float));
}

void NetworkGpu::clearRadiance() {
  const float zero[4] = {0.f, 0.f, 0.f, 0.f};
  for (auto& b : radiance_) glClearNamedBufferData(b.id(), GL_RGBA32F, GL_RGBA, GL_FLOAT, zero);
  current_ = 0;
}

std::vector<double> NetworkGpu::iterate(gl::ShaderLibrary& shaders, int count, glm::vec3 sky, bool linearSource,
                                        const std::function<bool()>& cancelled) {
  std::vector<double> out;
  const gl::Program& source = shaders.program({"illumination_network/source.comp"});
  bindCommon(source);
  source.set("u_lightCount", lights_);
  source.set("u_phaseModel", phaseModel_);
  source.set("u_phaseG", g_);
  const gl::Program& link = shaders.program({"illumination_network/iterate.comp"});
  bindCommon(link);
  link.set("u_sky", &sky.x, 3);
  link.set("u_linearSource", linearSource ? 1 : 0);
  nodes_.bindBase(GL_SHADER_STORAGE_BUFFER, 0);
  dirs_.bindBase(GL_SHADER_STORAGE_BUFFER, 1);
  upstream_.bindBase(GL_SHADER_STORAGE_BUFFER, 7);
  alpha_.bindBase(GL_SHADER_STORAGE_BUFFER, 8);
  weights_.bindBase(GL_SHADER_STORAGE_BUFFER, 9);
  lightBuf_.bindBase(GL_SHADER_STORAGE_BUFFER, 12);
  transmittance_.bindBase(GL_SHADER_STORAGE_BUFFER, 13);
  residual_.bindBase(GL_SHADER_STORAGE_BUFFER, 14);
  source_.bindBase(GL_SHADER_STORAGE_BUFFER, 18);
  bool stop = false;
  for (int done = 0; done < count && !stop;) {
    int batch = std::min(kMaxIterationsPerBatch, count - done);
    const std::uint32_t zero = 0;
    glClearNamedBufferData(residual_.id(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    for (int n = 0; n < batch; ++n) {
      // A cancelled or timed-out request stops within kCancelPollIterations iterations: the GPU is
      // drained first, so the check sees the time the queued iterations really took.
      if (cancelled && n % kCancelPollIterations == 0 && (glFinish(), cancelled())) {
        batch = n, stop = true;
        break;
      }
      radiance_[current_].bindBase(GL_SHADER_STORAGE_BUFFER, 10);
      radiance_[1 - current_].bindBase(GL_SHADER_STORAGE_BUFFER, 11);
      source.use();
      glDispatchCompute(groups(N_ * D_), 1, 1);
      glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
      link.use();
      link.set("u_iteration", n);
      glDispatchCompute(groups(N_ * D_), 1, 1);
      glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
      current_ = 1 - current_;
    }
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    std::vector<std::uint32_t> bits(static_cast<std::size_t>(batch));
    if (batch > 0) residual_.download(bits.data(), bits.size() * sizeof(std::uint32_t));
    for (std::uint32_t b : bits) {
      float f;
      std::memcpy(&f, &b, sizeof f);
      out.push_back(f);
    }
    done += batch;
  }
  gl::checkError("NetworkGpu::iterate()");
  return out;
}

std::vector<glm::dvec3> NetworkGpu::downloadRadiance() const {
  std::vector<glm::vec4> raw(std::size_t(N_) * D_);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  radiance_[current_].download(raw.data(), raw.size() * sizeof(glm::vec4));
  std::vector<glm::dvec3> out(raw.size());
  for (std::size_t k = 0; k < raw.size(); ++k) out[k] = glm::dvec3(glm::vec3(raw[k]));
  return out;
}

void NetworkGpu::uploadRadiance(const std::vector<glm::dvec3>& I) {
  std::vector<glm::vec4> raw(I.size());
  for (std::size_t k = 0; k < I.size(); ++k) raw[k] = glm::vec4(glm::vec3(I[k]), 0.f);
  radiance_[current_].upload(raw.data(), raw.size() * sizeof(glm::vec4));
}

void NetworkGpu::cameraSources(gl::ShaderLibrary& shaders, const gl::Buffer& order, gl::Buffer& splats,
                               bool orthographic, glm::vec3 eye, glm::vec3 toCamera, bool includeLights,
                               bool excludeSky, glm::vec3 sky) {
  const gl::Program& prog = shaders.program({"illumination_network/camera.comp"});
  bindCommon(prog);
  prog.set("u_lightCount", lights_);
  prog.set("u_includeLights", includeLights ? 1 : 0);
  prog.set("u_excludeSky", excludeSky && skyTransmittance_.id() != 0 ? 1 : 0);
  prog.set("u_sky", &sky.x, 3);
  if (skyTransmittance_.id() != 0) skyTransmittance_.bindBase(GL_SHADER_STORAGE_BUFFER, 17);
  prog.set("u_phaseModel", phaseModel_);
  prog.set("u_phaseG", g_);
  prog.set("u_orthographic", orthographic ? 1 : 0);
  prog.set("u_eye", &eye.x, 3);
  prog.set("u_toCamera", &toCamera.x, 3);
  nodes_.bindBase(GL_SHADER_STORAGE_BUFFER, 0);
  dirs_.bindBase(GL_SHADER_STORAGE_BUFFER, 1);
  radiance_[current_].bindBase(GL_SHADER_STORAGE_BUFFER, 10);
  lightBuf_.bindBase(GL_SHADER_STORAGE_BUFFER, 12);
  transmittance_.bindBase(GL_SHADER_STORAGE_BUFFER, 13);
  splats.bindBase(GL_SHADER_STORAGE_BUFFER, 15);
  order.bindBase(GL_SHADER_STORAGE_BUFFER, 16);
  glDispatchCompute(groups(N_), 1, 1);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
  gl::checkError("NetworkGpu::cameraSources()");
}

}  // namespace radiant::network
