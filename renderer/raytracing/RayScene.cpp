#include "renderer/raytracing/RayScene.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include <embree3/rtcore.h>

#include "renderer/scene/MaterialDecode.h"

namespace radiant::rt {
namespace {

constexpr float kRayOffsetRelative = 64.f * std::numeric_limits<float>::epsilon();
constexpr float kRayOffsetMinimum = 1e-30f;
constexpr int kMaxAlphaPassThrough = 64;

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

}  // namespace

struct RayScene::Embree {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  ~Embree() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
  void check(const char* call) const {
    const RTCError e = rtcGetDeviceError(device);
    if (e != RTC_ERROR_NONE)
      throw std::runtime_error(std::string("RayScene::RayScene(): ") + call + " failed: Embree error " +
                               std::to_string(static_cast<int>(e)));
  }
};

RayScene::RayScene(const Scene& s) : scene_(&s), embree_(std::make_unique<Embree>()) {
  Embree& e = *embree_;
  e.device = rtcNewDevice(nullptr);
  if (!e.device)
    throw std::runtime_error("RayScene::RayScene(): rtcNewDevice failed: Embree error " +
                             std::to_string(static_cast<int>(rtcGetDeviceError(nullptr))));
  e.scene = rtcNewScene(e.device);
  e.check("rtcNewScene");
  rtcSetSceneFlags(e.scene, RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(e.scene, RTC_BUILD_QUALITY_HIGH);

  emissiveOffset_.assign(s.meshes.size(), -1);
  materialRecords_.reserve(s.meshes.size());
  for (const MeshInstance& m : s.meshes) materialRecords_.push_back(toGpuMaterial(s.material(m.material)));
  for (size_t mi = 0; mi < s.meshes.size(); ++mi) {
    const MeshInstance& m = s.meshes[mi];
    const size_t triangles = m.triangleCount();
    if (triangles == 0 || m.positions.empty()) continue;
    for (std::uint32_t idx : m.indices)
      if (idx >= m.positions.size())
        throw std::invalid_argument("RayScene::RayScene(): mesh '" + m.name + "' index " + std::to_string(idx) +
                                    " >= vertex count " + std::to_string(m.positions.size()));
    const Material& mat = s.material(m.material);
    if (mat.alphaMode != AlphaMode::Opaque) anyAlpha_ = true;

    RTCGeometry geom = rtcNewGeometry(e.device, RTC_GEOMETRY_TYPE_TRIANGLE);
    e.check("rtcNewGeometry");
    auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                           3 * sizeof(float), m.positions.size()));
    auto* ib = static_cast<unsigned*>(
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), triangles));
    e.check("rtcSetNewGeometryBuffer");
    for (size_t v = 0; v < m.positions.size(); ++v) {
      vb[3 * v + 0] = m.positions[v].x;
      vb[3 * v + 1] = m.positions[v].y;
      vb[3 * v + 2] = m.positions[v].z;
    }
    std::copy(m.indices.begin(), m.indices.begin() + triangles * 3, ib);
    rtcCommitGeometry(geom);
    rtcAttachGeometryByID(e.scene, geom, static_cast<unsigned>(mi));
    rtcReleaseGeometry(geom);
    e.check("rtcAttachGeometryByID");

    if (maxComponent(mat.emission()) > 0.f) {
      emissiveOffset_[mi] = static_cast<int>(triangleLights_.size());
      for (size_t t = 0; t < triangles; ++t) {
        const glm::vec3& v0 = m.positions[m.indices[3 * t]];
        const glm::vec3& v1 = m.positions[m.indices[3 * t + 1]];
        const glm::vec3& v2 = m.positions[m.indices[3 * t + 2]];
        triangleLights_.push_back(
            {static_cast<int>(mi), static_cast<int>(t), 0.5f * glm::length(glm::cross(v1 - v0, v2 - v0))});
      }
    }
  }
  rtcCommitScene(e.scene);
  e.check("rtcCommitScene");
}

RayScene::~RayScene() = default;

glm::vec4 RayScene::textureAt(const TextureRef& ref, const SurfaceHit& h, bool srgb) const {
  if (!ref.valid() || ref.texture >= static_cast<int>(scene_->textures.size())) return glm::vec4(1.f);
  const MeshInstance& m = scene_->meshes[h.mesh];
  const auto& uvs = ref.texCoord == 1 ? m.uv1 : m.uv0;
  glm::vec2 uv(0.f);
  if (!uvs.empty()) {
    const std::uint32_t* i = &m.indices[static_cast<size_t>(h.prim) * 3];
    uv = h.b0 * uvs[i[0]] + h.b1 * uvs[i[1]] + h.b2 * uvs[i[2]];
  }
  // KHR_texture_transform (identity rows without it): the rows GLSL's materialSlotUv applies.
  return sampleTexture(scene_->textures[ref.texture], ref.transformUv(uv), srgb);
}

glm::vec3 RayScene::unlitRadiance(const SurfaceHit& h) const {
  return decodeUnlitRadiance(materialRecordOf(h.mesh), materialOf(h.mesh),
                             [&](const TextureRef& ref, bool srgb) { return textureAt(ref, h, srgb); });
}

glm::vec3 RayScene::emissionAt(const SurfaceHit& h, const glm::vec3& dir) const {
  const Material& mat = materialOf(h.mesh);
  if (!mat.isEmissive()) return glm::vec3(0.f);
  if (!mat.doubleSided && glm::dot(dir, h.ng) >= 0.f) return glm::vec3(0.f);
  return decodeEmission(materialRecordOf(h.mesh), mat,
                        [&](const TextureRef& ref, bool srgb) { return textureAt(ref, h, srgb); });
}

SurfaceHit RayScene::makeHit(int mesh, int prim, float u, float v, const glm::vec3& origin) const {
  SurfaceHit h;
  h.mesh = mesh;
  h.prim = prim;
  h.b1 = u;
  h.b2 = v;
  h.b0 = 1.f - h.b1 - h.b2;
  const MeshInstance& m = scene_->meshes[h.mesh];
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

SurfaceHit RayScene::pointOn(int mesh, int prim, glm::vec2 b) const {
  SurfaceHit h = makeHit(mesh, prim, b.y, 1.f - b.x - b.y, glm::vec3(0.f));
  h.distance = 0.f;
  return h;
}

glm::vec3 RayScene::offsetOrigin(const glm::vec3& p, const glm::vec3& ng, float scale, const glm::vec3& dir) {
  const float eps = std::max(kRayOffsetRelative * scale, kRayOffsetMinimum);
  return p + (glm::dot(dir, ng) >= 0.f ? eps : -eps) * ng;
}

bool RayScene::intersect(Ray ray, SurfaceHit& hit, Sampler& sampler, RayCounter& counter) const {
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
    rtcIntersect1(embree_->scene, &ctx, &rh);
    ++counter.rays;
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
    hit = makeHit(static_cast<int>(rh.hit.geomID), static_cast<int>(rh.hit.primID), rh.hit.u, rh.hit.v, origin);
    if (!anyAlpha_ || !passesThrough(hit, sampler)) return true;
    const float travelled = rh.ray.tfar;
    ray.org = offsetOrigin(hit.p, hit.ng, hit.offsetScale, ray.dir);
    ray.tnear = 0.f;
    ray.tfar = ray.tfar == kInf ? kInf : std::max(0.f, ray.tfar - travelled);
  }
  return false;
}

bool RayScene::passesThrough(const SurfaceHit& hit, Sampler& sampler) const {
  const Material& mat = materialOf(hit.mesh);
  if (mat.alphaMode == AlphaMode::Opaque) return false;
  const float a = decodeBaseColor(materialRecordOf(hit.mesh), mat, [&](const TextureRef& ref, bool srgb) {
                    return textureAt(ref, hit, srgb);
                  }).a;
  if (mat.alphaMode == AlphaMode::Mask) return a < mat.alphaCutoff;
  return sampler.next() >= a;  // Blend: stochastic coverage
}

bool RayScene::occluded(const Ray& ray, Sampler& sampler, RayCounter& counter) const {
  if (anyAlpha_) {
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
  rtcOccluded1(embree_->scene, &ctx, &r);
  ++counter.rays;
  return r.tfar < 0.f;  // Embree sets tfar = -inf on a hit
}

Shading RayScene::shade(const SurfaceHit& hit, const glm::vec3& wo, TransportMode mode) const {
  const Material& mat = materialOf(hit.mesh);
  const MeshInstance& m = scene_->meshes[hit.mesh];
  Shading s;
  // Factors x textures: the shared decoder (shaders/common/material_decode.glsl, MaterialDecode.h).
  const gpu::MaterialParams params = decodeBsdfInputs(
      materialRecordOf(hit.mesh), mat, [&](const TextureRef& ref, bool srgb) { return textureAt(ref, hit, srgb); });
  s.bsdf = GltfBsdf::fromParams(params, mode);
  const bool front = glm::dot(wo, hit.ng) >= 0.f;
  s.bsdf.eta = front ? s.bsdf.ior : 1.f / s.bsdf.ior;
  s.ngFacing = front ? hit.ng : -hit.ng;

  // Shading normal: interpolated vertex normal, normal-mapped when a tangent frame exists
  // (material_decode.glsl's mapTangentNormal, as material.glsl's decodeShadingNormal).
  glm::vec3 ns = hit.ng;
  // KHR_materials_clearcoat: the interpolated normal, or its own clearcoatNormalTexture (decodeCoatNormal
  // of material.glsl), never the base's normal map.
  glm::vec3 coat = s.ngFacing;
  const std::uint32_t* i = &m.indices[static_cast<size_t>(hit.prim) * 3];
  if (m.normals.size() == m.positions.size()) {
    const glm::vec3 n = hit.b0 * m.normals[i[0]] + hit.b1 * m.normals[i[1]] + hit.b2 * m.normals[i[2]];
    if (glm::dot(n, n) > 0.f) ns = glm::normalize(n);
    // Vertex normals inconsistent with the winding are turned to its side before normal mapping (as
    // material.glsl's windingSideNormal), so that a mapped normal tilted past the geometric horizon stays
    // where the map put it instead of being mirrored.
    if (glm::dot(ns, hit.ng) < 0.f) ns = -ns;
    coat = ns;
    if (mat.hasNormalMap() && m.tangents.size() == m.positions.size()) {
      const glm::vec4 t4 = hit.b0 * m.tangents[i[0]] + hit.b1 * m.tangents[i[1]] + hit.b2 * m.tangents[i[2]];
      const glm::vec4 frame(glm::vec3(t4), m.tangents[i[0]].w);
      const glm::vec3 interpolated = ns;
      if (mat.normalTexture.valid())
        ns = mapTangentNormal(textureAt(mat.normalTexture, hit, false), mat.normalTexture.scale, interpolated, frame);
      if (mat.clearcoatNormalTexture.valid())
        coat = mapTangentNormal(textureAt(mat.clearcoatNormalTexture, hit, false), mat.clearcoatNormalTexture.scale,
                                interpolated, frame);
    }
    if (!front) ns = -ns;
    if (!front) coat = -coat;
    // wo under (or at) the shading hemisphere: bend the normal towards wo until n.wo = 1e-3, as every
    // GLSL consumer does (direct.frag, transparency.frag, photon_gi's surface.glsl), not replace it.
    auto towardsViewer = [&](glm::vec3 n) {
      const float nv = glm::dot(n, wo);
      return nv < 1e-3f ? glm::normalize(n + wo * (1e-3f - nv)) : n;
    };
    ns = towardsViewer(ns);
    coat = towardsViewer(coat);
  } else {
    ns = s.ngFacing;
  }
  s.frame = ShadingFrame::fromNormal(ns);
  s.bsdf.coatNormal = s.frame.toLocal(coat);
  return s;
}

}  // namespace radiant::rt
