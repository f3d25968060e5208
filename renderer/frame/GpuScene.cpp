#include "renderer/frame/GpuScene.h"

#include "renderer/raytracing/Bsdf.h"
#include "renderer/scene/MeshLod.h"

#include <atomic>
#include <cmath>
#include <string>

namespace radiant {

gpu::Light toGpuLight(const Light& l) {
  gpu::Light g{};
  const int type = l.type == LightType::Directional ? gpu::kLightDirectional
                 : l.type == LightType::Point       ? gpu::kLightPoint
                                                    : gpu::kLightSpot;
  g.positionType = glm::vec4(l.position, static_cast<float>(type));
  g.directionRange = glm::vec4(glm::normalize(l.direction), l.range);
  g.radiantIntensity = glm::vec4(l.color * l.intensity, 0.f);
  // KHR_lights_punctual: the smooth falloff runs between cos(outer) and cos(inner).
  g.spotCone = glm::vec4(std::cos(l.outerConeAngle), std::cos(l.innerConeAngle), l.angularRadius, 0.f);
  return g;
}

namespace {

template <class T>
gl::Buffer makeBuffer(const std::string& label, const std::vector<T>& data) {
  return gl::Buffer(label, data.size() * sizeof(T), data.data(), 0);
}

}  // namespace

namespace {
std::string nextSceneKey(const Scene& scene) {
  static std::atomic<std::uint64_t> generation{0};
  return (scene.digest.empty() ? std::string("unnamed") : scene.digest) + "#" + std::to_string(++generation);
}
}  // namespace

std::size_t GpuScene::estimateBytes(const Scene& scene) {
  std::size_t bytes = 0;
  for (const Texture& t : scene.textures) bytes += std::size_t(t.width) * std::size_t(t.height) * 4 * 4 / 3;
  constexpr std::size_t kVertexBytes = 2 * sizeof(glm::vec3) + 2 * sizeof(glm::vec2) + sizeof(glm::vec4);
  for (const MeshInstance& mi : scene.meshes)
    bytes += mi.positions.size() * kVertexBytes + 2 * mi.indices.size() * sizeof(std::uint32_t);
  return bytes;
}

GpuScene::GpuScene(const Scene& scene, const rt::Cancel& cancel) : sceneKey(nextSceneKey(scene)) {
  // Textures: colour textures are sampled through sRGB formats so the hardware linearises them.
  std::map<std::pair<int, bool>, int> textureIndex;
  auto gpuTexture = [&](const TextureRef& ref, bool srgb) -> int {
    if (!ref.valid() || ref.texture >= static_cast<int>(scene.textures.size())) return -1;
    auto key = std::make_pair(ref.texture, srgb);
    if (auto it = textureIndex.find(key); it != textureIndex.end()) return it->second;
    const Texture& t = scene.textures[ref.texture];
    const int levels = 1 + static_cast<int>(std::floor(std::log2(std::max(1, std::max(t.width, t.height)))));
    gl::Texture tex("scene texture " + t.name, GL_TEXTURE_2D, srgb ? GL_SRGB8_ALPHA8 : GL_RGBA8,
                    t.width, t.height, 1, levels);
    // glTF's uv (0,0) is the top-left texel, which is the first row in memory: uploading rows in
    // file order and sampling with the uv as given is therefore consistent (no flip).
    tex.upload(0, 0, 0, 0, t.width, t.height, 1, GL_RGBA, GL_UNSIGNED_BYTE, t.rgba8.data());
    tex.generateMipmaps();
    const bool mipmapped = t.minFilter == GL_NEAREST_MIPMAP_NEAREST || t.minFilter == GL_LINEAR_MIPMAP_NEAREST ||
                           t.minFilter == GL_NEAREST_MIPMAP_LINEAR || t.minFilter == GL_LINEAR_MIPMAP_LINEAR;
    tex.setFilter(mipmapped || t.minFilter == GL_LINEAR || t.minFilter == GL_NEAREST ? static_cast<GLenum>(t.minFilter)
                                                                                      : GL_LINEAR_MIPMAP_LINEAR,
                  t.magFilter == GL_NEAREST ? GL_NEAREST : GL_LINEAR);
    glTextureParameteri(tex.id(), GL_TEXTURE_WRAP_S, t.wrapS);
    glTextureParameteri(tex.id(), GL_TEXTURE_WRAP_T, t.wrapT);
    textures.push_back(std::move(tex));
    textureIndex[key] = static_cast<int>(textures.size()) - 1;
    return textures.back() ? static_cast<int>(textures.size()) - 1 : -1;
  };

  std::vector<gpu::Material> mats;
  for (const Material& m : scene.materials) mats.push_back(toGpuMaterial(m));
  const int defaultMaterial = static_cast<int>(mats.size());
  mats.push_back(toGpuMaterial(Material{}));
  materials = makeBuffer("materials", mats);

  lodBaseError = radiant::lodBaseError(scene.features.bounds);
  for (const MeshInstance& mi : scene.meshes) {
    cancel.check("the scene's upload (gpu_scene)");
    GpuMesh g;
    const std::size_t n = mi.positions.size();
    const std::string label = "mesh " + mi.name;
    g.positions = makeBuffer(label + " positions", mi.positions);
    std::vector<glm::vec3> normals = mi.normals;
    normals.resize(n, glm::vec3(0.f, 1.f, 0.f));
    g.normals = makeBuffer(label + " normals", normals);
    // Absent attributes get zero-filled buffers so every program sees the same vertex layout.
    std::vector<glm::vec2> uv0 = mi.uv0, uv1 = mi.uv1;
    uv0.resize(n, glm::vec2(0.f));
    uv1.resize(n, glm::vec2(0.f));
    g.uv0 = makeBuffer(label + " uv0", uv0);
    g.uv1 = makeBuffer(label + " uv1", uv1);
    std::vector<glm::vec4> tangents = mi.tangents;
    tangents.resize(n, glm::vec4(1.f, 0.f, 0.f, 1.f));
    g.tangents = makeBuffer(label + " tangents", tangents);
    g.indices = makeBuffer(label + " indices", mi.indices);
    g.indexCount = static_cast<GLsizei>(mi.indices.size());
    // One vertex layout for the mesh and its levels of detail (the same vertices, other indices).
    auto vertexArray = [&g](const std::string& name, const gl::Buffer& indices) {
      gl::VertexArray vao(name);
      vao.attribute(0, 0, g.positions, 3, sizeof(glm::vec3));
      vao.attribute(1, 1, g.normals, 3, sizeof(glm::vec3));
      vao.attribute(2, 2, g.uv0, 2, sizeof(glm::vec2));
      vao.attribute(3, 3, g.uv1, 2, sizeof(glm::vec2));
      vao.attribute(4, 4, g.tangents, 4, sizeof(glm::vec4));
      vao.elements(indices);
      return vao;
    };
    g.vao = vertexArray(label, g.indices);
    for (MeshLodLevel& level : buildMeshLods(mi, lodBaseError)) {
      GpuMesh::Lod lod;
      lod.indices = makeBuffer(label + " lod indices", level.indices);
      lod.indexCount = static_cast<GLsizei>(level.indices.size());
      lod.error = level.error;
      lod.vao = vertexArray(label + " lod", lod.indices);
      g.lods.push_back(std::move(lod));
    }
    g.material = mi.material >= 0 && mi.material < defaultMaterial ? mi.material : defaultMaterial;
    const Material& m = scene.material(mi.material);
    const auto slots = materialTextureSlots(m);
    for (int s = 0; s < gpu::kSlotCount; ++s) g.textures[s] = gpuTexture(*slots[s], materialSlotIsSrgb(s));
    triangles += mi.triangleCount();
    meshes.push_back(std::move(g));
  }

  for (const Light& l : scene.lights) lightData.push_back(toGpuLight(l));
  if (lightData.empty()) lightData.push_back(gpu::Light{});  // a zero-size SSBO is not bindable
  lights = gl::Buffer("lights", lightData.size() * sizeof(gpu::Light), lightData.data(), 0);
  sheenAlbedo = gl::Buffer("sheen albedo", sizeof(float) * gpu::kSheenAlbedoSize * gpu::kSheenAlbedoSize,
                           rt::sheenAlbedoTable(), 0);
  gl::checkError("GpuScene upload");
}

void GpuScene::bindSceneBuffers() const {
  bindMaterialBuffers();
  lights.bindBase(GL_SHADER_STORAGE_BUFFER, kLightBinding);
}

void GpuScene::bindMaterialBuffers() const {
  materials.bindBase(GL_SHADER_STORAGE_BUFFER, kMaterialBinding);
  sheenAlbedo.bindBase(GL_SHADER_STORAGE_BUFFER, gpu::kBindingSheenAlbedo);
}

void GpuScene::bindMaterialTextures(std::size_t meshIndex) const {
  const GpuMesh& m = meshes[meshIndex];
  for (int s = 0; s < gpu::kSlotCount; ++s)
    if (m.textures[s] >= 0) textures[m.textures[s]].bindUnit(gpu::materialTextureUnit(s));
}

void GpuScene::draw(const gl::Program& program, bool withTextures) const {
  drawMeshes(program, withTextures, [](std::size_t) { return true; });
}

std::size_t GpuScene::drawMeshes(const gl::Program& program, bool withTextures,
                                 const std::function<bool(std::size_t meshIndex)>& select,
                                 const std::function<float(std::size_t meshIndex)>& allowance) const {
  // Not the lights: a pass may have bound the frame's (the scene's and the environment's,
  // bindDirectLighting) for the program it draws with.
  bindMaterialBuffers();
  const GLint materialLoc = program.uniformLocation("u_material");
  std::size_t drawn = 0;
  for (std::size_t i = 0; i < meshes.size(); ++i) {
    if (!select(i)) continue;
    const GpuMesh& m = meshes[i];
    if (materialLoc >= 0) glProgramUniform1i(program.id(), materialLoc, m.material);
    if (withTextures) bindMaterialTextures(i);
    const GpuMesh::Lod* lod = nullptr;
    if (allowance && !m.lods.empty()) {
      const float allowed = allowance(i);
      for (const GpuMesh::Lod& l : m.lods)
        if (l.error <= allowed) lod = &l;
    }
    (lod ? lod->vao : m.vao).bind();
    const GLsizei count = lod ? lod->indexCount : m.indexCount;
    glDrawElements(GL_TRIANGLES, count, GL_UNSIGNED_INT, nullptr);
    drawn += static_cast<std::size_t>(count) / 3;
  }
  return drawn;
}

}  // namespace radiant
