#include "renderer/techniques/photon_gi/Splatting.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <glm/gtc/type_ptr.hpp>

#include "renderer/frame/Beauty.h"
#include "renderer/frame/GpuTypes.h"
#include "renderer/raytracing/Bsdf.h"
#include "renderer/raytracing/PhotonTracer.h"
#include "renderer/shading/PhotonGrid.h"
#include "renderer/shading/Stretches.h"
#include "renderer/shading/GBufferInputs.h"

namespace radiant::photon_gi {
namespace {

// Bindings, the surface test, the renormalisation floor and the gather's slice length are shared with
// the readers of the published grid (renderer/shading/PhotonGrid.h).
constexpr GLuint kSplatBinding = kPhotonSplatBinding, kCellBinding = kPhotonCellBinding;
// gather.comp and fixup_list.comp: the fix-up list (binding 4 is free in photon_gi's shaders).
constexpr GLuint kFixupListBinding = 4;
constexpr int kMaxCellsPerAxis = 128;
constexpr int kSplatsPerStretch = 65536;  // splat quads drawn between two cancel checks
constexpr std::uint32_t kGatherSlice = kPhotonGatherSlice;
constexpr float kPlaneTolerance = kPhotonPlaneTolerance;
constexpr float kNormalCosine = kPhotonNormalCosine;
constexpr float kMinKernelMass = kPhotonMinKernelMass;

// A buffer's size for `bytes`: rounded up to an eighth of the power of two at or below it (at least 4 KiB),
// so at most 12.5% is unused. Powers of two left up to half of it unused, and llvmpipe writes every byte
// of a new buffer: the 4M-photon Cornell box's 325 MB of splats took a 512 MiB buffer, 187 MiB of its
// peak resident set (issue 30).
std::size_t capacity(std::size_t bytes) {
  const std::size_t granule = std::max<std::size_t>(4096, std::bit_floor(std::max<std::size_t>(bytes, 1)) / 8);
  return (std::max<std::size_t>(bytes, 1) + granule - 1) / granule * granule;
}

// Declares `name` with room for `bytes`: a larger buffer is kept, unless the grid is being replaced
// (its upload follows) and the buffer is over twice what it needs, so that one large photon set does
// not hold its buffer for every later scene.
void declareBuffer(FrameResources& res, const char* name, std::size_t bytes, bool replacing) {
  const bool have = res.hasBuffer(name);
  const std::size_t size = have ? res.buffer(name).size() : 0;
  if (!have || size < bytes || (replacing && size > 2 * capacity(bytes))) res.buffer(name, capacity(bytes));
}

}  // namespace

std::uint32_t splatDirectionBits(const glm::vec3& wi) { return rt::octEncode(wi, 15); }

glm::vec3 splatDirection(const GpuSplat& s) { return rt::octDecode(s.wiFlags & ((1u << 30) - 1u), 15); }

double meshArea(const MeshInstance& m) {
  double a = 0.0;
  for (std::size_t t = 0; t + 2 < m.indices.size(); t += 3) {
    const glm::vec3 &v0 = m.positions[m.indices[t]], &v1 = m.positions[m.indices[t + 1]],
                    &v2 = m.positions[m.indices[t + 2]];
    a += 0.5 * glm::length(glm::cross(v1 - v0, v2 - v0));
  }
  return a;
}

void appendCoveragePoints(const MeshInstance& m, std::size_t n, float h, std::vector<GpuSplat>& out) {
  std::vector<double> cdf{0.0};
  for (std::size_t t = 0; t + 2 < m.indices.size(); t += 3) {
    const glm::vec3 &v0 = m.positions[m.indices[t]], &v1 = m.positions[m.indices[t + 1]],
                    &v2 = m.positions[m.indices[t + 2]];
    cdf.push_back(cdf.back() + 0.5 * glm::length(glm::cross(v1 - v0, v2 - v0)));
  }
  if (n == 0 || !(cdf.back() > 0.0)) return;
  const float weight = static_cast<float>(cdf.back() / double(n));
  constexpr double g1 = 0.7548776662466927, g2 = 0.5698402909980532;  // R2: 1/phi2, 1/phi2^2
  for (std::size_t i = 0; i < n; ++i) {
    const double target = (i + 0.5) / double(n) * cdf.back();
    const std::size_t t = std::min<std::size_t>(
        static_cast<std::size_t>(std::upper_bound(cdf.begin(), cdf.end(), target) - cdf.begin()) - 1, cdf.size() - 2);
    if (!(cdf[t + 1] > cdf[t])) continue;
    const glm::vec2 u(static_cast<float>(std::fmod(0.5 + g1 * i, 1.0)), static_cast<float>(std::fmod(0.5 + g2 * i, 1.0)));
    const glm::vec2 b = rt::sampleUniformTriangle(u);
    const glm::vec3 &v0 = m.positions[m.indices[3 * t]], &v1 = m.positions[m.indices[3 * t + 1]],
                    &v2 = m.positions[m.indices[3 * t + 2]];
    const glm::vec3 p = b.x * v0 + b.y * v1 + (1.f - b.x - b.y) * v2;
    const glm::vec3 ng = glm::normalize(glm::cross(v1 - v0, v2 - v0));
    out.push_back({glm::vec4(p, h), ng, 0u, glm::vec4(0.f, 0.f, 0.f, weight)});
  }
}

SplatGrid buildSplatGrid(std::vector<GpuSplat> splats) {
  SplatGrid g;
  Bounds b;
  float hMax = 0.f;
  for (const GpuSplat& s : splats) {
    b.extend(glm::vec3(s.positionRadius));
    hMax = std::max(hMax, s.positionRadius.w);
    g.hMin = g.hMin > 0.f ? std::min(g.hMin, s.positionRadius.w) : s.positionRadius.w;
  }
  g.originals = splats.size();
  if (splats.empty()) {
    g.cellStart = {0, 0};
    return g;
  }
  const glm::vec3 extent = b.extent();
  const float longest = std::max({extent.x, extent.y, extent.z});
  // A splat reaches h sqrt(1 + tolerance^2) in 3-D: the surface test accepts in-plane distances below h
  // and plane distances below kPlaneTolerance h.
  const float reachScale = std::sqrt(1.f + kPlaneTolerance * kPlaneTolerance) * (1.f + 1e-5f);
  const float minCell = std::max(longest / kMaxCellsPerAxis, 1e-30f);
  // A splat whose reach spans m cells beyond its own (m = ceil(reach / cell)) is stored in its cell c
  // and, per axis, in c + 3k for |k| <= K = floor((m + 1) / 3): a point m or fewer cells away walks the
  // 3 x 3 x 3 cells around its own, and exactly one of them per axis is c + 3k (one of any three
  // consecutive cells is), so the walk meets the splat once, never twice. Copies carry kSplatCopy: the
  // splat method (one quad per splat) draws originals only.
  auto copiesPerAxis = [&](float h, float cell) {
    const int m = static_cast<int>(std::ceil(h * reachScale / cell));
    return 2 * ((std::max(m, 1) + 1) / 3) + 1;
  };
  // The cell: the reach of the largest kernel (every splat stored once) or of a percentile one, whichever
  // gives the least walk: a point's 27 cells hold about entries x (3 cell)^3 / volume candidates, so the
  // choice minimises entries x cell^3, with the copies at most 3 x the splats and 2^20 (64 MiB). Kernels
  // of very different sizes (photon_gi's kernel is per surface: a wide floor's beside small spheres')
  // made every pixel walk cells as wide as the widest.
  std::vector<float> radii;
  radii.reserve(splats.size());
  for (const GpuSplat& s : splats) radii.push_back(s.positionRadius.w);
  std::sort(radii.begin(), radii.end());
  g.cellSize = std::max(hMax * reachScale, minCell);
  double best = double(splats.size()) * std::pow(double(g.cellSize), 3.0);
  const std::size_t maxEntries = splats.size() + std::min<std::size_t>(3 * splats.size(), std::size_t(1) << 20);
  // With copies the grid is padded by 3 K cells on every side (K of the widest kernel), so that every
  // copy lies inside it: a copy dropped at the border was missed by the points next to it (a test's
  // find). A candidate that would need more than kMaxCellsPerAxis cells is not taken.
  auto padding = [&](float cell) { return 3 * ((copiesPerAxis(hMax, cell) - 1) / 2); };
  auto fits = [&](float cell) {
    return glm::all(glm::lessThanEqual(glm::ivec3(glm::floor(extent / cell)) + 1 + 2 * padding(cell),
                                       glm::ivec3(kMaxCellsPerAxis)));
  };
  for (double q : {0.25, 0.5, 0.75, 0.9, 0.97, 0.99}) {
    const float cell = std::max(radii[static_cast<std::size_t>(q * double(radii.size() - 1))] * reachScale, minCell);
    if (!(cell < g.cellSize) || !fits(cell)) continue;
    std::size_t entries = 0;
    for (float h : radii) {
      const std::size_t c = static_cast<std::size_t>(copiesPerAxis(h, cell));
      entries += c * c * c;
      if (entries > maxEntries) break;
    }
    const double walk = double(entries) * std::pow(double(cell), 3.0);
    if (entries <= maxEntries && walk < best) {
      best = walk;
      g.cellSize = cell;
    }
  }
  const int pad = g.cellSize < hMax * reachScale ? padding(g.cellSize) : 0;
  g.origin = b.min - glm::vec3(float(pad) * g.cellSize);
  g.dims = glm::clamp(glm::ivec3(glm::floor(extent / g.cellSize)) + 1 + 2 * pad, glm::ivec3(1),
                      glm::ivec3(kMaxCellsPerAxis));
  const std::size_t cells = static_cast<std::size_t>(g.dims.x) * g.dims.y * g.dims.z;
  auto cellOf = [&](const glm::ivec3& c) { return (static_cast<std::size_t>(c.z) * g.dims.y + c.y) * g.dims.x + c.x; };
  // Every entry (splat, cell): the originals, then their copies in cells inside the grid.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> entries;  // (splat index, cell), copies flagged below
  std::vector<std::uint8_t> isCopy;
  entries.reserve(splats.size());
  for (std::size_t i = 0; i < splats.size(); ++i) {
    const GpuSplat& s = splats[i];
    const glm::ivec3 c = glm::clamp(glm::ivec3(glm::floor((glm::vec3(s.positionRadius) - g.origin) / g.cellSize)),
                                    glm::ivec3(0), g.dims - 1);
    const int K = (copiesPerAxis(s.positionRadius.w, g.cellSize) - 1) / 2;
    for (int kz = -K; kz <= K; ++kz)
      for (int ky = -K; ky <= K; ++ky)
        for (int kx = -K; kx <= K; ++kx) {
          const glm::ivec3 q = c + 3 * glm::ivec3(kx, ky, kz);
          if (glm::any(glm::lessThan(q, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(q, g.dims))) continue;
          entries.emplace_back(static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(cellOf(q)));
          isCopy.push_back(kx != 0 || ky != 0 || kz != 0);
        }
  }
  // Counting sort by cell: O(N), stable (photon order is kept within a cell).
  g.cellStart.assign(cells + 1, 0);
  for (const auto& e : entries) ++g.cellStart[e.second + 1];
  for (std::size_t c = 0; c < cells; ++c) g.maxPerCell = std::max(g.maxPerCell, g.cellStart[c + 1]);
  for (std::size_t c = 0; c < cells; ++c) g.cellStart[c + 1] += g.cellStart[c];
  std::vector<std::uint32_t> next(g.cellStart.begin(), g.cellStart.end() - 1);
  g.splats.resize(entries.size());
  for (std::size_t e = 0; e < entries.size(); ++e) {
    GpuSplat& out = g.splats[next[entries[e].second]++];
    out = splats[entries[e].first];
    out.wiFlags = isCopy[e] ? (out.wiFlags | kSplatCopy) : (out.wiFlags & ~kSplatCopy);
  }
  g.count = g.splats.size();
  g.walkReach = 0.f;
  if (g.count != g.originals) {
    g.walkReach = std::numeric_limits<float>::infinity();
  } else {
    for (const GpuSplat& s : g.splats) {
      const glm::vec3 p(s.positionRadius);
      const glm::vec3 lo = g.origin + glm::vec3(glm::clamp(glm::ivec3(glm::floor((p - g.origin) / g.cellSize)),
                                                           glm::ivec3(0), g.dims - 1)) * g.cellSize;
      const glm::vec3 gap = glm::max(glm::max(lo - p, p - (lo + g.cellSize)), glm::vec3(0.f));
      g.walkReach = std::max(g.walkReach, glm::length(gap) + s.positionRadius.w * reachScale);
    }
  }
  return g;
}

void declareSplatResources(FrameResources& res, const SplatGrid& grid, const SplatSettings& settings,
                           bool replacing) {
  declareBuffer(res, "photon_gi_splats", std::max<std::size_t>(grid.count, 1) * sizeof(GpuSplat), replacing);
  declareBuffer(res, "photon_gi_cells", grid.cellStart.size() * sizeof(std::uint32_t), replacing);
  const int w = res.view().width, h = res.view().height;
  gl::Texture& accum = res.texture("photon_gi_accum", GL_TEXTURE_2D, GL_RGBA32F, w, h);
  accum.setFilter(GL_NEAREST, GL_NEAREST);
  if (settings.method == Method::Gather && settings.gatherStep > 1) {
    const int step = settings.gatherStep;
    res.texture("photon_gi_accum_low", GL_TEXTURE_2D, GL_RGBA32F, (w + step - 1) / step, (h + step - 1) / step)
        .setFilter(GL_NEAREST, GL_NEAREST);
    res.texture("photon_gi_fixup", GL_TEXTURE_2D, GL_R32F, w, h).setFilter(GL_NEAREST, GL_NEAREST);
    // The fix-up list (fixup_list.comp): a 16-byte header and one packed point per pixel at most.
    const std::size_t listBytes = 16 + 4 * static_cast<std::size_t>(w) * h;
    declareBuffer(res, "photon_gi_fixup_list", listBytes, true);  // rewritten every frame
    // The fix-up cascade's block samples (steps step / 2, step / 4, ... down to 2), one texture sized
    // for the finest of them.
    if (step >= 4)
      res.texture("photon_gi_accum_refine", GL_TEXTURE_2D, GL_RGBA32F, (w + 1) / 2, (h + 1) / 2)
          .setFilter(GL_NEAREST, GL_NEAREST);
  }
  gl::Framebuffer& splatFb = res.framebuffer("photon_gi_splat");
  splatFb.attach(GL_COLOR_ATTACHMENT0, accum);
  splatFb.setDrawBuffers({GL_COLOR_ATTACHMENT0});
  splatFb.checkComplete("photon_gi::declareSplatResources");
  gl::Texture& indirect = res.texture("indirect");
  indirect.setFilter(GL_NEAREST, GL_NEAREST);
  gl::Framebuffer& resolveFb = res.framebuffer("photon_gi_resolve");
  resolveFb.attach(GL_COLOR_ATTACHMENT0, indirect);
  attachBeauty(res, resolveFb, GL_COLOR_ATTACHMENT1);
  resolveFb.setDrawBuffers({GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1});
  resolveFb.checkComplete("photon_gi::declareSplatResources");
}

void uploadSplatGrid(FrameResources& res, const SplatGrid& grid) {
  if (grid.splats.size() != grid.count)
    throw std::logic_error("photon_gi::uploadSplatGrid: the grid's splats were released before upload");
  if (!grid.splats.empty())
    res.buffer("photon_gi_splats").upload(grid.splats.data(), grid.splats.size() * sizeof(GpuSplat));
  res.buffer("photon_gi_cells").upload(grid.cellStart.data(), grid.cellStart.size() * sizeof(std::uint32_t));
}

void splatAndResolve(FrameResources& res, gl::ShaderLibrary& shaders, const FrameView& view,
                     const SplatSettings& settings, const SplatGrid& grid, bool upload, bool addToBeauty) {
  gl::Buffer& splats = res.buffer("photon_gi_splats");
  gl::Buffer& cells = res.buffer("photon_gi_cells");
  if (upload) uploadSplatGrid(res, grid);
  // With the layers of the receiver's material (photon_gi/surface.glsl).
  using gbuffer::Attachment;
  gbuffer::bind(res, {Attachment::Position, Attachment::Normal, Attachment::Albedo, Attachment::Material,
                      Attachment::Emission, Attachment::GeometricNormal, Attachment::Layers, Attachment::Specular});
  splats.bindBase(GL_SHADER_STORAGE_BUFFER, kSplatBinding);
  cells.bindBase(GL_SHADER_STORAGE_BUFFER, kCellBinding);
  auto common = [&](const gl::Program& p) {
    p.use();
    p.set("u_kernel", static_cast<int>(settings.kernel));
    p.set("u_planeTolerance", kPlaneTolerance);
    p.set("u_normalCosine", kNormalCosine);
    p.set("u_minGlossyRoughness", settings.minGlossyRoughness);
  };
  gl::Texture& accum = res.texture("photon_gi_accum");
  const float zero[4] = {0.f, 0.f, 0.f, 0.f};
  const GLsizei count = static_cast<GLsizei>(grid.count);
  if (settings.method == Method::Splat) {
    gl::Framebuffer& fb = res.framebuffer("photon_gi_splat");
    fb.bind();
    glViewport(0, 0, view.width, view.height);
    glClearNamedFramebufferfv(fb.id(), GL_COLOR, 0, zero);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
    const gl::Program& prog = shaders.program({"photon_gi/splat.vert", "photon_gi/splat.frag"});
    common(prog);
    drawInstancedInStretches(prog, GL_TRIANGLE_STRIP, 4, count, kSplatsPerStretch, res.cancel(), "photon_gi's splatting");
    glDisable(GL_BLEND);
  } else {
    const gl::Program& prog = shaders.program({"photon_gi/gather.comp"});
    common(prog);
    prog.set("u_gridOrigin", glm::value_ptr(grid.origin), 3);
    prog.set("u_cellSize", grid.cellSize);
    prog.set("u_walkReach", std::min(grid.walkReach, 1e30f));
    const int dims[3] = {grid.dims.x, grid.dims.y, grid.dims.z};
    glUniform3iv(glGetUniformLocation(prog.id(), "u_gridDims"), 1, dims);
    const int size[2] = {view.width, view.height};
    glUniform2iv(glGetUniformLocation(prog.id(), "u_size"), 1, size);
    const std::uint32_t slices = std::max<std::uint32_t>(1, (grid.maxPerCell + kGatherSlice - 1) / kGatherSlice);
    // One gather over an output grid (full resolution or the block samples; fixup 0), or over the
    // fix-up list of its points that upsample.comp left without a value: fixup 1 the marked pixels (full
    // resolution), 2 the blocks whose centre pixel is marked (the cascade; the others get alpha -1, no
    // sample). The list is built on the GPU (fixup_list.comp) and gathered with an indirect dispatch of
    // as many workgroups as it has entries / 64.
    const gl::Program& listProg = shaders.program({"photon_gi/fixup_list.comp"});
    auto gather = [&](gl::Texture& target, int step, int outW, int outH, int fixup) {
      const int out[2] = {outW, outH};
      if (fixup) {
        gl::Buffer& list = res.buffer("photon_gi_fixup_list");
        const std::uint32_t header[4] = {0, 1, 1, 0};
        list.upload(header, sizeof header);
        list.bindBase(GL_SHADER_STORAGE_BUFFER, kFixupListBinding);
        listProg.use();
        glUniform2iv(glGetUniformLocation(listProg.id(), "u_size"), 1, size);
        glUniform2iv(glGetUniformLocation(listProg.id(), "u_outSize"), 1, out);
        listProg.set("u_step", step);
        res.texture("photon_gi_fixup").bindImage(1, GL_READ_ONLY);
        glDispatchCompute((outW + 7) / 8, (outH + 7) / 8, 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_COMMAND_BARRIER_BIT);
        glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, list.id());
        if (fixup == 2) {
          const float none[4] = {0.f, 0.f, 0.f, -1.f};
          glClearTexImage(target.id(), 0, GL_RGBA, GL_FLOAT, none);
        }
      }
      prog.use();
      glUniform2iv(glGetUniformLocation(prog.id(), "u_outSize"), 1, out);
      prog.set("u_step", step);
      prog.set("u_list", fixup ? 1 : 0);
      target.bindImage(0, GL_READ_WRITE);
      for (std::uint32_t k = 0; k < slices; ++k) {
        if (k > 0) res.cancel().check("photon_gi's gather");
        glUniform1ui(glGetUniformLocation(prog.id(), "u_sliceBegin"), k * kGatherSlice);
        glUniform1ui(glGetUniformLocation(prog.id(), "u_sliceLength"), kGatherSlice);
        prog.set("u_accumulate", k > 0 ? 1 : 0);
        if (fixup)
          glDispatchComputeIndirect(0);
        else
          glDispatchCompute((outW + 7) / 8, (outH + 7) / 8, 1);
        glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
      }
      if (fixup) glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, 0);
    };
    const int step = settings.gatherStep;
    if (step <= 1) {
      gather(accum, 1, view.width, view.height, 0);
    } else {
      gl::Texture& low = res.texture("photon_gi_accum_low");
      const int lowW = (view.width + step - 1) / step, lowH = (view.height + step - 1) / step;
      gather(low, step, lowW, lowH, 0);  // its image barrier orders upsample's imageLoad of the samples
      // Spreads the block samples of `samples` (one per `blockStep` x `blockStep` block) onto the pixels
      // of their surface; refine = 0 writes every pixel and marks the unmatched ones in photon_gi_fixup,
      // refine = 1 fills only marked pixels that this finer step matches and unmarks them; refine = 2 is
      // the neighbour fill below.
      const gl::Program& up = shaders.program({"photon_gi/upsample.comp"});
      auto upsample = [&](gl::Texture& samples, int blockStep, int refine) {
        common(up);
        glUniform2iv(glGetUniformLocation(up.id(), "u_size"), 1, size);
        const int lowSize[2] = {(view.width + blockStep - 1) / blockStep, (view.height + blockStep - 1) / blockStep};
        glUniform2iv(glGetUniformLocation(up.id(), "u_lowSize"), 1, lowSize);
        up.set("u_step", blockStep);
        up.set("u_hMin", grid.hMin);
        up.set("u_renormalize", settings.renormalize ? 1 : 0);
        up.set("u_minKernelMass", kMinKernelMass);
        up.set("u_refine", refine);
        up.set("u_fillRadius", std::max(2, step / 2));
        samples.bindImage(2, GL_READ_ONLY);
        accum.bindImage(0, refine ? GL_READ_WRITE : GL_WRITE_ONLY);
        res.texture("photon_gi_fixup").bindImage(1, refine ? GL_READ_WRITE : GL_WRITE_ONLY);
        glDispatchCompute((view.width + 7) / 8, (view.height + 7) / 8, 1);
        glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
      };
      upsample(low, step, 0);
      // The neighbour fill (upsample.comp, u_refine = 2): a marked pixel borrows from the pixels within
      // max(2, step / 2) that were matched on its own surface (the same test, within h_min), instead
      // of gathering. On a supersampled frame the marked pixels are mostly edge samples with such a
      // neighbour: cornell_glass at 128 px, k = 2, it fills 1533 of 1886 (the cascade and the full gather
      // then run on 353 and 174).
      upsample(low, step, 2);
      // The fix-up cascade: the marked pixels are edge pixels, k^2 times as many on a frame supersampled
      // k times (whose step is k gather_step), so before the full gather they try block samples of half
      // the step, taken only at marked block centres (about as many samples as at k = 1's step).
      for (int fine = step / 2; fine >= 2; fine /= 2) {
        gl::Texture& refine = res.texture("photon_gi_accum_refine");
        common(prog);
        gather(refine, fine, (view.width + fine - 1) / fine, (view.height + fine - 1) / fine, 2);
        upsample(refine, fine, 1);
      }
      common(prog);
      gather(accum, 1, view.width, view.height, 1);
    }
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_FRAMEBUFFER_BARRIER_BIT);
  }

  resolve(res, shaders, view, accum, settings.renormalize, addToBeauty);
}

void resolve(FrameResources& res, gl::ShaderLibrary& shaders, const FrameView& view, const gl::Texture& accum,
             bool renormalize, bool addToBeauty) {
  const float zero[4] = {0.f, 0.f, 0.f, 0.f};
  gl::Framebuffer& resolveFb = res.framebuffer("photon_gi_resolve");
  resolveFb.bind();
  glViewport(0, 0, view.width, view.height);
  glClearNamedFramebufferfv(resolveFb.id(), GL_COLOR, 0, zero);
  glDisable(GL_BLEND);  // the AOV is overwritten
  BeautyWrite beauty = BeautyWrite::drawBuffer(res, 1, addToBeauty);
  accum.bindUnit(0);
  const gl::Program& prog = shaders.program({"common/fullscreen.vert", "photon_gi/resolve.frag"});
  prog.use();
  prog.set("u_renormalize", renormalize ? 1 : 0);
  prog.set("u_minKernelMass", kMinKernelMass);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  beauty.commit();
  res.markWritten("indirect");
}

}  // namespace radiant::photon_gi
