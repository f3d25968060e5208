// GPU/CPU parity of the material model (issue #20): a compute shader (shaders/tests/parity.comp)
// evaluates the GLSL BRDF (common/brdf.glsl), the punctual-light falloff (common/lights.glsl) and the
// material decoder (common/material.glsl over common/material_decode.glsl) on ~10^4 random inputs each,
// and the results must equal what the ray-tracing core computes: rt::GltfBsdf::eval * |cos| (brdf.glsl
// itself compiled as C++, so the BSDF cases test the two compilers and the n = +z frame, not two
// copies), rt::punctualLi / rangeWindow / spotFalloff, and decodeMaterial / RayScene::shade (its BSDF
// and normal-mapped shading normal) / RayScene::emissionAt (material_decode.glsl compiled as C++: the
// material cases test the compilers and each language's texel fetch, the GPU's samplers against
// RayScene::textureAt). (That no two samplers of the frame's programs share a unit is render_test's
// RenderCore.SamplerUnitsAreUniqueAcrossEveryTechniquesPrograms.)
//
// The inputs go through the same code a render uses: scene Lights and Materials are uploaded by
// GpuScene (toGpuLight, toGpuMaterial, the sRGB/linear texture formats, the glTF samplers), and the
// CPU reads the same Scene through RayScene. Inputs deliberately include metals, transmission,
// roughness exactly 0 and 1, roughness below sqrt(kMinGgxAlpha) (the alpha clamp), grazing angles,
// textures on every slot with every wrap mode and both filters, both uv sets, and KHR_texture_transform
// rows on every slot of a third of the materials.
//
// Tolerances are float tolerances, not modelling slack: relative 1e-4 (BRDF; 2e-3 for the texel-
// exact material values) plus, for the BRDF, the change of the CPU value itself when wi moves by 1e-5
// rad or n.h by two float ulps (near the peak of an alpha = 1e-3 lobe the value is ill-conditioned in
// float: a one-ulp change of n.h changes D by per cents). Textures: linear texels at texel centres are
// exact; sRGB texels carry llvmpipe's approximate sRGB decode (2e-3); bilinear taps between texel
// centres get 1/128 of the value range (llvmpipe quantises filter weights to 8 bits).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "renderer/frame/GpuScene.h"
#include "renderer/frame/GpuTypes.h"
#include "renderer/gl/Gl.h"
#include "renderer/gl/ShaderLibrary.h"
#include "renderer/io/ImageIO.h"
#include "renderer/platform/EglDevice.h"
#include "renderer/raytracing/Bsdf.h"
#include "renderer/raytracing/Lights.h"
#include "renderer/raytracing/RayScene.h"
#include "renderer/scene/GltfExtensions.h"
#include "renderer/scene/MaterialDecode.h"

namespace radiant {
namespace {

using gl::Buffer;
using gl::Program;
using gl::ShaderLibrary;

constexpr GLuint kCasesBinding = 3, kResultsBinding = 4;

class ParityTest : public ::testing::Test {
protected:
  static void SetUpTestSuite() { device_ = EglDevice::create(); }
  static void TearDownTestSuite() { device_.reset(); }
  void SetUp() override { device_->makeCurrent(); }

  // Runs `file` with `defines` over `count` cases in one dispatch.
  template <class Case, class Result>
  std::vector<Result> run(const std::string& define, const std::vector<Case>& cases, std::size_t resultsPerCase,
                          const std::function<void(const Program&)>& bind = {}) {
    const Program& program = library_.program({"tests/parity.comp"}, {{define, ""}});
    Buffer in("parity cases", cases.size() * sizeof(Case), cases.data(), 0);
    Buffer out("parity results", cases.size() * resultsPerCase * sizeof(Result));
    in.bindBase(GL_SHADER_STORAGE_BUFFER, kCasesBinding);
    out.bindBase(GL_SHADER_STORAGE_BUFFER, kResultsBinding);
    program.use();
    program.set("u_count", static_cast<int>(cases.size()));
    if (bind) bind(program);
    glDispatchCompute(static_cast<GLuint>((cases.size() + 63) / 64), 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    gl::checkError(("parity.comp " + define).c_str());
    std::vector<Result> results(cases.size() * resultsPerCase);
    out.download(results.data(), results.size() * sizeof(Result));
    return results;
  }

  static std::unique_ptr<EglDevice> device_;
  ShaderLibrary library_;
};
std::unique_ptr<EglDevice> ParityTest::device_;

float uniform(std::mt19937& rng, float lo = 0.f, float hi = 1.f) {
  return std::uniform_real_distribution<float>(lo, hi)(rng);
}
glm::vec3 unitVector(std::mt19937& rng) {
  return rt::sampleUniformSphere({uniform(rng), uniform(rng)});
}
// Roughness with the values that matter drawn often: 0 (Dirac), 1, below sqrt(kMinGgxAlpha) (clamped
// alpha), and anything between.
float randomRoughness(std::mt19937& rng) {
  const float u = uniform(rng);
  if (u < 0.15f) return 0.f;
  if (u < 0.3f) return 1.f;
  if (u < 0.45f) return uniform(rng, 0.005f, 0.03f);  // roughness^2 < kMinGgxAlpha for < 0.0316
  return uniform(rng);
}
float zeroOneOrBetween(std::mt19937& rng) {
  const float u = uniform(rng);
  return u < 0.3f ? 0.f : u < 0.5f ? 1.f : uniform(rng);
}

// --------------------------------------------------------------------------------------------------
// BRDF: gltfBsdfCos(n, wo, wi, params, eta) == rt::GltfBsdf::eval(wo, wi) |wi.z| in the frame of n.

struct BrdfCase {
  glm::vec4 n, wo, wi;  // wi.w = eta
  gpu::MaterialParams p;
  glm::vec4 nc;  // the clear coat's normal (KHR_materials_clearcoat)
};
static_assert(sizeof(BrdfCase) == 160, "matches parity.comp's std430 BrdfCase");

rt::GltfBsdf cpuBsdf(const BrdfCase& c) {
  rt::GltfBsdf b;
  b.baseColor = glm::vec3(c.p.baseColor);
  b.metallic = c.p.surface.x;
  b.roughness = c.p.surface.y;
  b.transmission = c.p.surface.z;
  b.ior = c.p.surface.w;
  b.eta = c.wi.w;
  b.mode = rt::TransportMode::Radiance;
  b.clearcoat = c.p.clearcoat.x;
  b.clearcoatRoughness = c.p.clearcoat.y;
  b.sheenColor = glm::vec3(c.p.sheen);
  b.sheenRoughness = c.p.sheen.w;
  b.specularColor = glm::vec3(c.p.specular);
  b.specularWeight = c.p.specular.w;
  b.coatNormal = rt::ShadingFrame::fromNormal(glm::vec3(c.n)).toLocal(glm::vec3(c.nc));
  return b;
}
glm::vec3 cpuBrdfCos(const BrdfCase& c, const glm::vec3& wiWorld) {
  const rt::ShadingFrame f = rt::ShadingFrame::fromNormal(glm::vec3(c.n));
  const glm::vec3 wo = f.toLocal(glm::vec3(c.wo)), wi = f.toLocal(wiWorld);
  return cpuBsdf(c).eval(wo, wi) * std::abs(wi.z);
}

// Relative change of D when n.h moves by two float ulps below 1 (2.4e-7): how ill-conditioned the
// specular value is at this configuration in float arithmetic.
float ggxConditioning(const BrdfCase& c) {
  const rt::GltfBsdf b = cpuBsdf(c);
  const rt::ShadingFrame f = rt::ShadingFrame::fromNormal(glm::vec3(c.n));
  const glm::vec3 wo = f.toLocal(glm::vec3(c.wo)), wi = f.toLocal(glm::vec3(c.wi));
  glm::vec3 h = wi.z > 0.f ? wo + wi : b.eta * wi + wo;
  if (glm::dot(h, h) == 0.f) return 0.f;
  h = glm::normalize(h);
  float k = 0.f;
  if (!b.isDelta()) {  // a Dirac base has no peak to evaluate; a glossy coat over it still has one
    const float cosH = std::min(1.f, std::abs(h.z)), a = b.alpha();
    const float d = rt::ggxD(cosH, a);
    k = d > 0.f ? std::abs(rt::ggxD(cosH - 2.4e-7f, a) - d) / d : 0.f;
  }
  // The coat's lobe has its own peak (around the coat normal), conditioned the same way.
  if (b.hasCoat() && !b.coatIsDelta() && wi.z > 0.f) {
    const float cosC = std::min(1.f, std::abs(glm::dot(b.coatNormal, h)));
    const float ac = rt::alphaFromRoughness(b.clearcoatRoughness), dc = rt::ggxD(cosC, ac);
    if (dc > 0.f) k = std::max(k, std::abs(rt::ggxD(cosC - 2.4e-7f, ac) - dc) / dc);
  }
  return k;
}

// What the random BRDF inputs cover, counted.
struct BrdfCaseCounts {
  int roughness0 = 0, roughness1 = 0, clampedAlpha = 0, metals = 0, transmissive = 0, grazing = 0, below = 0,
      inside = 0, coated = 0, sheened = 0, tinted = 0;
};

std::vector<BrdfCase> randomBrdfCases(std::mt19937& rng, int count, BrdfCaseCounts& counts) {
  std::vector<BrdfCase> cases;
  auto& [roughness0, roughness1, clampedAlpha, metals, transmissive, grazing, below, inside, coated, sheened,
         tinted] = counts;
  for (int i = 0; i < count; ++i) {
    BrdfCase c{};
    const glm::vec3 n = unitVector(rng);
    const rt::ShadingFrame f = rt::ShadingFrame::fromNormal(n);
    // wo in n's hemisphere; a quarter of the cases at grazing angles (n.wo < 0.02).
    glm::vec3 woL = unitVector(rng);
    woL.z = std::abs(woL.z);
    if (uniform(rng) < 0.25f) {
      const float cz = uniform(rng, 1e-3f, 0.02f), phi = uniform(rng, 0.f, 2.f * rt::kPi);
      woL = glm::vec3(std::sqrt(1.f - cz * cz) * std::cos(phi), std::sqrt(1.f - cz * cz) * std::sin(phi), cz);
    }
    // wi anywhere (below the surface is transmission); some grazing, some near the mirror direction.
    glm::vec3 wiL = unitVector(rng);
    const float u = uniform(rng);
    if (u < 0.15f) wiL.z = std::copysign(uniform(rng, 1e-3f, 0.02f), wiL.z), wiL = glm::normalize(wiL);
    else if (u < 0.3f) wiL = glm::normalize(glm::vec3(-woL.x, -woL.y, woL.z) + 0.05f * unitVector(rng));
    if (woL.z < 0.02f || std::abs(wiL.z) < 0.02f) ++grazing;
    if (wiL.z < 0.f) ++below;
    c.n = glm::vec4(n, 0.f);
    c.wo = glm::vec4(glm::normalize(f.toWorld(woL)), 0.f);
    const float ior = uniform(rng) < 0.3f ? 1.5f : uniform(rng, 1.05f, 2.5f);
    const bool fromInside = uniform(rng) < 0.2f;
    inside += fromInside;
    c.wi = glm::vec4(glm::normalize(f.toWorld(wiL)), fromInside ? 1.f / ior : ior);
    const float metallic = zeroOneOrBetween(rng), roughness = randomRoughness(rng),
                transmission = zeroOneOrBetween(rng);
    c.p.baseColor = glm::vec4(uniform(rng), uniform(rng), uniform(rng), 1.f);
    c.p.emission = glm::vec4(0.f, 0.f, 0.f, 1.f);
    c.p.surface = glm::vec4(metallic, roughness, transmission, ior);
    // The layers: a third of the cases each without clear coat, sheen or specular tint; the coat's
    // normal tilted off n (a normal-mapped base under an unmapped coat) in half of the coated ones.
    c.p.clearcoat = uniform(rng) < 0.35f ? glm::vec4(0.f) : glm::vec4(zeroOneOrBetween(rng), randomRoughness(rng), 0.f, 0.f);
    c.p.sheen = uniform(rng) < 0.35f ? glm::vec4(0.f, 0.f, 0.f, gpu::kMinSheenRoughness)
                                     : glm::vec4(uniform(rng), uniform(rng), uniform(rng),
                                                 uniform(rng) < 0.2f ? gpu::kMinSheenRoughness
                                                                     : uniform(rng, gpu::kMinSheenRoughness, 1.f));
    c.p.specular = uniform(rng) < 0.35f ? glm::vec4(1.f)
                                        : glm::vec4(uniform(rng, 0.f, 2.f), uniform(rng, 0.f, 2.f),
                                                    uniform(rng, 0.f, 30.f), zeroOneOrBetween(rng));
    glm::vec3 nc = n;
    if (uniform(rng) < 0.5f) nc = glm::normalize(n + 0.3f * unitVector(rng));
    if (glm::dot(nc, glm::vec3(c.wo)) <= 0.01f) nc = n;
    c.nc = glm::vec4(nc, 0.f);
    coated += c.p.clearcoat.x > 0.f;
    sheened += c.p.sheen.r > 0.f;
    tinted += c.p.specular != glm::vec4(1.f);
    roughness0 += roughness == 0.f;
    roughness1 += roughness == 1.f;
    clampedAlpha += roughness > 0.f && roughness * roughness < gpu::kMinGgxAlpha;
    metals += metallic == 1.f;
    transmissive += transmission > 0.f;
    cases.push_back(c);
  }
  return cases;
}

TEST_F(ParityTest, BrdfMatchesCpuBsdfOnRandomInputs) {
  std::mt19937 rng(20);
  const int kCases = 12000;
  BrdfCaseCounts counts;
  const std::vector<BrdfCase> cases = randomBrdfCases(rng, kCases, counts);
  const auto& [roughness0, roughness1, clampedAlpha, metals, transmissive, grazing, below, inside, coated, sheened,
               tinted] = counts;
  // The inputs cover what the issue asks for, in numbers.
  EXPECT_GT(roughness0, 1000);
  EXPECT_GT(roughness1, 1000);
  EXPECT_GT(clampedAlpha, 1000);
  EXPECT_GT(metals, 1500);
  EXPECT_GT(transmissive, 5000);
  EXPECT_GT(grazing, 3000);
  EXPECT_GT(below, 4000);
  EXPECT_GT(inside, 1500);
  EXPECT_GT(coated, 4000);
  EXPECT_GT(sheened, 6000);
  EXPECT_GT(tinted, 6000);

  // The sheen's directional-albedo table, as GpuScene uploads it.
  const Buffer sheenTable("sheen albedo", sizeof(float) * gpu::kSheenAlbedoSize * gpu::kSheenAlbedoSize,
                          rt::sheenAlbedoTable(), 0);
  sheenTable.bindBase(GL_SHADER_STORAGE_BUFFER, gpu::kBindingSheenAlbedo);
  const std::vector<glm::vec4> gpu = run<BrdfCase, glm::vec4>("PARITY_BRDF", cases, 1);
  int failures = 0, nonzero = 0;
  float worst = 0.f;
  for (int i = 0; i < kCases; ++i) {
    const BrdfCase& c = cases[i];
    const glm::vec3 cpu = cpuBrdfCos(c, glm::vec3(c.wi));
    const glm::vec3 g(gpu[i]);
    // Conditioning: how much the CPU value itself moves when wi moves by ~1e-5 rad.
    const float conditioning = ggxConditioning(c);
    float wobble = 0.f;
    for (int k = 0; k < 2; ++k) {
      const glm::vec3 wi2 = glm::normalize(glm::vec3(c.wi) + 1e-5f * unitVector(rng));
      wobble = std::max(wobble, rt::maxComponent(glm::abs(cpuBrdfCos(c, wi2) - cpu)));
    }
    if (rt::maxComponent(cpu) > 0.f) ++nonzero;
    for (int ch = 0; ch < 3; ++ch) {
      const float tol = 1e-6f + (1e-4f + 2.f * conditioning) * std::abs(cpu[ch]) + 2.f * wobble;
      const float err = std::abs(g[ch] - cpu[ch]);
      if (!(err <= tol)) {
        if (++failures <= 10)
          ADD_FAILURE() << "case " << i << " channel " << ch << ": GPU " << g[ch] << " CPU " << cpu[ch]
                        << " (metallic " << c.p.surface.x << " roughness " << c.p.surface.y << " transmission "
                        << c.p.surface.z << " ior " << c.p.surface.w << " eta " << c.wi.w << " coat "
                        << c.p.clearcoat.x << "/" << c.p.clearcoat.y << " sheen " << c.p.sheen.r << "/"
                        << c.p.sheen.w << " specular " << c.p.specular.w << " n.wo "
                        << glm::dot(c.n, c.wo) << " n.wi " << glm::dot(c.n, c.wi) << ")";
      }
      if (cpu[ch] > 0.f) worst = std::max(worst, err / cpu[ch]);
    }
  }
  EXPECT_EQ(failures, 0);
  EXPECT_GT(nonzero, kCases / 2);  // most cases compare real values, not two zeros
  RecordProperty("worst_relative_error", std::to_string(worst));
}

// --------------------------------------------------------------------------------------------------
// Sampling: sampleMaterial(n, nc, wo, params, eta, importance, u) == rt::GltfBsdf::sample(wo, u) in the
// frame of n, for the same random numbers: the same lobe (flags, delta), direction, weight and pdf, in
// both transport modes.

struct SampleCase {
  BrdfCase c;       // c.wi is unused but for c.wi.w = eta
  glm::vec4 u;      // lobe, Fresnel, direction
  glm::vec4 mode;   // x = 1: importance
};
static_assert(sizeof(SampleCase) == 192, "matches parity.comp's std430 SampleCase");

TEST_F(ParityTest, SamplingMatchesCpuBsdfOnRandomInputs) {
  std::mt19937 rng(21);
  const int kCases = 12000;
  BrdfCaseCounts counts;
  std::vector<SampleCase> cases;
  for (const BrdfCase& c : randomBrdfCases(rng, kCases, counts))
    cases.push_back({c, glm::vec4(uniform(rng), uniform(rng), uniform(rng), uniform(rng)),
                     glm::vec4(uniform(rng) < 0.4f ? 1.f : 0.f, 0.f, 0.f, 0.f)});
  const Buffer sheenTable("sheen albedo", sizeof(float) * gpu::kSheenAlbedoSize * gpu::kSheenAlbedoSize,
                          rt::sheenAlbedoTable(), 0);
  sheenTable.bindBase(GL_SHADER_STORAGE_BUFFER, gpu::kBindingSheenAlbedo);
  const std::vector<glm::vec4> gpu = run<SampleCase, glm::vec4>("PARITY_SAMPLE", cases, 3);

  int failures = 0, compared = 0, atBoundary = 0, importance = 0;
  std::map<unsigned, int> byFlags;
  float worstDir = 0.f;
  auto fail = [&](int i, const std::string& what) {
    const SampleCase& s = cases[i];
    if (++failures <= 40)
      ADD_FAILURE() << "case " << i << ": " << what << " (metallic " << s.c.p.surface.x << " roughness "
                    << s.c.p.surface.y << " transmission " << s.c.p.surface.z << " eta " << s.c.wi.w << " coat "
                    << s.c.p.clearcoat.x << "/" << s.c.p.clearcoat.y << " sheen " << s.c.p.sheen.r << " u ("
                    << s.u.x << ", " << s.u.y << ", " << s.u.z << ", " << s.u.w << ") importance " << s.mode.x
                    << " n.wo " << glm::dot(s.c.n, s.c.wo) << ")";
  };
  for (int i = 0; i < kCases; ++i) {
    const SampleCase& sc = cases[i];
    const rt::ShadingFrame f = rt::ShadingFrame::fromNormal(glm::vec3(sc.c.n));
    rt::GltfBsdf b = cpuBsdf(sc.c);
    b.mode = sc.mode.x != 0.f ? rt::TransportMode::Importance : rt::TransportMode::Radiance;
    importance += sc.mode.x != 0.f;
    const glm::vec3 wo = f.toLocal(glm::vec3(sc.c.wo));
    // A lobe choice within float rounding of a boundary of the lobe CDF (or of the Fresnel split) may
    // go either way in the two languages: those cases are not compared (and counted).
    const auto lp = b.lobeProbabilities(wo);
    bool boundary = false;
    for (float edge : {lp.coat, lp.coat + lp.sheen, lp.coat + lp.sheen + lp.reflect,
                       lp.coat + lp.sheen + lp.reflect + lp.diffuse})
      boundary = boundary || std::abs(sc.u.x - edge) < 1e-4f;
    if (sc.u.x >= lp.coat + lp.sheen + lp.reflect + lp.diffuse) {
      const glm::vec3 h = b.isDelta() ? glm::vec3(0.f, 0.f, 1.f) : rt::sampleGgxVndf(wo, b.alpha(), {sc.u.z, sc.u.w});
      boundary = boundary || std::abs(sc.u.y - rt::fresnelDielectric(glm::dot(wo, h), b.eta)) < 1e-4f;
    }
    rt::GltfBsdf::Sample s;
    const bool ok = b.sample(wo, sc.u.x, sc.u.y, {sc.u.z, sc.u.w}, s);
    const glm::vec3 gWi(gpu[3 * i]), gWeight(gpu[3 * i + 1]);
    const float gPdf = gpu[3 * i].w;
    const unsigned gFlags = static_cast<unsigned>(gpu[3 * i + 1].w);
    const bool gValid = gpu[3 * i + 2].x != 0.f, gDelta = gpu[3 * i + 2].y != 0.f;
    if (boundary) {
      ++atBoundary;
      continue;
    }
    if (ok != gValid) {
      // A direction within rounding of the horizon is refused by one language only.
      const float z = ok ? s.wi.z : glm::dot(glm::vec3(sc.c.n), gWi);
      if (std::abs(z) < 1e-4f) continue;
      fail(i, std::string("valid: CPU ") + (ok ? "yes" : "no") + ", GPU " + (gValid ? "yes" : "no"));
      continue;
    }
    if (!ok) continue;
    ++compared;
    ++byFlags[s.flags];
    if (s.flags != gFlags || s.delta != gDelta) {
      fail(i, "lobe: CPU flags " + std::to_string(s.flags) + ", GPU " + std::to_string(gFlags));
      continue;
    }
    // Direction: float rounding of the VNDF and reflection/refraction formulas (unit vectors; 4e-6
    // measured on llvmpipe, 1e-4 leaves room for another CPU's transcendental functions).
    const glm::vec3 cWi = f.toWorld(s.wi);
    const float dirErr = rt::maxComponent(glm::abs(gWi - cWi));
    worstDir = std::max(worstDir, dirErr);
    if (!(dirErr <= 1e-4f)) {
      fail(i, "direction off by " + std::to_string(dirErr));
      continue;
    }
    // Weight and pdf: float tolerance (5e-4 relative: the weight is f / pdf, each within the BRDF
    // test's 1e-4, and the pdf sums up to five lobes) plus how much the CPU's own values move between
    // the two directions (ill-conditioned near an alpha = 1e-3 peak, as in the BRDF test), and the BRDF
    // test's conditioning term at the GPU's direction.
    glm::vec3 cWeightAtG = s.weight;
    float cPdfAtG = s.pdf, conditioning = 0.f;
    if (!s.delta) {
      const glm::vec3 wiG = f.toLocal(glm::normalize(gWi));
      cPdfAtG = b.pdf(wo, wiG);
      cWeightAtG = cPdfAtG > 0.f ? b.eval(wo, wiG) * std::abs(wiG.z) / cPdfAtG : glm::vec3(0.f);
      BrdfCase at = sc.c;
      at.wi = glm::vec4(glm::normalize(gWi), sc.c.wi.w);
      conditioning = ggxConditioning(at);
    }
    for (int ch = 0; ch < 3; ++ch) {
      const float tol = 1e-5f + (5e-4f + 4.f * conditioning) * std::abs(s.weight[ch]) +
                        2.f * std::abs(cWeightAtG[ch] - s.weight[ch]);
      if (!(std::abs(gWeight[ch] - s.weight[ch]) <= tol)) {
        fail(i, "weight channel " + std::to_string(ch) + ": GPU " + std::to_string(gWeight[ch]) + " CPU " +
                    std::to_string(s.weight[ch]));
        break;
      }
    }
    const float pdfTol = 1e-6f + (5e-4f + 4.f * conditioning) * s.pdf + 2.f * std::abs(cPdfAtG - s.pdf);
    if (!(std::abs(gPdf - s.pdf) <= pdfTol))
      fail(i, "pdf: GPU " + std::to_string(gPdf) + " CPU " + std::to_string(s.pdf));
  }
  EXPECT_EQ(failures, 0);
  // Every kind of lobe was sampled and compared, in both modes; the boundary skips are rare.
  using namespace rt;
  EXPECT_GT(byFlags[kLobeReflection | kLobeDiffuse], 500);
  EXPECT_GT(byFlags[kLobeReflection | kLobeGlossy], 1000);
  EXPECT_GT(byFlags[kLobeTransmission | kLobeGlossy], 300);
  EXPECT_GT(byFlags[kLobeReflection | kLobeSpecular], 500);
  EXPECT_GT(byFlags[kLobeTransmission | kLobeSpecular], 100);
  EXPECT_GT(importance, 4000);
  EXPECT_GT(compared, kCases * 3 / 4);
  EXPECT_LT(atBoundary, kCases / 100);
  RecordProperty("worst_direction_error", std::to_string(worstDir));
  RecordProperty("compared", std::to_string(compared));
  RecordProperty("at_boundary", std::to_string(atBoundary));
  for (const auto& [flags, n] : byFlags) RecordProperty("lobe_" + std::to_string(flags), std::to_string(n));
}

// --------------------------------------------------------------------------------------------------
// Punctual lights: sampleLight / rangeWindow / spotFalloff == rt::punctualLi / rangeWindow / spotFalloff.

TEST_F(ParityTest, LightFalloffMatchesCpuLightsOnRandomInputs) {
  std::mt19937 rng(2020);
  Scene scene;
  const int kLights = 64;
  int ranged = 0, spots = 0;
  for (int i = 0; i < kLights; ++i) {
    Light l;
    l.type = i % 4 == 0 ? LightType::Directional : i % 4 == 1 ? LightType::Point : LightType::Spot;
    l.color = glm::vec3(uniform(rng), uniform(rng), uniform(rng));
    l.intensity = uniform(rng, 0.1f, 100.f);
    l.range = uniform(rng) < 0.7f ? uniform(rng, 0.5f, 6.f) : 0.f;
    l.outerConeAngle = uniform(rng, 0.1f, 1.5707f);
    l.innerConeAngle = uniform(rng) < 0.2f ? 0.f : uniform(rng, 0.f, l.outerConeAngle);
    l.position = 3.f * unitVector(rng) * uniform(rng);
    l.direction = unitVector(rng);
    ranged += l.range > 0.f && l.type != LightType::Directional;
    spots += l.type == LightType::Spot;
    scene.lights.push_back(l);
  }
  EXPECT_GT(ranged, 20);
  EXPECT_GT(spots, 25);
  const GpuScene gpuScene(scene);

  const int kCases = 10000;
  std::vector<glm::vec4> cases;
  for (int i = 0; i < kCases; ++i) {
    const int li = i % kLights;
    const Light& l = scene.lights[li];
    glm::vec3 p = 4.f * unitVector(rng) * uniform(rng);
    // Half of the spot cases inside the cone, around the falloff band.
    if (l.type == LightType::Spot && uniform(rng) < 0.5f) {
      const float c = uniform(rng, std::cos(l.outerConeAngle) - 0.05f, std::min(1.f, std::cos(l.innerConeAngle) + 0.05f));
      const rt::ShadingFrame f = rt::ShadingFrame::fromNormal(glm::normalize(l.direction));
      const float phi = uniform(rng, 0.f, 2.f * rt::kPi), s = std::sqrt(std::max(0.f, 1.f - c * c));
      p = l.position + uniform(rng, 0.2f, l.range > 0.f ? 1.2f * l.range : 5.f) *
                           f.toWorld(glm::vec3(s * std::cos(phi), s * std::sin(phi), std::min(c, 1.f)));
    }
    cases.push_back(glm::vec4(p, static_cast<float>(li)));
  }
  gpuScene.lights.bindBase(GL_SHADER_STORAGE_BUFFER, GpuScene::kLightBinding);
  const std::vector<glm::vec4> gpu = run<glm::vec4, glm::vec4>("PARITY_LIGHT", cases, 3);

  int failures = 0, windowed = 0, inFalloffBand = 0;
  auto expectNear = [&](int i, const char* what, float g, float c, float relTol) {
    if (std::abs(g - c) <= 1e-6f + relTol * std::abs(c)) return;
    if (++failures <= 10) ADD_FAILURE() << "case " << i << " " << what << ": GPU " << g << " CPU " << c;
  };
  for (int i = 0; i < kCases; ++i) {
    const Light& l = scene.lights[static_cast<int>(cases[i].w)];
    glm::vec3 wi, Li;
    float dist = 0.f;
    rt::punctualLi(l, glm::vec3(cases[i]), wi, dist, Li);
    const glm::vec4 gI = gpu[3 * i], gWi = gpu[3 * i + 1], gF = gpu[3 * i + 2];
    // The spot falloff t^2, t = (cd - cos_outer) / (cos_inner - cos_outer), amplifies the float error of
    // cd (~2.4e-7) by 2 / (t (cos_inner - cos_outer)) relative: that is its conditioning, not a drift.
    float spotConditioning = 0.f;
    if (l.type == LightType::Spot) {
      const float scale = 1.f / std::max(0.001f, std::cos(l.innerConeAngle) - std::cos(l.outerConeAngle));
      const float t = std::sqrt(rt::spotFalloff(l, glm::dot(glm::normalize(l.direction), -wi)));
      spotConditioning = t > 0.f ? 2.f * scale * 2.4e-7f / t : 0.f;
    }
    for (int ch = 0; ch < 3; ++ch) expectNear(i, "intensity", gI[ch], Li[ch], 1e-4f + 2.f * spotConditioning);
    for (int ch = 0; ch < 3; ++ch) expectNear(i, "wi", gWi[ch], wi[ch], 1e-5f);
    if (l.type == LightType::Directional) continue;
    expectNear(i, "distance", gI.w, dist, 1e-5f);
    const float window = rt::rangeWindow(dist, l.range);
    expectNear(i, "rangeWindow", gF.x, window, 1e-4f);
    windowed += window > 0.f && window < 1.f;
    if (l.type == LightType::Spot) {
      const float falloff = rt::spotFalloff(l, glm::dot(glm::normalize(l.direction), -wi));
      expectNear(i, "spotFalloff", gF.y, falloff, 1e-4f + 2.f * spotConditioning);
      inFalloffBand += falloff > 0.f && falloff < 1.f;
    }
  }
  EXPECT_EQ(failures, 0);
  EXPECT_GT(windowed, 1000);      // the range window is tested where it is neither 0 nor 1
  EXPECT_GT(inFalloffBand, 500);  // and the spot cone between its angles
}

// --------------------------------------------------------------------------------------------------
// Material decoding: GLSL decodeMaterial == C++ decodeMaterial == RayScene::shade / emissionAt.

Texture randomTexture(std::mt19937& rng, int index) {
  Texture t;
  t.name = "random" + std::to_string(index);
  t.width = 8;
  t.height = 4 + 4 * (index % 2);
  t.rgba8.resize(static_cast<std::size_t>(t.width) * t.height * 4);
  for (auto& b : t.rgba8) b = static_cast<std::uint8_t>(std::uniform_int_distribution<int>(0, 255)(rng));
  const int wraps[] = {10497, 33071, 33648};  // REPEAT, CLAMP_TO_EDGE, MIRRORED_REPEAT
  t.wrapS = wraps[index % 3];
  t.wrapT = wraps[(index / 3) % 3];
  t.magFilter = index % 2 == 0 ? 9728 : 9729;  // NEAREST, LINEAR
  return t;
}

TEST_F(ParityTest, MaterialDecodingMatchesCpuOnRandomInputs) {
  std::mt19937 rng(202020);
  Scene scene;
  const int kTextures = 18, kNormalTextures = 4, kMaterials = 32, kPerMaterial = 320;
  for (int i = 0; i < kTextures; ++i) scene.textures.push_back(randomTexture(rng, i));
  // Normal maps as they are: tangent-space z >= 0.25 (blue >= 160), so the mapped normal stays on the
  // surface's side and neither decoder falls back to the geometric normal.
  for (int i = 0; i < kNormalTextures; ++i) {
    Texture t = randomTexture(rng, i);
    for (std::size_t p = 2; p < t.rgba8.size(); p += 4) t.rgba8[p] = static_cast<std::uint8_t>(160 + t.rgba8[p] % 96);
    scene.textures.push_back(t);
  }
  auto maybeTexture = [&](float p) {
    TextureRef r;
    if (uniform(rng) < p) {
      r.texture = std::uniform_int_distribution<int>(0, kTextures - 1)(rng);
      r.texCoord = uniform(rng) < 0.3f ? 1 : 0;
    }
    return r;
  };
  int textured = 0, layerTextured = 0, transformedSlots = 0;
  std::vector<int> transformedMaterials;
  for (int i = 0; i < kMaterials; ++i) {
    Material m;
    m.name = "random" + std::to_string(i);
    m.baseColorFactor = glm::vec4(uniform(rng), uniform(rng), uniform(rng), uniform(rng));
    if (i % 5 == 0) m.baseColorFactor = glm::vec4(1.3f, 0.5f, 1.1f, 1.f);  // out of range: the decoders clamp
    m.metallicFactor = zeroOneOrBetween(rng);
    m.roughnessFactor = randomRoughness(rng);
    m.transmissionFactor = zeroOneOrBetween(rng);
    m.ior = i % 7 == 0 ? 0.f : uniform(rng, 1.f, 2.5f);  // 0: the decoders fall back to kDefaultIor
    m.emissiveFactor = glm::vec3(uniform(rng), uniform(rng), uniform(rng));
    m.emissiveStrength = uniform(rng, 1.f, 5.f);
    // The layers' factors, out of range in some materials (the decoders clamp).
    m.clearcoatFactor = zeroOneOrBetween(rng);
    m.clearcoatRoughnessFactor = i % 6 == 1 ? 1.4f : randomRoughness(rng);
    m.sheenColorFactor = glm::vec3(uniform(rng), uniform(rng), i % 6 == 2 ? 1.7f : uniform(rng));
    m.sheenRoughnessFactor = i % 4 == 3 ? 0.f : uniform(rng);  // 0: the decoders clamp to kMinSheenRoughness
    m.specularFactor = zeroOneOrBetween(rng);
    m.specularColorFactor = glm::vec3(uniform(rng, 0.f, 3.f), uniform(rng), i % 6 == 4 ? -1.f : uniform(rng));
    m.baseColorTexture = maybeTexture(0.7f);
    m.metallicRoughnessTexture = maybeTexture(0.7f);
    m.occlusionTexture = maybeTexture(0.6f);
    m.occlusionTexture.scale = uniform(rng);
    m.emissiveTexture = maybeTexture(0.6f);
    m.transmissionTexture = maybeTexture(0.6f);
    // The layered extensions' textures (KHR_materials_clearcoat, _sheen, _specular).
    m.clearcoatTexture = maybeTexture(0.5f);
    m.clearcoatRoughnessTexture = maybeTexture(0.5f);
    m.sheenColorTexture = maybeTexture(0.5f);
    m.sheenRoughnessTexture = maybeTexture(0.5f);
    m.specularTexture = maybeTexture(0.5f);
    m.specularColorTexture = maybeTexture(0.5f);
    auto normalMap = [&](TextureRef& r) {
      r.texture = kTextures + std::uniform_int_distribution<int>(0, kNormalTextures - 1)(rng);
      r.texCoord = uniform(rng) < 0.3f ? 1 : 0;
      r.scale = uniform(rng, 0.5f, 1.5f);
    };
    if (uniform(rng) < 0.7f) normalMap(m.normalTexture);
    if (uniform(rng) < 0.5f) normalMap(m.clearcoatNormalTexture);
    m.doubleSided = true;
    for (const TextureRef* r : materialTextureSlots(m)) textured += r->valid();
    for (const TextureRef* r : {&m.clearcoatTexture, &m.clearcoatRoughnessTexture, &m.clearcoatNormalTexture,
                                &m.sheenColorTexture, &m.sheenRoughnessTexture, &m.specularTexture,
                                &m.specularColorTexture})
      layerTextured += r->valid();
    // KHR_texture_transform on every slot of a third of the materials, with the loader's own rows
    // (gltf::textureTransformRows). The transforms map the 8x8 grid of texel centres onto itself (odd
    // integer scales, mirrors, quarter turns, offsets in eighths), so texel-centre points stay exact.
    if (i % 3 == 0) {
      struct Transform { glm::vec2 offset; float rotation; glm::vec2 scale; };
      const Transform transforms[] = {{{0.375f, -1.25f}, 0.f, {1.f, 1.f}},
                                      {{0.125f, 0.5f}, 0.5f * rt::kPi, {3.f, -1.f}},
                                      {{-0.5f, 0.25f}, rt::kPi, {-1.f, 3.f}},
                                      {{0.125f, 0.f}, -0.5f * rt::kPi, {1.f, 5.f}}};
      int k = i / 3;
      for (const TextureRef* slot : materialTextureSlots(m)) {
        TextureRef* r = const_cast<TextureRef*>(slot);  // m is this loop's own, mutable Material
        const Transform& t = transforms[k++ % 4];
        gltf::textureTransformRows(t.offset, t.rotation, t.scale, r->uvRow0, r->uvRow1);
        // Exact rows: float cos(pi/2) is -4.4e-8, which would move a texel-centre lookup by ~2e-6 of a
        // texel, beyond the texel-centre tolerance (the rows are multiples of 1/8 in exact arithmetic).
        r->uvRow0 = glm::round(r->uvRow0 * 8.f) / 8.f;
        r->uvRow1 = glm::round(r->uvRow1 * 8.f) / 8.f;
        transformedSlots += r->valid();
      }
      transformedMaterials.push_back(i);
    }
    scene.materials.push_back(m);
    // One triangle per material whose barycentrics map to uv0 = (-1,-1) + 4 (b1, b2) and uv1 =
    // (-1,-1) + 4 (b2, b1), so uvs in [-1, 1]^2 exercise the wrap modes.
    MeshInstance mesh;
    mesh.name = m.name;
    mesh.material = i;
    mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    // A constant shading normal tilted off the geometric one, and a random tangent frame.
    const glm::vec3 n = glm::normalize(glm::vec3(uniform(rng, -0.3f, 0.3f), uniform(rng, -0.3f, 0.3f), 1.f));
    const glm::vec4 tangent(unitVector(rng), uniform(rng) < 0.5f ? -1.f : 1.f);
    mesh.normals = {n, n, n};
    mesh.tangents = {tangent, tangent, tangent};
    mesh.uv0 = {{-1, -1}, {3, -1}, {-1, 3}};
    mesh.uv1 = {{-1, -1}, {-1, 3}, {3, -1}};
    mesh.indices = {0, 1, 2};
    for (const auto& p : mesh.positions) mesh.bounds.extend(p);
    scene.meshes.push_back(mesh);
  }
  EXPECT_GT(textured, 150);
  EXPECT_GT(layerTextured, 80);
  EXPECT_GT(transformedSlots, 25);
  scene.features = computeFeatures(scene);
  const rt::RayScene rays(scene);
  const GpuScene gpuScene(scene);

  // Points: half at texel centres of an 8x8 grid (exact for both filters), half anywhere.
  struct Point { glm::vec2 uv; bool centre; };
  std::vector<Point> points;
  std::vector<glm::vec4> cases;
  for (int i = 0; i < kMaterials * kPerMaterial; ++i) {
    glm::vec2 uv;
    const bool centre = i % 2 == 0;
    do {
      if (centre)
        uv = (glm::vec2(std::uniform_int_distribution<int>(-8, 7)(rng), std::uniform_int_distribution<int>(-8, 7)(rng)) +
              0.5f) / 8.f;
      else
        uv = glm::vec2(uniform(rng, -1.f, 1.f), uniform(rng, -1.f, 1.f));
    } while (uv.x + uv.y > 2.f);
    points.push_back({uv, centre});
    cases.push_back(glm::vec4(uv, uv.y, uv.x));
  }
  const Program* program = nullptr;
  std::vector<gpu::MaterialParams> gpu(cases.size());
  std::vector<glm::vec4> gpuNormals(cases.size()), gpuCoatNormals(cases.size());
  {
    program = &library_.program({"tests/parity.comp"}, {{"PARITY_MATERIAL", ""}});
    Buffer in("parity cases", cases.size() * sizeof(glm::vec4), cases.data(), 0);
    Buffer out("parity results", cases.size() * sizeof(gpu::MaterialParams));
    Buffer normals("parity normals", cases.size() * sizeof(glm::vec4));
    Buffer coatNormals("parity coat normals", cases.size() * sizeof(glm::vec4));
    in.bindBase(GL_SHADER_STORAGE_BUFFER, kCasesBinding);
    out.bindBase(GL_SHADER_STORAGE_BUFFER, kResultsBinding);
    normals.bindBase(GL_SHADER_STORAGE_BUFFER, kResultsBinding + 1);
    coatNormals.bindBase(GL_SHADER_STORAGE_BUFFER, kResultsBinding + 2);
    gpuScene.materials.bindBase(GL_SHADER_STORAGE_BUFFER, GpuScene::kMaterialBinding);
    program->use();
    for (int mi = 0; mi < kMaterials; ++mi) {
      gpuScene.bindMaterialTextures(static_cast<std::size_t>(mi));
      program->set("u_material", gpuScene.meshes[mi].material);
      program->set("u_first", mi * kPerMaterial);
      program->set("u_count", kPerMaterial);
      program->set("u_normal", &scene.meshes[mi].normals[0].x, 3);
      program->set("u_tangent", &scene.meshes[mi].tangents[0].x, 4);
      program->set("u_front", mi % 2);  // odd materials are seen from the front, even ones from the back
      glDispatchCompute((kPerMaterial + 63) / 64, 1, 1);
    }
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    gl::checkError("parity.comp PARITY_MATERIAL");
    out.download(gpu.data(), gpu.size() * sizeof(gpu::MaterialParams));
    normals.download(gpuNormals.data(), gpuNormals.size() * sizeof(glm::vec4));
    coatNormals.download(gpuCoatNormals.data(), gpuCoatNormals.size() * sizeof(glm::vec4));
  }

  int failures = 0, checked = 0, normalsCompared = 0, mappedNormalsCompared = 0, mappedCoatNormalsCompared = 0,
      movedByTransform = 0,
      transformedCases = 0;
  struct Worst { int failures = 0; float relative = 0.f, absolute = 0.f; };
  std::map<std::string, Worst> byWhat;  // per quantity
  auto expectNear = [&](int i, const char* what, float g, float c, float tol) {
    ++checked;
    auto& w = byWhat[std::string(what) + (points[i].centre ? " centre" : " between")];
    w.relative = std::max(w.relative, std::abs(g - c) / std::max(std::abs(c), 1e-3f));
    w.absolute = std::max(w.absolute, std::abs(g - c));
    if (std::abs(g - c) <= tol) return;
    ++w.failures;
    if (++failures <= 10)
      ADD_FAILURE() << "case " << i << " (material " << i / kPerMaterial << ", uv " << points[i].uv.x << ","
                    << points[i].uv.y << (points[i].centre ? " texel centre" : "") << ") " << what << ": GPU " << g
                    << " CPU " << c;
  };
  // An sRGB value between texel centres: GL 4.5 (section 8.24) lets an implementation decode sRGB after
  // filtering ("inferior", but allowed), and NVIDIA's (H200, driver 580) does: up to 60% off the
  // decode-then-filter value at dark texels (the GPU check, 2026-12-04). Either order passes.
  auto expectNearEither = [&](int i, const char* what, float g, float c, float cAfter, float tol) {
    expectNear(i, what, g, std::abs(g - cAfter) < std::abs(g - c) ? cAfter : c, tol);
  };
  for (int i = 0; i < static_cast<int>(cases.size()); ++i) {
    const int mi = i / kPerMaterial;
    const Material& m = scene.materials[mi];
    const glm::vec2 uv = points[i].uv;
    const float b1 = (uv.x + 1.f) / 4.f, b2 = (uv.y + 1.f) / 4.f;
    const rt::SurfaceHit hit = rays.pointOn(mi, 0, glm::vec2(1.f - b1 - b2, b1));
    const gpu::MaterialParams cpu =
        decodeMaterial(m, [&](const TextureRef& ref, bool srgb) { return rays.textureAt(ref, hit, srgb); });
    // The same decode with sRGB texels filtered first and decoded after (texel centres: identical).
    const gpu::MaterialParams cpuAfter = decodeMaterial(m, [&](const TextureRef& ref, bool srgb) {
      glm::vec4 v = rays.textureAt(ref, hit, false);
      if (srgb)
        for (int ch = 0; ch < 3; ++ch) v[ch] = io::srgbToLinear(v[ch]);
      return v;
    });
    const gpu::MaterialParams& g = gpu[i];
    if (std::count(transformedMaterials.begin(), transformedMaterials.end(), mi)) {
      // The transform really moves the lookups: the same material with identity rows decodes to
      // something else at most points (so the GPU/CPU agreement below is not two decoders ignoring it).
      Material plain = m;
      for (const TextureRef* slot : materialTextureSlots(plain)) {
        TextureRef* r = const_cast<TextureRef*>(slot);
        r->uvRow0 = glm::vec3(1.f, 0.f, 0.f);
        r->uvRow1 = glm::vec3(0.f, 1.f, 0.f);
      }
      const gpu::MaterialParams untransformed =
          decodeMaterial(plain, [&](const TextureRef& ref, bool srgb) { return rays.textureAt(ref, hit, srgb); });
      const float moved = std::max({rt::maxComponent(glm::abs(glm::vec3(untransformed.baseColor - cpu.baseColor))),
                                    rt::maxComponent(glm::abs(glm::vec3(untransformed.emission - cpu.emission))),
                                    rt::maxComponent(glm::abs(glm::vec3(untransformed.surface - cpu.surface))),
                                    rt::maxComponent(glm::abs(glm::vec3(untransformed.clearcoat - cpu.clearcoat))),
                                    rt::maxComponent(glm::abs(glm::vec3(untransformed.sheen - cpu.sheen))),
                                    rt::maxComponent(glm::abs(glm::vec3(untransformed.specular - cpu.specular)))});
      ++transformedCases;
      movedByTransform += moved > 0.05f;
    }
    // Texel centres: linear texels are exact up to float rounding (measured 1.5e-7); sRGB texels
    // differ by the device's sRGB decode, which GL leaves to the implementation: llvmpipe's is off by up
    // to 1.55e-3 of 1, NVIDIA's (H200, driver 580, the GPU check of 2026-12-04) by up to 0.54% of the
    // value. Between centres the GPU's 8-bit filter weights allow 1/128 of each value's range.
    const bool centre = points[i].centre;
    const float linearTol = centre ? 1e-6f : 1.f / 128.f;
    // An sRGB value's tolerance: absolute (times the factor's scale) plus 0.6% of the value.
    auto srgbTol = [&](float c, float scale) { return ((centre ? 0.f : 1.f / 128.f) + 2e-3f) * scale + 6e-3f * std::abs(c); };
    const float emissionScale = std::max(1.f, rt::maxComponent(m.emission()));
    for (int ch = 0; ch < 4; ++ch) {
      if (ch < 3) {
        expectNearEither(i, "baseColor.rgb", g.baseColor[ch], cpu.baseColor[ch], cpuAfter.baseColor[ch],
                         srgbTol(cpu.baseColor[ch], 1.f));
        expectNearEither(i, "emission", g.emission[ch], cpu.emission[ch], cpuAfter.emission[ch],
                         srgbTol(cpu.emission[ch], emissionScale));
      } else {
        expectNear(i, "baseColor.a", g.baseColor[ch], cpu.baseColor[ch], linearTol);
        expectNear(i, "occlusion", g.emission[ch], cpu.emission[ch], linearTol);
      }
      expectNear(i, "surface", g.surface[ch], cpu.surface[ch], linearTol);
      // The layers: factor x texel, linear data (clear coat, coat roughness, sheen roughness, specular
      // weight) or sRGB colour (sheen and specular colour; the specular colour factor goes up to 3).
      expectNear(i, "clearcoat", g.clearcoat[ch], cpu.clearcoat[ch], linearTol);
      if (ch < 3) {
        expectNearEither(i, "sheen.rgb", g.sheen[ch], cpu.sheen[ch], cpuAfter.sheen[ch], srgbTol(cpu.sheen[ch], 1.f));
        expectNearEither(i, "specular.rgb", g.specular[ch], cpu.specular[ch], cpuAfter.specular[ch],
                         srgbTol(cpu.specular[ch], std::max(1.f, m.specularColorFactor[ch])));
      } else {
        expectNear(i, "sheen.a", g.sheen[ch], cpu.sheen[ch], linearTol);
        expectNear(i, "specular.a", g.specular[ch], cpu.specular[ch], linearTol);
      }
    }
    // The ray-tracing core's own reading of the material is the decoder's, and its normal-mapped
    // shading normal is GLSL's decodeShadingNormal (2 texel - 1, times a normal scale up to 1.5, then
    // normalised: four times the texel tolerance between texel centres).
    // Back faces (even materials) see the reversed frame. A mapped normal within 0.05 of wo's horizon
    // is left out: there each side has its own fallback by design (RayScene::shade takes the geometric
    // normal, the raster passes bend the normal towards wo per pixel).
    const glm::vec3 wo(0.f, 0.f, mi % 2 ? 1.f : -1.f);
    const rt::Shading sh = rays.shade(hit, wo);
    if (glm::dot(glm::vec3(gpuNormals[i]), wo) > 0.05f) {
      for (int ch = 0; ch < 3; ++ch)
        expectNear(i, m.normalTexture.valid() ? "normal (mapped)" : "normal", gpuNormals[i][ch], sh.frame.n[ch],
                   centre ? 1e-5f : 4.f / 128.f);
      ++normalsCompared;
      mappedNormalsCompared += m.normalTexture.valid();
    }
    // KHR_materials_clearcoat's normal: decodeCoatNormal == RayScene::shade's coat normal (its own map or
    // the interpolated normal), with the same horizon exclusion.
    const glm::vec3 coatWorld = sh.frame.toWorld(sh.bsdf.coatNormal);
    if (glm::dot(glm::vec3(gpuCoatNormals[i]), wo) > 0.05f) {
      for (int ch = 0; ch < 3; ++ch)
        expectNear(i, m.clearcoatNormalTexture.valid() ? "coat normal (mapped)" : "coat normal", gpuCoatNormals[i][ch],
                   coatWorld[ch], centre ? 1e-5f : 4.f / 128.f);
      mappedCoatNormalsCompared += m.clearcoatNormalTexture.valid();
    }
    expectNear(i, "shade.baseColor.r", sh.bsdf.baseColor.r, cpu.baseColor.r, 0.f);
    expectNear(i, "shade.metallic", sh.bsdf.metallic, cpu.surface.x, 0.f);
    expectNear(i, "shade.roughness", sh.bsdf.roughness, cpu.surface.y, 0.f);
    expectNear(i, "shade.transmission", sh.bsdf.transmission, cpu.surface.z, 0.f);
    expectNear(i, "shade.ior", sh.bsdf.ior, cpu.surface.w, 0.f);
    expectNear(i, "shade.clearcoat", sh.bsdf.clearcoat, cpu.clearcoat.x, 0.f);
    expectNear(i, "shade.clearcoatRoughness", sh.bsdf.clearcoatRoughness, cpu.clearcoat.y, 0.f);
    expectNear(i, "shade.sheen.b", sh.bsdf.sheenColor.b, cpu.sheen.b, 0.f);
    expectNear(i, "shade.sheenRoughness", sh.bsdf.sheenRoughness, cpu.sheen.a, 0.f);
    expectNear(i, "shade.specular.r", sh.bsdf.specularColor.r, cpu.specular.r, 0.f);
    expectNear(i, "shade.specularWeight", sh.bsdf.specularWeight, cpu.specular.a, 0.f);
    const glm::vec3 e = rays.emissionAt(hit, -wo);
    expectNear(i, "emissionAt.g", e.g, cpu.emission.g, 0.f);
  }
  for (const auto& [what, w] : byWhat)
    std::printf("%-28s failures %6d  worst error: relative %.3g absolute %.3g\n", what.c_str(), w.failures,
                w.relative, w.absolute);
  EXPECT_EQ(failures, 0) << "of " << checked << " comparisons";
  EXPECT_GT(normalsCompared, 9000);
  EXPECT_GT(mappedNormalsCompared, 5000);
  EXPECT_GT(mappedCoatNormalsCompared, 3000);
  EXPECT_GT(transformedCases, 3000);
  EXPECT_GT(movedByTransform, transformedCases / 2);
}

}  // namespace
}  // namespace radiant
