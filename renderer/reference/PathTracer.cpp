#include "renderer/reference/PathTracer.h"
#include "renderer/scene/Environment.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "renderer/reference/Brdf.h"

namespace radiant::reference {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
// Ray origins are pushed off surfaces by this many float ulps of the largest coordinate involved
// (hit point and the triangle's vertices), so the offset follows the scene's scale: a scene modelled in
// millimetres and one in kilometres both self-intersect neither too much nor leak.
constexpr float kRayOffsetRelative = 64.f * std::numeric_limits<float>::epsilon();
constexpr float kRayOffsetMinimum = 1e-30f;
constexpr int kMaxAlphaPassThrough = 64;
constexpr int kTileSize = 16;
constexpr int kRussianRouletteStart = 3;

// ---------------------------------------------------------------------------------------------------
// Counter-based random numbers: every value is a hash of (pixel, sample, seed, dimension).

inline std::uint64_t splitMix64(std::uint64_t z) {
  z += 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

struct Sampler {
  std::uint64_t key = 0;
  std::uint64_t dimension = 0;
  Sampler(std::uint64_t pixel, std::uint64_t sample, std::uint64_t seed)
      : key(splitMix64(splitMix64(splitMix64(seed) ^ pixel) ^ (sample * 0xD1B54A32D192ED03ull))) {}
  float next() {
    const std::uint64_t h = splitMix64(key ^ (++dimension * 0xA0761D6478BD642Full));
    return static_cast<float>(h >> 40) * 0x1p-24f;  // [0, 1)
  }
  glm::vec2 next2() { const float a = next(); return {a, next()}; }
};

// ---------------------------------------------------------------------------------------------------
// Textures (glTF samplers: wrap modes, nearest or bilinear; sRGB decoded before filtering).

float srgbToLinear(float c) {
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}
const std::array<float, 256>& srgbTable() {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    for (int i = 0; i < 256; ++i) t[i] = srgbToLinear(i / 255.f);
    return t;
  }();
  return table;
}

int wrapCoordinate(int i, int n, int mode) {
  switch (mode) {
    case 33071: return std::clamp(i, 0, n - 1);  // CLAMP_TO_EDGE
    case 33648: {                                // MIRRORED_REPEAT
      const int period = 2 * n;
      int k = i % period;
      if (k < 0) k += period;
      return k < n ? k : period - 1 - k;
    }
    default: {  // REPEAT
      int k = i % n;
      return k < 0 ? k + n : k;
    }
  }
}

glm::vec4 texel(const Texture& t, int x, int y, bool srgb) {
  const std::uint8_t* p = &t.rgba8[(static_cast<size_t>(y) * t.width + x) * 4];
  if (srgb) {
    const auto& lut = srgbTable();
    return {lut[p[0]], lut[p[1]], lut[p[2]], p[3] / 255.f};
  }
  return glm::vec4(p[0], p[1], p[2], p[3]) / 255.f;
}

glm::vec4 sampleTexture(const Texture& t, glm::vec2 uv, bool srgb) {
  if (t.width <= 0 || t.height <= 0 || t.rgba8.size() < static_cast<size_t>(t.width) * t.height * 4)
    return glm::vec4(1.f);
  const float x = uv.x * t.width - 0.5f, y = uv.y * t.height - 0.5f;
  if (t.magFilter == 9728) {  // NEAREST
    const int ix = wrapCoordinate(static_cast<int>(std::floor(x + 0.5f)), t.width, t.wrapS);
    const int iy = wrapCoordinate(static_cast<int>(std::floor(y + 0.5f)), t.height, t.wrapT);
    return texel(t, ix, iy, srgb);
  }
  const float fx0 = std::floor(x), fy0 = std::floor(y);
  const float fx = x - fx0, fy = y - fy0;
  const int x0 = static_cast<int>(fx0), y0 = static_cast<int>(fy0);
  const int xa = wrapCoordinate(x0, t.width, t.wrapS), xb = wrapCoordinate(x0 + 1, t.width, t.wrapS);
  const int ya = wrapCoordinate(y0, t.height, t.wrapT), yb = wrapCoordinate(y0 + 1, t.height, t.wrapT);
  return (1.f - fy) * ((1.f - fx) * texel(t, xa, ya, srgb) + fx * texel(t, xb, ya, srgb)) +
         fy * ((1.f - fx) * texel(t, xa, yb, srgb) + fx * texel(t, xb, yb, srgb));
}

// ---------------------------------------------------------------------------------------------------
// Environment: uniform sky or an equirectangular map importance sampled by a piecewise-constant 2D
// distribution over texels weighted by luminance * sin(theta) (pbrt-v3 14.2.4).

class Environment {
public:
  explicit Environment(const ReferenceOptions& o) : map_(o.environment), sky_(o.skyRadiance) {
    if (map_) {
      if (map_->width <= 0 || map_->height <= 0 || map_->channels <= 0 ||
          map_->pixels.size() < static_cast<size_t>(map_->width) * map_->height * map_->channels)
        throw std::invalid_argument("PathTracer::render(): environment image has no pixels");
      const int w = map_->width, h = map_->height;
      conditional_.assign(static_cast<size_t>(h) * (w + 1), 0.f);
      marginal_.assign(h + 1, 0.f);
      for (int y = 0; y < h; ++y) {
        const float sinTheta = std::sin(kPi * (y + 0.5f) / h);
        float* cdf = &conditional_[static_cast<size_t>(y) * (w + 1)];
        for (int x = 0; x < w; ++x) cdf[x + 1] = cdf[x] + std::max(0.f, luminance(texelAt(x, y))) * sinTheta;
        marginal_[y + 1] = marginal_[y] + cdf[w];
      }
      total_ = marginal_[h];
      active_ = total_ > 0.f;
    } else {
      active_ = maxComponent(sky_) > 0.f;
    }
  }
  bool active() const { return active_; }

  glm::vec3 radiance(const glm::vec3& dir) const {
    if (!map_) return sky_;
    int x, y;
    texelOf(dir, x, y);
    return texelAt(x, y);
  }

  float pdf(const glm::vec3& dir) const {
    if (!active_) return 0.f;
    if (!map_) return uniformSpherePdf();
    const float sinTheta = safeSqrt(1.f - dir.y * dir.y);
    if (sinTheta <= 0.f) return 0.f;
    int x, y;
    texelOf(dir, x, y);
    const int w = map_->width, h = map_->height;
    const float* cdf = &conditional_[static_cast<size_t>(y) * (w + 1)];
    const float p = (cdf[x + 1] - cdf[x]) / total_;  // discrete texel probability
    return p * w * h / (2.f * kPi * kPi * sinTheta);  // uv density -> solid angle: dw = 2 pi^2 sin(theta) du dv
  }

  glm::vec3 sample(glm::vec2 u, float& pdfOut) const {
    if (!map_) {
      pdfOut = uniformSpherePdf();
      return sampleUniformSphere(u);
    }
    const int w = map_->width, h = map_->height;
    const int y = findInterval(marginal_.data(), h, u.y * total_);
    const float rowLo = marginal_[y], rowHi = marginal_[y + 1];
    const float fy = rowHi > rowLo ? std::clamp((u.y * total_ - rowLo) / (rowHi - rowLo), 0.f, 1.f) : 0.5f;
    const float* cdf = &conditional_[static_cast<size_t>(y) * (w + 1)];
    const int x = findInterval(cdf, w, u.x * cdf[w]);
    const float colLo = cdf[x], colHi = cdf[x + 1];
    const float fx = colHi > colLo ? std::clamp((u.x * cdf[w] - colLo) / (colHi - colLo), 0.f, 1.f) : 0.5f;
    const float uu = (x + fx) / w, vv = (y + fy) / h;
    const float theta = kPi * vv, phi = 2.f * kPi * (uu - 0.5f);
    const float sinTheta = std::sin(theta);
    const glm::vec3 dir(sinTheta * std::sin(phi), std::cos(theta), -sinTheta * std::cos(phi));
    if (sinTheta <= 0.f) { pdfOut = 0.f; return dir; }
    pdfOut = (colHi - colLo) / total_ * w * h / (2.f * kPi * kPi * sinTheta);
    return dir;
  }

private:
  glm::vec3 texelAt(int x, int y) const {
    const float* p = map_->at(x, y);
    return map_->channels >= 3 ? glm::vec3(p[0], p[1], p[2]) : glm::vec3(p[0]);
  }
  void texelOf(const glm::vec3& dir, int& x, int& y) const { equirectTexel(*map_, dir, x, y); }
  // Largest i in [0, n) with cdf[i] <= value and cdf[i + 1] > cdf[i] when possible.
  static int findInterval(const float* cdf, int n, float value) {
    const float* it = std::upper_bound(cdf, cdf + n + 1, value);
    int i = static_cast<int>(it - cdf) - 1;
    i = std::clamp(i, 0, n - 1);
    while (i > 0 && cdf[i + 1] <= cdf[i]) --i;         // skip zero-probability cells (value at an edge)
    while (i < n - 1 && cdf[i + 1] <= cdf[i]) ++i;
    return i;
  }

  const Image* map_;
  glm::vec3 sky_;
  std::vector<float> conditional_, marginal_;
  float total_ = 0.f;
  bool active_ = false;
};

struct Ray {
  glm::vec3 org, dir;
  float tnear = 0.f, tfar = kInf;
};

// What a closest hit tells the shader.
struct SurfaceHit {
  int mesh = -1, prim = -1;
  float b0 = 0.f, b1 = 0.f, b2 = 0.f;
  glm::vec3 p{0.f};
  glm::vec3 ng{0.f};  // unit geometric normal of the winding (front face = counter-clockwise)
  float offsetScale = 0.f;
  float distance = 0.f;  // from the original ray origin
};

float maxAbs(const glm::vec3& v) { return std::max(std::abs(v.x), std::max(std::abs(v.y), std::abs(v.z))); }

struct RayCounter {
  std::uint64_t rays = 0;
};

}  // namespace

// ---------------------------------------------------------------------------------------------------

struct PathTracer::Impl {
  const Scene* scene = nullptr;
  RTCDevice device = nullptr;
  RTCScene rtcScene = nullptr;
  bool anyAlpha = false;

  // Emissive triangles: light index = emissiveOffset[mesh] + prim; power-proportional CDF.
  std::vector<int> emissiveOffset;
  struct TriangleLight { int mesh, prim; float area; };
  std::vector<TriangleLight> triangleLights;
  std::vector<float> lightCdf;  // size + 1
  float totalLightPower = 0.f;

  mutable std::atomic<std::uint64_t> lastRays{0};

  explicit Impl(const Scene& s);
  ~Impl() {
    if (rtcScene) rtcReleaseScene(rtcScene);
    if (device) rtcReleaseDevice(device);
  }

  void checkDevice(const char* call) const {
    const RTCError e = rtcGetDeviceError(device);
    if (e != RTC_ERROR_NONE)
      throw std::runtime_error(std::string("PathTracer::PathTracer(): ") + call + " failed: Embree error " +
                               std::to_string(static_cast<int>(e)));
  }

  const Material& materialOf(int mesh) const { return scene->material(scene->meshes[mesh].material); }

  glm::vec2 uvAt(const SurfaceHit& h, int set) const {
    const MeshInstance& m = scene->meshes[h.mesh];
    const auto& uvs = set == 1 ? m.uv1 : m.uv0;
    if (uvs.empty()) return glm::vec2(0.f);
    const std::uint32_t* i = &m.indices[static_cast<size_t>(h.prim) * 3];
    return h.b0 * uvs[i[0]] + h.b1 * uvs[i[1]] + h.b2 * uvs[i[2]];
  }
  glm::vec4 textureAt(const TextureRef& ref, const SurfaceHit& h, bool srgb) const {
    if (!ref.valid() || ref.texture >= static_cast<int>(scene->textures.size())) return glm::vec4(1.f);
    return sampleTexture(scene->textures[ref.texture], ref.transformUv(uvAt(h, ref.texCoord)), srgb);
  }

  float alphaAt(const Material& mat, const SurfaceHit& h) const {
    return mat.baseColorFactor.a * textureAt(mat.baseColorTexture, h, true).a;
  }

  // Emitted radiance towards -dir (zero from the back of a single-sided emitter).
  glm::vec3 emissionAt(const Material& mat, const SurfaceHit& h, const glm::vec3& dir) const {
    if (!mat.isEmissive()) return glm::vec3(0.f);
    if (!mat.doubleSided && glm::dot(dir, h.ng) >= 0.f) return glm::vec3(0.f);
    return mat.emission() * glm::vec3(textureAt(mat.emissiveTexture, h, true));
  }

  SurfaceHit makeHit(const RTCRayHit& rh, const glm::vec3& origin) const {
    SurfaceHit h;
    h.mesh = static_cast<int>(rh.hit.geomID);
    h.prim = static_cast<int>(rh.hit.primID);
    h.b1 = rh.hit.u;
    h.b2 = rh.hit.v;
    h.b0 = 1.f - h.b1 - h.b2;
    const MeshInstance& m = scene->meshes[h.mesh];
    const std::uint32_t* i = &m.indices[static_cast<size_t>(h.prim) * 3];
    const glm::vec3 &v0 = m.positions[i[0]], &v1 = m.positions[i[1]], &v2 = m.positions[i[2]];
    // The barycentric interpolation is far more accurate than org + t dir.
    h.p = h.b0 * v0 + h.b1 * v1 + h.b2 * v2;
    const glm::vec3 n = glm::cross(v1 - v0, v2 - v0);
    const float len = glm::length(n);
    h.ng = len > 0.f ? n / len : glm::vec3(0.f, 0.f, 1.f);
    h.offsetScale = std::max({maxAbs(h.p), maxAbs(v0), maxAbs(v1), maxAbs(v2)});
    h.distance = glm::length(h.p - origin);
    return h;
  }

  // Origin for a ray leaving p in direction dir, pushed off the surface to dir's side of ng.
  static glm::vec3 offsetOrigin(const glm::vec3& p, const glm::vec3& ng, float scale, const glm::vec3& dir) {
    const float eps = std::max(kRayOffsetRelative * scale, kRayOffsetMinimum);
    return p + (glm::dot(dir, ng) >= 0.f ? eps : -eps) * ng;
  }

  // Closest hit, passing through alpha-masked / blended surfaces.
  bool intersect(Ray ray, SurfaceHit& hit, Sampler& sampler, RayCounter& counter) const {
    const glm::vec3 origin = ray.org;
    for (int pass = 0; pass < kMaxAlphaPassThrough; ++pass) {
      RTCIntersectContext ctx;
      rtcInitIntersectContext(&ctx);
      RTCRayHit rh{};
      rh.ray.org_x = ray.org.x; rh.ray.org_y = ray.org.y; rh.ray.org_z = ray.org.z;
      rh.ray.dir_x = ray.dir.x; rh.ray.dir_y = ray.dir.y; rh.ray.dir_z = ray.dir.z;
      rh.ray.tnear = ray.tnear;
      rh.ray.tfar = ray.tfar;
      rh.ray.mask = 0xFFFFFFFFu;
      rh.ray.flags = 0;
      rh.ray.time = 0.f;
      rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
      rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
      rtcIntersect1(rtcScene, &ctx, &rh);
      ++counter.rays;
      if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
      hit = makeHit(rh, origin);
      if (!anyAlpha || !passesThrough(hit, sampler)) return true;
      const float travelled = rh.ray.tfar;
      ray.org = offsetOrigin(hit.p, hit.ng, hit.offsetScale, ray.dir);
      ray.tnear = 0.f;
      ray.tfar = ray.tfar == kInf ? kInf : std::max(0.f, ray.tfar - travelled);
    }
    return false;
  }

  bool passesThrough(const SurfaceHit& hit, Sampler& sampler) const {
    const Material& mat = materialOf(hit.mesh);
    if (mat.alphaMode == AlphaMode::Opaque) return false;
    const float a = alphaAt(mat, hit);
    if (mat.alphaMode == AlphaMode::Mask) return a < mat.alphaCutoff;
    return sampler.next() >= a;  // Blend: stochastic coverage
  }

  bool occluded(const Ray& ray, Sampler& sampler, RayCounter& counter) const {
    if (anyAlpha) {
      SurfaceHit h;
      return intersect(ray, h, sampler, counter);
    }
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRay r{};
    r.org_x = ray.org.x; r.org_y = ray.org.y; r.org_z = ray.org.z;
    r.dir_x = ray.dir.x; r.dir_y = ray.dir.y; r.dir_z = ray.dir.z;
    r.tnear = ray.tnear;
    r.tfar = ray.tfar;
    r.mask = 0xFFFFFFFFu;
    r.flags = 0;
    r.time = 0.f;
    rtcOccluded1(rtcScene, &ctx, &r);
    ++counter.rays;
    return r.tfar < 0.f;  // Embree sets tfar = -inf on a hit
  }

  // Solid-angle pdf with which NEE would have picked point `hit` on an emissive triangle seen along dir.
  float triangleLightPdf(const SurfaceHit& hit, const glm::vec3& dir) const {
    if (totalLightPower <= 0.f || emissiveOffset[hit.mesh] < 0) return 0.f;
    const int li = emissiveOffset[hit.mesh] + hit.prim;
    const TriangleLight& tl = triangleLights[li];
    const float pSelect = (lightCdf[li + 1] - lightCdf[li]) / totalLightPower;
    const float cosL = std::abs(glm::dot(hit.ng, dir));
    if (pSelect <= 0.f || cosL <= 0.f || tl.area <= 0.f) return 0.f;
    return pSelect * hit.distance * hit.distance / (tl.area * cosL);
  }

  struct Shading {
    GltfBsdf bsdf;
    ShadingFrame frame;
    glm::vec3 ngFacing;  // geometric normal on wo's side
  };

  Shading shade(const SurfaceHit& hit, const glm::vec3& wo) const {
    const Material& mat = materialOf(hit.mesh);
    const MeshInstance& m = scene->meshes[hit.mesh];
    Shading s;
    const glm::vec4 base = mat.baseColorFactor * textureAt(mat.baseColorTexture, hit, true);
    s.bsdf.baseColor = glm::clamp(glm::vec3(base), 0.f, 1.f);
    const glm::vec4 mr = textureAt(mat.metallicRoughnessTexture, hit, false);
    s.bsdf.metallic = std::clamp(mat.metallicFactor * mr.b, 0.f, 1.f);
    s.bsdf.roughness = std::clamp(mat.roughnessFactor * mr.g, 0.f, 1.f);
    s.bsdf.transmission =
        std::clamp(mat.transmissionFactor * (mat.transmissionTexture.valid()
                                                 ? textureAt(mat.transmissionTexture, hit, false).r : 1.f),
                   0.f, 1.f);
    s.bsdf.ior = mat.ior > 0.f ? mat.ior : 1.5f;
    const bool front = glm::dot(wo, hit.ng) >= 0.f;
    s.bsdf.eta = front ? s.bsdf.ior : 1.f / s.bsdf.ior;
    s.ngFacing = front ? hit.ng : -hit.ng;

    // Shading normal: interpolated vertex normal, normal-mapped when a tangent frame exists.
    glm::vec3 ns = hit.ng;
    const std::uint32_t* i = &m.indices[static_cast<size_t>(hit.prim) * 3];
    if (m.normals.size() == m.positions.size()) {
      const glm::vec3 n = hit.b0 * m.normals[i[0]] + hit.b1 * m.normals[i[1]] + hit.b2 * m.normals[i[2]];
      if (glm::dot(n, n) > 0.f) ns = glm::normalize(n);
      if (mat.normalTexture.valid() && m.tangents.size() == m.positions.size()) {
        const glm::vec4 t4 = hit.b0 * m.tangents[i[0]] + hit.b1 * m.tangents[i[1]] + hit.b2 * m.tangents[i[2]];
        glm::vec3 t = glm::vec3(t4) - ns * glm::dot(ns, glm::vec3(t4));
        if (glm::dot(t, t) > 0.f) {
          t = glm::normalize(t);
          const glm::vec3 b = glm::cross(ns, t) * (m.tangents[i[0]].w < 0.f ? -1.f : 1.f);
          glm::vec3 tn = glm::vec3(textureAt(mat.normalTexture, hit, false)) * 2.f - 1.f;
          tn.x *= mat.normalTexture.scale;
          tn.y *= mat.normalTexture.scale;
          const glm::vec3 mapped = tn.x * t + tn.y * b + tn.z * ns;
          if (glm::dot(mapped, mapped) > 0.f) ns = glm::normalize(mapped);
        }
      }
      if (glm::dot(ns, hit.ng) < 0.f) ns = -ns;  // normals inconsistent with the winding
      if (!front) ns = -ns;
      if (glm::dot(ns, wo) <= 1e-4f) ns = s.ngFacing;  // wo under the shading hemisphere
    } else {
      ns = s.ngFacing;
    }
    s.frame = ShadingFrame::fromNormal(ns);
    return s;
  }

  bool inRange(int k, const ReferenceOptions& o) const { return k >= o.minPathBounce && k <= o.maxPathBounce; }

  // Direct light at a scattering vertex by next-event estimation (k = the vertex's bounce count).
  glm::vec3 estimateDirect(const SurfaceHit& hit, const Shading& sh, const glm::vec3& woL, const Environment& env,
                           Sampler& sampler, RayCounter& counter) const {
    glm::vec3 L(0.f);
    auto visible = [&](const glm::vec3& wi, const glm::vec3& wiL) {
      // The direction must be on the side of the geometric surface that the lobe (reflection or
      // transmission) expects, or light leaks through shading-normal tricks.
      const float gs = glm::dot(wi, sh.ngFacing);
      return wiL.z > 0.f ? gs > 0.f : gs < 0.f;
    };

    // Punctual lights (KHR_lights_punctual), all of them every vertex.
    for (const Light& light : scene->lights) {
      glm::vec3 wi;
      float dist = kInf;
      glm::vec3 Li = light.color * light.intensity;
      if (light.type == LightType::Directional) {
        const float len = glm::length(light.direction);
        if (len <= 0.f) continue;
        wi = -light.direction / len;  // directional intensity is the irradiance normal to the beam (lux)
      } else {
        const glm::vec3 d = light.position - hit.p;
        const float d2 = glm::dot(d, d);
        if (d2 <= 0.f) continue;
        dist = std::sqrt(d2);
        wi = d / dist;
        // Inverse square law, windowed by range: KHR_lights_punctual's recommended
        // clamp(1 - (d / range)^4, 0, 1) / d^2.
        float attenuation = 1.f / d2;
        if (light.range > 0.f) attenuation *= std::clamp(1.f - std::pow(dist / light.range, 4.f), 0.f, 1.f);
        Li *= attenuation;
        if (light.type == LightType::Spot) {
          // KHR_lights_punctual spot falloff: t = saturate(cd * scale + offset),
          // scale = 1 / max(0.001, cos(inner) - cos(outer)), offset = -cos(outer) * scale; attenuation t^2.
          const float len = glm::length(light.direction);
          if (len <= 0.f) continue;
          const float cd = glm::dot(light.direction / len, -wi);
          const float cosOuter = std::cos(light.outerConeAngle), cosInner = std::cos(light.innerConeAngle);
          const float scale = 1.f / std::max(0.001f, cosInner - cosOuter);
          const float t = std::clamp(cd * scale - cosOuter * scale, 0.f, 1.f);
          Li *= t * t;
        }
      }
      if (maxComponent(Li) <= 0.f) continue;
      const glm::vec3 wiL = sh.frame.toLocal(wi);
      if (!visible(wi, wiL)) continue;
      const glm::vec3 f = sh.bsdf.eval(woL, wiL);
      if (maxComponent(f) <= 0.f) continue;
      Ray shadow{offsetOrigin(hit.p, hit.ng, hit.offsetScale, wi), wi, 0.f, dist};
      if (dist != kInf) {
        const glm::vec3 d = light.position - shadow.org;
        shadow.tfar = glm::length(d);
        shadow.dir = d / shadow.tfar;
      }
      if (occluded(shadow, sampler, counter)) continue;
      L += f * std::abs(wiL.z) * Li;
    }

    // One emissive triangle, chosen in proportion to power, sampled uniformly by area; MIS with the BSDF.
    if (totalLightPower > 0.f) {
      const float uSel = sampler.next();
      const glm::vec2 uTri = sampler.next2();
      const float target = uSel * totalLightPower;
      int li = static_cast<int>(std::upper_bound(lightCdf.begin(), lightCdf.end(), target) - lightCdf.begin()) - 1;
      li = std::clamp(li, 0, static_cast<int>(triangleLights.size()) - 1);
      while (li > 0 && lightCdf[li + 1] <= lightCdf[li]) --li;
      const TriangleLight& tl = triangleLights[li];
      const float pSelect = (lightCdf[li + 1] - lightCdf[li]) / totalLightPower;
      const MeshInstance& m = scene->meshes[tl.mesh];
      const std::uint32_t* i = &m.indices[static_cast<size_t>(tl.prim) * 3];
      const glm::vec3 &v0 = m.positions[i[0]], &v1 = m.positions[i[1]], &v2 = m.positions[i[2]];
      const glm::vec2 b = sampleUniformTriangle(uTri);
      SurfaceHit lh;
      lh.mesh = tl.mesh;
      lh.prim = tl.prim;
      lh.b0 = b.x; lh.b1 = b.y; lh.b2 = 1.f - b.x - b.y;
      lh.p = lh.b0 * v0 + lh.b1 * v1 + lh.b2 * v2;
      lh.ng = glm::normalize(glm::cross(v1 - v0, v2 - v0));
      lh.offsetScale = std::max({maxAbs(lh.p), maxAbs(v0), maxAbs(v1), maxAbs(v2)});
      const glm::vec3 d = lh.p - hit.p;
      const float d2 = glm::dot(d, d);
      if (pSelect > 0.f && d2 > 0.f) {
        const float dist = std::sqrt(d2);
        const glm::vec3 wi = d / dist;
        const float cosL = std::abs(glm::dot(lh.ng, wi));
        const glm::vec3 Le = emissionAt(materialOf(tl.mesh), lh, wi);
        const glm::vec3 wiL = sh.frame.toLocal(wi);
        if (cosL > 0.f && maxComponent(Le) > 0.f && visible(wi, wiL)) {
          const float lightPdf = pSelect * d2 / (tl.area * cosL);  // area -> solid angle
          const glm::vec3 f = sh.bsdf.eval(woL, wiL);
          if (maxComponent(f) > 0.f) {
            Ray shadow;
            shadow.org = offsetOrigin(hit.p, hit.ng, hit.offsetScale, wi);
            const glm::vec3 targetP = offsetOrigin(lh.p, lh.ng, lh.offsetScale, -wi);
            const glm::vec3 sd = targetP - shadow.org;
            shadow.tfar = glm::length(sd);
            if (shadow.tfar > 0.f) {
              shadow.dir = sd / shadow.tfar;
              if (!occluded(shadow, sampler, counter)) {
                const float w = powerHeuristic(lightPdf, sh.bsdf.pdf(woL, wiL));
                L += f * std::abs(wiL.z) * Le * (w / lightPdf);
              }
            }
          }
        }
      }
    }

    // The environment, importance sampled; MIS with the BSDF.
    if (env.active()) {
      float envPdf = 0.f;
      const glm::vec3 wi = env.sample(sampler.next2(), envPdf);
      const glm::vec3 wiL = sh.frame.toLocal(wi);
      if (envPdf > 0.f && visible(wi, wiL)) {
        const glm::vec3 f = sh.bsdf.eval(woL, wiL);
        const glm::vec3 Le = env.radiance(wi);
        if (maxComponent(f) > 0.f && maxComponent(Le) > 0.f) {
          Ray shadow{offsetOrigin(hit.p, hit.ng, hit.offsetScale, wi), wi, 0.f, kInf};
          if (!occluded(shadow, sampler, counter)) {
            const float w = powerHeuristic(envPdf, sh.bsdf.pdf(woL, wiL));
            L += f * std::abs(wiL.z) * Le * (w / envPdf);
          }
        }
      }
    }
    return L;
  }

  glm::vec3 radiance(Ray ray, const ReferenceOptions& o, const Environment& env, Sampler& sampler,
                     RayCounter& counter) const {
    glm::vec3 L(0.f), beta(1.f);
    float etaScale = 1.f;  // product of eta^2 over refractions: keeps Russian roulette blind to the
                           // radiance scaling at interfaces (pbrt-v4 14.1.4)
    int k = 0;  // scattering events so far
    bool prevDelta = true;  // the camera "sampled" this direction: no MIS on directly seen emitters
    float prevPdf = 0.f;
    const int lastVertex = std::min(o.maxBounces, o.maxPathBounce);
    for (;;) {
      SurfaceHit hit;
      if (!intersect(ray, hit, sampler, counter)) {
        if (env.active() && inRange(k, o)) {
          const float w = prevDelta ? 1.f : powerHeuristic(prevPdf, env.pdf(ray.dir));
          L += beta * env.radiance(ray.dir) * w;
        }
        break;
      }
      const Material& mat = materialOf(hit.mesh);
      if (mat.unlit) {  // KHR_materials_unlit: the base colour leaves the surface, nothing scatters
        if (inRange(k, o)) L += beta * glm::vec3(mat.baseColorFactor * textureAt(mat.baseColorTexture, hit, true));
        break;
      }
      if (inRange(k, o)) {
        const glm::vec3 Le = emissionAt(mat, hit, ray.dir);
        if (maxComponent(Le) > 0.f) {
          const float w = prevDelta ? 1.f : powerHeuristic(prevPdf, triangleLightPdf(hit, ray.dir));
          L += beta * Le * w;
        }
      }
      if (k >= lastVertex) break;
      ++k;

      const glm::vec3 wo = -ray.dir;
      const Shading sh = shade(hit, wo);
      const glm::vec3 woL = sh.frame.toLocal(wo);
      if (inRange(k, o) && sh.bsdf.hasNonDeltaLobe(woL))
        L += beta * estimateDirect(hit, sh, woL, env, sampler, counter);

      const float uLobe = sampler.next(), uFresnel = sampler.next();
      const glm::vec2 uDir = sampler.next2();
      GltfBsdf::Sample bs;
      if (!sh.bsdf.sample(woL, uLobe, uFresnel, uDir, bs)) break;
      const glm::vec3 wi = sh.frame.toWorld(bs.wi);
      const float gs = glm::dot(wi, sh.ngFacing);
      if (bs.wi.z > 0.f ? gs <= 0.f : gs >= 0.f) break;  // leaked through the geometric surface
      beta *= bs.weight;
      if (bs.wi.z < 0.f) etaScale *= sh.bsdf.eta * sh.bsdf.eta;
      prevDelta = bs.delta;
      prevPdf = bs.pdf;
      if (!(maxComponent(beta) > 0.f)) break;
      if (o.russianRoulette && k >= kRussianRouletteStart) {
        const float q = std::min(0.95f, maxComponent(beta) * etaScale);
        if (sampler.next() >= q) break;
        beta /= q;
      }
      ray = Ray{offsetOrigin(hit.p, hit.ng, hit.offsetScale, wi), wi, 0.f, kInf};
    }
    return L;
  }

  float ambientOcclusion(const Ray& cameraRay, const ReferenceOptions& o, Sampler& sampler, RayCounter& counter) const {
    SurfaceHit hit;
    if (!intersect(cameraRay, hit, sampler, counter)) return 1.f;
    const MeshInstance& m = scene->meshes[hit.mesh];
    const glm::vec3 ngFacing = glm::dot(cameraRay.dir, hit.ng) < 0.f ? hit.ng : -hit.ng;
    glm::vec3 n = ngFacing;
    if (m.normals.size() == m.positions.size()) {
      const std::uint32_t* i = &m.indices[static_cast<size_t>(hit.prim) * 3];
      const glm::vec3 ni = hit.b0 * m.normals[i[0]] + hit.b1 * m.normals[i[1]] + hit.b2 * m.normals[i[2]];
      if (glm::dot(ni, ni) > 0.f) n = glm::normalize(ni);
      if (glm::dot(n, ngFacing) < 0.f) n = -n;
    }
    const ShadingFrame frame = ShadingFrame::fromNormal(n);
    const float R = o.aoRadius;
    const glm::vec2 u = sampler.next2();
    glm::vec3 wL;
    if (o.mode == ReferenceOptions::Mode::AoVolumetric) wL = sampleCosinePowerHemisphere(u, 3.f);
    else wL = sampleCosineHemisphere(u);
    if (wL.z <= 0.f) return 0.f;
    const glm::vec3 w = frame.toWorld(wL);
    if (glm::dot(w, ngFacing) <= 0.f) return 0.f;  // into the surface itself: occluded at distance 0
    // Ray length: R, or R cos(theta) for the tangent sphere (r <= R cos(theta)).
    const float length = o.mode == ReferenceOptions::Mode::AoVolumetric ? R * wL.z : R;
    Ray ray{offsetOrigin(hit.p, hit.ng, hit.offsetScale, w), w, 0.f, length};
    switch (o.mode) {
      case ReferenceOptions::Mode::AoCosineStep:
        // eq. 4.2, step membership: estimator [d >= R] under p(w) = cos/pi.
        return occluded(ray, sampler, counter) ? 0.f : 1.f;
      case ReferenceOptions::Mode::AoCubicFalloff: {
        // eq. 4.2 with mu(r) = min(1, (r/R)^3): estimator mu(d) under p(w) = cos/pi.
        SurfaceHit occ;
        if (!intersect(ray, occ, sampler, counter)) return 1.f;
        const float r = std::min(occ.distance, R) / R;
        return r * r * r;
      }
      case ReferenceOptions::Mode::AoVolumetric: {
        // eq. 4.6: V = (2/pi) \int min(d/R, cos)^3 dw; with p(w) = 2 cos^3 / pi the estimator is
        // min(1, d / (R cos))^3: the visible fraction of the ray's chord through the tangent sphere, cubed.
        SurfaceHit occ;
        if (!intersect(ray, occ, sampler, counter)) return 1.f;
        const float r = std::min(occ.distance, length) / length;
        return r * r * r;
      }
      default: return 0.f;
    }
  }

  Ray cameraRay(const Camera& cam, int width, int height, float px, float py) const {
    const float aspect = cam.aspectRatio > 0.f ? cam.aspectRatio : static_cast<float>(width) / height;
    const float sx = 2.f * px / width - 1.f;
    const float sy = 1.f - 2.f * py / height;
    const glm::mat3 rot(cam.world);
    Ray r;
    if (cam.projection == ProjectionType::Orthographic) {
      r.org = glm::vec3(cam.world * glm::vec4(sx * cam.xmag, sy * cam.ymag, 0.f, 1.f));
      const glm::vec3 d = rot * glm::vec3(0.f, 0.f, -1.f);
      const float len = glm::length(d);
      r.dir = d / len;
      r.tnear = std::max(0.f, cam.znear) * len;
    } else {
      const float tanY = std::tan(0.5f * cam.yfov);
      const glm::vec3 d = rot * glm::vec3(sx * tanY * aspect, sy * tanY, -1.f);
      const float len = glm::length(d);
      r.org = glm::vec3(cam.world[3]);
      r.dir = d / len;
      r.tnear = std::max(0.f, cam.znear) * len;  // the point at view depth znear
    }
    r.tfar = kInf;
    return r;
  }
};

PathTracer::Impl::Impl(const Scene& s) : scene(&s) {
  device = rtcNewDevice(nullptr);
  if (!device)
    throw std::runtime_error("PathTracer::PathTracer(): rtcNewDevice failed: Embree error " +
                             std::to_string(static_cast<int>(rtcGetDeviceError(nullptr))));
  rtcScene = rtcNewScene(device);
  checkDevice("rtcNewScene");
  rtcSetSceneFlags(rtcScene, RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(rtcScene, RTC_BUILD_QUALITY_HIGH);

  emissiveOffset.assign(s.meshes.size(), -1);
  lightCdf.push_back(0.f);
  for (size_t mi = 0; mi < s.meshes.size(); ++mi) {
    const MeshInstance& m = s.meshes[mi];
    const size_t triangles = m.triangleCount();
    if (triangles == 0 || m.positions.empty()) continue;
    for (std::uint32_t idx : m.indices)
      if (idx >= m.positions.size())
        throw std::invalid_argument("PathTracer::PathTracer(): mesh '" + m.name + "' index " + std::to_string(idx) +
                                    " >= vertex count " + std::to_string(m.positions.size()));
    const Material& mat = s.material(m.material);
    if (mat.alphaMode != AlphaMode::Opaque) anyAlpha = true;

    RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    checkDevice("rtcNewGeometry");
    auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                           3 * sizeof(float), m.positions.size()));
    auto* ib = static_cast<unsigned*>(
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), triangles));
    checkDevice("rtcSetNewGeometryBuffer");
    for (size_t v = 0; v < m.positions.size(); ++v) {
      vb[3 * v + 0] = m.positions[v].x;
      vb[3 * v + 1] = m.positions[v].y;
      vb[3 * v + 2] = m.positions[v].z;
    }
    std::copy(m.indices.begin(), m.indices.begin() + triangles * 3, ib);
    rtcCommitGeometry(geom);
    rtcAttachGeometryByID(rtcScene, geom, static_cast<unsigned>(mi));
    rtcReleaseGeometry(geom);
    checkDevice("rtcAttachGeometryByID");

    const glm::vec3 emission = mat.emission();
    if (maxComponent(emission) > 0.f) {
      emissiveOffset[mi] = static_cast<int>(triangleLights.size());
      const float sides = mat.doubleSided ? 2.f : 1.f;
      for (size_t t = 0; t < triangles; ++t) {
        const glm::vec3& v0 = m.positions[m.indices[3 * t]];
        const glm::vec3& v1 = m.positions[m.indices[3 * t + 1]];
        const glm::vec3& v2 = m.positions[m.indices[3 * t + 2]];
        const float area = 0.5f * glm::length(glm::cross(v1 - v0, v2 - v0));
        triangleLights.push_back({static_cast<int>(mi), static_cast<int>(t), area});
        // Power ~ pi * area * emitted radiance (max channel, so no coloured emitter gets probability 0).
        lightCdf.push_back(lightCdf.back() + sides * area * maxComponent(emission));
      }
    }
  }
  totalLightPower = lightCdf.back();
  rtcCommitScene(rtcScene);
  checkDevice("rtcCommitScene");
}

PathTracer::PathTracer(const Scene& scene) : impl_(std::make_unique<Impl>(scene)) {}
PathTracer::~PathTracer() = default;
PathTracer::PathTracer(PathTracer&&) noexcept = default;
PathTracer& PathTracer::operator=(PathTracer&&) noexcept = default;

std::uint64_t PathTracer::raysTraced() const { return impl_->lastRays.load(); }

Image PathTracer::render(const Camera& camera, int width, int height, const ReferenceOptions& options) const {
  if (width <= 0 || height <= 0)
    throw std::invalid_argument("PathTracer::render(): image size " + std::to_string(width) + "x" +
                                std::to_string(height) + " is not positive");
  if (options.spp < 1) throw std::invalid_argument("PathTracer::render(): spp must be >= 1");
  if (options.mode != ReferenceOptions::Mode::Radiance && !(options.aoRadius > 0.f))
    throw std::invalid_argument("PathTracer::render(): aoRadius must be > 0");
  if (options.maxBounces < 0) throw std::invalid_argument("PathTracer::render(): maxBounces must be >= 0");

  const Environment env(options);
  const char* aov = options.mode == ReferenceOptions::Mode::Radiance ? "beauty" : "ao";
  Image image = Image::make(aov, width, height, 3);
  const int tilesX = (width + kTileSize - 1) / kTileSize, tilesY = (height + kTileSize - 1) / kTileSize;
  std::atomic<std::uint64_t> rays{0};
  const Impl& impl = *impl_;

  auto renderTiles = [&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, tilesX * tilesY, 1), [&](const tbb::blocked_range<int>& range) {
      RayCounter counter;
      for (int tile = range.begin(); tile != range.end(); ++tile) {
        const int x0 = (tile % tilesX) * kTileSize, y0 = (tile / tilesX) * kTileSize;
        const int x1 = std::min(width, x0 + kTileSize), y1 = std::min(height, y0 + kTileSize);
        for (int y = y0; y < y1; ++y)
          for (int x = x0; x < x1; ++x) {
            const std::uint64_t pixel = static_cast<std::uint64_t>(y) * width + x;
            glm::dvec3 sum(0.0);
            for (int s = 0; s < options.spp; ++s) {
              Sampler sampler(pixel, static_cast<std::uint64_t>(s), options.seed);
              const glm::vec2 jitter = sampler.next2();
              const Ray ray = impl.cameraRay(camera, width, height, x + jitter.x, y + jitter.y);
              glm::vec3 value;
              if (options.mode == ReferenceOptions::Mode::Radiance)
                value = impl.radiance(ray, options, env, sampler, counter);
              else
                value = glm::vec3(impl.ambientOcclusion(ray, options, sampler, counter));
              // A non-finite sample would poison the pixel; it can only come from degenerate input.
              if (std::isfinite(value.x) && std::isfinite(value.y) && std::isfinite(value.z))
                sum += glm::dvec3(value);
            }
            float* out = image.at(x, y);
            const glm::dvec3 mean = sum / static_cast<double>(options.spp);
            out[0] = static_cast<float>(mean.x);
            out[1] = static_cast<float>(mean.y);
            out[2] = static_cast<float>(mean.z);
          }
      }
      rays += counter.rays;
    });
  };
  if (options.threads > 0) {
    tbb::task_arena arena(options.threads);
    arena.execute(renderTiles);
  } else {
    renderTiles();
  }
  impl_->lastRays = rays.load();
  return image;
}

}  // namespace radiant::reference
