#include "renderer/shading/ImageBasedLighting.h"

#include <algorithm>
#include <cmath>

#include "renderer/frame/FrameResources.h"
#include "renderer/frame/FrameView.h"
#include "renderer/gl/Gl.h"
#include "renderer/raytracing/Bsdf.h"
#include "renderer/scene/Environment.h"

namespace radiant::ibl {
namespace {

constexpr float kPi = 3.14159265358979323846f;
// The DFG table's own alpha floor for its roughness-0 row (the BSDF's is gpu::kMinGgxAlpha, 1e-3).
constexpr float kMinAlpha = 2e-3f;

glm::vec2 hammersley(std::uint32_t i, std::uint32_t n) {
  std::uint32_t b = i;
  b = (b << 16u) | (b >> 16u);
  b = ((b & 0x55555555u) << 1u) | ((b & 0xAAAAAAAAu) >> 1u);
  b = ((b & 0x33333333u) << 2u) | ((b & 0xCCCCCCCCu) >> 2u);
  b = ((b & 0x0F0F0F0Fu) << 4u) | ((b & 0xF0F0F0F0u) >> 4u);
  b = ((b & 0x00FF00FFu) << 8u) | ((b & 0xFF00FF00u) >> 8u);
  return {(float(i) + 0.5f) / float(n), float(b) * 2.3283064365386963e-10f};
}

// GGX half vector around +z: p(h) = D(h) (n.h) (Karis eq. "ImportanceSampleGGX").
glm::vec3 sampleGgx(glm::vec2 u, float alpha) {
  const float phi = 2.f * kPi * u.x;
  const float cosTheta = std::sqrt((1.f - u.y) / (1.f + (alpha * alpha - 1.f) * u.y));
  const float sinTheta = std::sqrt(std::max(0.f, 1.f - cosTheta * cosTheta));
  return {sinTheta * std::cos(phi), sinTheta * std::sin(phi), cosTheta};
}

float pow5(float x) { return x * x * x * x * x; }

void basis(const glm::vec3& n, glm::vec3& t, glm::vec3& b) {
  const glm::vec3 a = std::abs(n.z) < 0.999f ? glm::vec3(0, 0, 1) : glm::vec3(1, 0, 0);
  t = glm::normalize(glm::cross(a, n));
  b = glm::cross(n, t);
}

glm::vec3 directionOf(int x, int y, int w, int h) {  // inverse of equirectUv at the texel centre
  const float u = (x + 0.5f) / float(w), v = (y + 0.5f) / float(h);
  const float phi = (u - 0.5f) * 2.f * kPi, theta = v * kPi;
  return {std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi)};
}

}  // namespace

glm::vec3 dfgAt(float mu, float roughness, int samples) {
  const float alpha = std::max(roughness * roughness, kMinAlpha);
  const glm::vec3 v(std::sqrt(std::max(0.f, 1.f - mu * mu)), 0.f, mu);
  double a = 0.0, b = 0.0, dp = 0.0;
  for (int i = 0; i < samples; ++i) {
    const glm::vec2 u = hammersley(std::uint32_t(i), std::uint32_t(samples));
    // Specular: l = reflect(-v, h), h ~ D(h)(n.h); weight f cos / pdf = 4 V (n.l)(v.h)/(n.h) F.
    const glm::vec3 h = sampleGgx(u, alpha);
    const float vh = glm::dot(v, h);
    const glm::vec3 l = 2.f * vh * h - v;
    if (l.z > 0.f && vh > 0.f) {
      const float w = 4.f * rt::ggxVisibility(l.z, mu, alpha) * l.z * vh / h.z;
      const float fc = pow5(1.f - vh);
      a += w * (1.f - fc);
      b += w * fc;
    }
    // Diffuse Fresnel weight: l ~ cos / pi (Malley), Dp = E[Fc(v.h)].
    const float r = std::sqrt(u.x), phi = 2.f * kPi * u.y;
    const glm::vec3 ld(r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.f, 1.f - u.x)));
    const glm::vec3 hd = glm::normalize(ld + v);
    dp += pow5(1.f - std::max(glm::dot(v, hd), 0.f));
  }
  return glm::vec3(float(a / samples), float(b / samples), float(dp / samples));
}

const std::vector<float>& dfgTable() {
  static const std::vector<float> table = [] {
    std::vector<float> t(std::size_t(kDfgSize) * kDfgSize * 4, 0.f);
    for (int j = 0; j < kDfgSize; ++j)
      for (int i = 0; i < kDfgSize; ++i) {
        const glm::vec3 d = dfgAt((i + 0.5f) / kDfgSize, float(j) / (kDfgSize - 1), 1024);
        float* p = &t[(std::size_t(j) * kDfgSize + i) * 4];
        p[0] = d.x;
        p[1] = d.y;
        p[2] = d.z;
      }
    return t;
  }();
  return table;
}

std::vector<float> prefilterEnvironment(const Image& map, const rt::Cancel& cancel) {
  // A 128 x 64 solid-angle-weighted box downsample first, so 128 GGX samples per texel do not alias
  // a high-resolution map.
  const int sw = std::min(map.width, 128), sh = std::min(map.height, 64);
  Image src = Image::make("env", sw, sh, 3);
  std::vector<float> weight(std::size_t(sw) * sh, 0.f);
  for (int y = 0; y < map.height; ++y) {
    if (y % 256 == 0) cancel.check("the environment's lighting build (prefilter)");
    const float w = std::sin(kPi * (y + 0.5f) / map.height);
    const int ty = std::min(sh - 1, y * sh / map.height);
    for (int x = 0; x < map.width; ++x) {
      const int tx = std::min(sw - 1, x * sw / map.width);
      const float* p = map.at(x, y);
      float* q = src.at(tx, ty);
      for (int c = 0; c < 3; ++c) q[c] += w * p[map.channels >= 3 ? c : 0];
      weight[std::size_t(ty) * sw + tx] += w;
    }
  }
  for (int i = 0; i < sw * sh; ++i)
    for (int c = 0; c < 3; ++c) src.pixels[std::size_t(i) * 3 + c] /= std::max(weight[std::size_t(i)], 1e-12f);

  constexpr int kSamples = 128;
  std::vector<float> out(std::size_t(kPrefilterLevels) * kPrefilterWidth * kPrefilterHeight * 4, 0.f);
  for (int k = 0; k < kPrefilterLevels; ++k) {
    const float roughness = float(k) / (kPrefilterLevels - 1);
    const float alpha = std::max(roughness * roughness, kMinAlpha);
    for (int y = 0; y < kPrefilterHeight; ++y)
      for (int x = 0; x < kPrefilterWidth; ++x) {
        const glm::vec3 n = directionOf(x, y, kPrefilterWidth, kPrefilterHeight);
        glm::vec3 t, b;
        basis(n, t, b);
        glm::vec3 sum(0.f);
        float total = 0.f;
        for (int i = 0; i < kSamples; ++i) {
          const glm::vec3 hl = sampleGgx(hammersley(std::uint32_t(i), kSamples), alpha);
          const glm::vec3 h = t * hl.x + b * hl.y + n * hl.z;
          const glm::vec3 l = 2.f * glm::dot(n, h) * h - n;  // v = n
          const float nl = glm::dot(n, l);
          if (nl <= 0.f) continue;
          int sx, sy;
          equirectTexel(src, l, sx, sy);
          const float* p = src.at(sx, sy);
          sum += nl * glm::vec3(p[0], p[1], p[2]);
          total += nl;
        }
        float* q = &out[((std::size_t(k) * kPrefilterHeight + y) * kPrefilterWidth + x) * 4];
        const glm::vec3 L = total > 0.f ? sum / total : glm::vec3(0.f);
        q[0] = L.x;
        q[1] = L.y;
        q[2] = L.z;
        q[3] = 1.f;
      }
  }
  return out;
}

namespace {
// Real SH basis up to l = 2 (Ramamoorthi and Hanrahan 2001, eq. 3).
std::array<float, 9> shBasis(const glm::vec3& d) {
  return {0.282095f,
          0.488603f * d.y, 0.488603f * d.z, 0.488603f * d.x,
          1.092548f * d.x * d.y, 1.092548f * d.y * d.z, 0.315392f * (3.f * d.z * d.z - 1.f),
          1.092548f * d.x * d.z, 0.546274f * (d.x * d.x - d.y * d.y)};
}
}  // namespace

std::array<glm::vec3, 9> irradianceSh(const Image& map, const rt::Cancel& cancel) {
  // Each texel is piecewise constant (Environment.h): integrate Y_lm over it by the midpoint rule on
  // subX x subY points, chosen per axis so the whole map is sampled at >= 512 x 256 (the rule's error on
  // the l = 2 terms falls as 1/points^2: ~1e-5 of pi at that density). One factor for both axes made a
  // 1 x 6000 map 512 x 3,072,000 points: 90 s (issue 30); per axis it is 512 x 6000.
  const int subX = std::max(1, (512 + map.width - 1) / std::max(map.width, 1));
  const int subY = std::max(1, (256 + map.height - 1) / std::max(map.height, 1));
  const int sw = map.width * subX, sh = map.height * subY;
  std::array<glm::dvec3, 9> L{};
  const double dTheta = kPi / sh, dPhi = 2.0 * kPi / sw;
  double omega = 0.0;
  for (int y = 0; y < sh; ++y) {
    if (y % 64 == 0) cancel.check("the environment's lighting build (irradiance)");
    const double theta = (y + 0.5) * dTheta;
    const double dOmega = std::sin(theta) * dTheta * dPhi;
    for (int x = 0; x < sw; ++x) {
      const glm::vec3 d = directionOf(x, y, sw, sh);
      const float* p = map.at(x / subX, y / subY);
      const glm::dvec3 radiance = map.channels >= 3 ? glm::dvec3(p[0], p[1], p[2]) : glm::dvec3(p[0]);
      const auto Y = shBasis(d);
      for (int i = 0; i < 9; ++i) L[std::size_t(i)] += radiance * double(Y[std::size_t(i)]) * dOmega;
      omega += dOmega;
    }
  }
  // The sum's solid angle is 4 pi only up to the rule: normalise so a uniform map integrates exactly.
  const double fix = 4.0 * kPi / omega;
  const float A[9] = {kPi, 2.f * kPi / 3.f, 2.f * kPi / 3.f, 2.f * kPi / 3.f, kPi / 4.f, kPi / 4.f, kPi / 4.f, kPi / 4.f, kPi / 4.f};
  std::array<glm::vec3, 9> c{};
  for (int i = 0; i < 9; ++i) c[std::size_t(i)] = glm::vec3(L[std::size_t(i)] * fix) * A[i];
  return c;
}

glm::vec3 irradianceFromSh(const std::array<glm::vec3, 9>& sh, const glm::vec3& n) {
  const auto Y = shBasis(n);
  glm::vec3 e(0.f);
  for (int i = 0; i < 9; ++i) e += sh[std::size_t(i)] * Y[std::size_t(i)];
  return glm::max(e, glm::vec3(0.f));
}

}  // namespace radiant::ibl

// ---- GL side ----------------------------------------------------------------------------------

namespace radiant::ibl {
namespace {
struct ShCoefficients {
  std::array<glm::vec3, 9> c{};
};
}  // namespace

int modeFor(const FrameResources& res) {
  const FrameView& v = res.view();
  if (v.environment) return kMap;
  return v.ambient != glm::vec3(0.f) ? kUniform : kNone;
}

void prepare(FrameResources& res) {
  gl::Texture& dfg = res.texture("ibl_dfg", GL_TEXTURE_2D, GL_RGBA32F, kDfgSize, kDfgSize);
  dfg.setFilter(GL_LINEAR, GL_LINEAR);
  glTextureParameteri(dfg.id(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(dfg.id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  if (FrameResources::Refill table = res.refill("ibl_dfg", "v1"); !table.hit()) {
    dfg.upload(0, 0, 0, 0, kDfgSize, kDfgSize, 1, GL_RGBA, GL_FLOAT, dfgTable().data());
    table.written();
  }
  const FrameView& view = res.view();
  const int layers = view.environment ? kPrefilterLevels : 1;
  gl::Texture& pre = res.texture("ibl_prefiltered", GL_TEXTURE_2D_ARRAY, GL_RGBA32F,
                                 view.environment ? kPrefilterWidth : 1, view.environment ? kPrefilterHeight : 1, layers);
  pre.setFilter(GL_LINEAR, GL_LINEAR);
  glTextureParameteri(pre.id(), GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTextureParameteri(pre.id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  if (view.environment) {
    // The map without the lights `direct` shades with shadows (FrameView::lightingEnvironment).
    const Image& env = *view.lightingEnvironment();
    const std::string key = view.lightingEnvironmentKey() + "|" + std::to_string(env.width) + "x" + std::to_string(env.height);
    // The levels live in the shared texture: prefiltered again when it holds another map's (a frame
    // with another environment since; FrameResources::refill).
    if (FrameResources::Refill levels = res.refill("ibl_prefiltered", key); !levels.hit()) {
      const std::vector<float> texels = prefilterEnvironment(env, res.cancel());
      pre.upload(0, 0, 0, 0, kPrefilterWidth, kPrefilterHeight, kPrefilterLevels, GL_RGBA, GL_FLOAT, texels.data());
      levels.written();
    }
    res.cached<ShCoefficients>("ibl_sh", key, [&] {
      auto s = std::make_unique<ShCoefficients>();
      s->c = irradianceSh(env, res.cancel());
      return s;
    });
  }
}

void bind(FrameResources& res, const gl::Program& program, int dfgUnit, int prefilteredUnit) {
  const FrameView& view = res.view();
  const int mode = modeFor(res);
  if (dfgUnit >= 0) res.texture("ibl_dfg").bindUnit(GLuint(dfgUnit));
  if (prefilteredUnit >= 0) res.texture("ibl_prefiltered").bindUnit(GLuint(prefilteredUnit));
  program.set("u_iblMode", mode);
  program.set("u_iblUniform", &view.ambient[0], 3);
  std::array<glm::vec3, 9> sh{};
  if (mode == kMap) {
    const Image& env = *view.lightingEnvironment();
    const std::string key = view.lightingEnvironmentKey() + "|" + std::to_string(env.width) + "x" + std::to_string(env.height);
    sh = res.cached<ShCoefficients>("ibl_sh", key, [&] {
      auto s = std::make_unique<ShCoefficients>();
      s->c = irradianceSh(env);
      return s;
    }).c;
  } else {
    sh[0] = view.ambient * (kPi / 0.282095f);  // E = pi L for a uniform sky: c0 Y00 = pi L
  }
  const GLint loc = program.uniformLocation("u_sh[0]");
  if (loc >= 0) glProgramUniform3fv(program.id(), loc, 9, &sh[0][0]);
}

}  // namespace radiant::ibl
