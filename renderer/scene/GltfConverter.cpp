#include "renderer/scene/GltfConverter.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <nlohmann/json.hpp>

#include "api/Media.h"
#include "api/Types.h"
#include "api/Validate.h"
#include "renderer/scene/GltfAccessors.h"
#include "renderer/scene/GltfLoader.h"

namespace radiant::gltf {

namespace {

glm::mat4 localMatrix(const tinygltf::Node& node) {
  if (node.matrix.size() == 16) {
    glm::mat4 m;
    for (int i = 0; i < 16; ++i) glm::value_ptr(m)[i] = float(node.matrix[std::size_t(i)]);  // column major
    return m;
  }
  glm::mat4 m(1.f);
  if (node.translation.size() == 3)
    m = glm::translate(m, glm::vec3(node.translation[0], node.translation[1], node.translation[2]));
  if (node.rotation.size() == 4)  // glTF stores x, y, z, w
    m *= glm::mat4_cast(glm::normalize(glm::quat(float(node.rotation[3]), float(node.rotation[0]),
                                                 float(node.rotation[1]), float(node.rotation[2]))));
  if (node.scale.size() == 3)
    m = glm::scale(m, glm::vec3(node.scale[0], node.scale[1], node.scale[2]));
  return m;
}

// The camera's rotation and translation with any scale or shear removed (a view matrix must be rigid).
glm::mat4 rigid(const glm::mat4& m) {
  glm::vec3 x(m[0]), y(m[1]), z(m[2]);
  z = glm::length(z) > 0.f ? glm::normalize(z) : glm::vec3(0, 0, 1);
  x = x - z * glm::dot(z, x);
  x = glm::length(x) > 0.f ? glm::normalize(x) : anyPerpendicular(z);
  y = glm::cross(z, x);
  glm::mat4 r(1.f);
  r[0] = glm::vec4(x, 0); r[1] = glm::vec4(y, 0); r[2] = glm::vec4(z, 0); r[3] = m[3];
  return r;
}

}  // namespace

// ---- model -> scene -------------------------------------------------------------------------

const tinygltf::Value* extension(const tinygltf::ExtensionMap& ext, const char* name) {
  const auto it = ext.find(name);
  return it != ext.end() && it->second.IsObject() ? &it->second : nullptr;
}

float number(const tinygltf::Value& v, const char* key, float fallback) {
  return v.Has(key) && v.Get(key).IsNumber() ? float(v.Get(key).GetNumberAsDouble()) : fallback;
}

namespace {

// A tinygltf extension value as JSON, so the request's schema validator can check it.
nlohmann::json toJson(const tinygltf::Value& v) {
  if (v.IsBool()) return v.Get<bool>();
  if (v.IsInt()) return v.Get<int>();
  if (v.IsNumber()) return v.GetNumberAsDouble();
  if (v.IsString()) return v.Get<std::string>();
  if (v.IsArray()) {
    nlohmann::json a = nlohmann::json::array();
    for (std::size_t i = 0; i < v.ArrayLen(); ++i) a.push_back(toJson(v.Get(int(i))));
    return a;
  }
  if (v.IsObject()) {
    nlohmann::json o = nlohmann::json::object();
    for (const auto& k : v.Keys()) o[k] = toJson(v.Get(k));
    return o;
  }
  return nullptr;
}

// Particles of all RADIANT_particle_system nodes of one file together.
constexpr std::size_t kMaxSceneParticles = std::size_t(1) << 20;

}  // namespace

Scene Converter::run() {
  convertTextures();
  convertMaterials();
  walkScene();
  if (!scene_.camera.fromFile) scene_.camera = defaultCameraFor(sceneBounds(), 1.f);
  return std::move(scene_);
}

void Converter::walkScene() {
  std::vector<int> roots;
  if (!m_.scenes.empty()) {
    const std::size_t s = m_.defaultScene >= 0 ? std::size_t(m_.defaultScene) : 0;
    if (s >= m_.scenes.size()) throw SceneError("/scene", "the default scene does not exist");
    scene_.name = m_.scenes[s].name;
    for (std::size_t k = 0; k < m_.scenes[s].nodes.size(); ++k) {
      const int n = m_.scenes[s].nodes[k];
      if (n < 0 || std::size_t(n) >= m_.nodes.size())
        throw SceneError(pointer(pointer("/scenes", s) + "/nodes", k),
                         "node " + std::to_string(n) + " does not exist");
      roots.push_back(n);
    }
  } else {
    // No scenes: render every node that is nobody's child.
    std::vector<bool> isChild(m_.nodes.size(), false);
    for (const auto& n : m_.nodes)
      for (int c : n.children)
        if (c >= 0 && std::size_t(c) < m_.nodes.size()) isChild[std::size_t(c)] = true;
    for (std::size_t i = 0; i < m_.nodes.size(); ++i)
      if (!isChild[i]) roots.push_back(int(i));
  }
  std::vector<bool> visited(m_.nodes.size(), false);
  // Depth first, in document order, so "the first camera" is well defined.
  std::vector<std::pair<int, glm::mat4>> stack;
  for (auto it = roots.rbegin(); it != roots.rend(); ++it) stack.emplace_back(*it, glm::mat4(1.f));
  while (!stack.empty()) {
    const auto [index, parent] = stack.back();
    stack.pop_back();
    const std::string ptr = pointer("/nodes", std::size_t(index));
    if (visited[std::size_t(index)])
      throw SceneError(ptr, "node " + std::to_string(index) +
                                " appears twice in the hierarchy (a cycle or a shared child)");
    visited[std::size_t(index)] = true;
    const auto& node = m_.nodes[std::size_t(index)];
    const glm::mat4 world = parent * localMatrix(node);
    visitNode(index, node, world, ptr);
    for (std::size_t k = node.children.size(); k-- > 0;) {
      const int c = node.children[k];
      if (c < 0 || std::size_t(c) >= m_.nodes.size())
        throw SceneError(pointer(ptr + "/children", k), "child node " + std::to_string(c) + " does not exist");
      stack.emplace_back(c, world);
    }
  }
}

void Converter::visitNode(int index, const tinygltf::Node& node, const glm::mat4& world, const std::string& ptr) {
  scene_.nodeNames.push_back(node.name);
  if (node.mesh >= 0) {
    if (std::size_t(node.mesh) >= m_.meshes.size())
      throw SceneError(ptr + "/mesh", "mesh " + std::to_string(node.mesh) + " does not exist");
    const auto& mesh = m_.meshes[std::size_t(node.mesh)];
    for (std::size_t p = 0; p < mesh.primitives.size(); ++p)
      addPrimitive(index, node, node.mesh, int(p), world);
  }
  if (node.camera >= 0 && !scene_.camera.fromFile) addCamera(node, world, ptr);
  if (const auto* e = extension(node.extensions, "KHR_lights_punctual")) addLight(*e, world, ptr);
  if (const auto* e = extension(node.extensions, "RADIANT_particle_system")) addParticleSystem(*e, world, ptr);
}

// RADIANT_particle_system (api/schema/media.json, "gltf_particles"): the request's particle-system
// schema with particles as accessors, in node-local space.
void Converter::addParticleSystem(const tinygltf::Value& e, const glm::mat4& world, const std::string& ptr) {
  const std::string eptr = ptr + "/extensions/RADIANT_particle_system";
  nlohmann::json system;
  try {
    system = api::validate(api::gltfMediaSchema(), toJson(e), eptr);
  } catch (const api::ApiError& err) {
    throw SceneError(err.pointer, err.detail());
  }
  api::ParticleColumns columns;
  const bool explicitParticles = system.contains("particles");
  if (explicitParticles) {
    const nlohmann::json& p = system["particles"];
    const std::string pp = eptr + "/particles";
    auto accessor = [&](const char* key) { return p[key].get<int>(); };
    columns.positions = asVec3(readFloats(m_, accessor("positions"), TINYGLTF_TYPE_VEC3, pp + "/positions", maxBytes_));
    columns.radii = readFloats(m_, accessor("radii"), TINYGLTF_TYPE_SCALAR, pp + "/radii", maxBytes_);
    if (p.contains("tau")) columns.tau = readFloats(m_, accessor("tau"), TINYGLTF_TYPE_SCALAR, pp + "/tau", maxBytes_);
    if (p.contains("albedo"))
      columns.albedo = asVec3(readFloats(m_, accessor("albedo"), TINYGLTF_TYPE_VEC3, pp + "/albedo", maxBytes_));
    if (p.contains("temperature"))
      columns.temperature =
          readFloats(m_, accessor("temperature"), TINYGLTF_TYPE_SCALAR, pp + "/temperature", maxBytes_);
    const std::size_t n = columns.positions.size();
    for (const auto& [key, size] : {std::pair<const char*, std::size_t>{"radii", columns.radii.size()},
                                    {"tau", columns.tau.size()}, {"albedo", columns.albedo.size()},
                                    {"temperature", columns.temperature.size()}})
      if (p.contains(key) && size != n)
        throw SceneError(pp + "/" + key, std::string(key) + " has " + std::to_string(size) +
                                             " elements, positions has " + std::to_string(n));
  }
  std::size_t used = 0;
  for (const auto& s : scene_.media) used += s.particles.size();
  api::ParticleSystem ps;
  try {
    ps = api::makeParticleSystem(system, explicitParticles ? &columns : nullptr, eptr,
                                 used < kMaxSceneParticles ? kMaxSceneParticles - used : 0);
  } catch (const api::ApiError& err) {
    throw SceneError(err.pointer, err.detail());
  }
  // Node-local to world: centres through the matrix, radii by its largest axis scale.
  const float scale = std::max({glm::length(glm::vec3(world[0])), glm::length(glm::vec3(world[1])),
                                glm::length(glm::vec3(world[2]))});
  for (auto& p : ps.particles) {
    p.position = glm::vec3(world * glm::vec4(p.position, 1.f));
    p.radius *= scale;
  }
  if (ps.name.empty()) ps.name = scene_.nodeNames.back();
  scene_.media.push_back(std::move(ps));
}

void Converter::addCamera(const tinygltf::Node& node, const glm::mat4& world, const std::string& ptr) {
  if (std::size_t(node.camera) >= m_.cameras.size())
    throw SceneError(ptr + "/camera", "camera " + std::to_string(node.camera) + " does not exist");
  const auto& c = m_.cameras[std::size_t(node.camera)];
  const std::string cptr = pointer("/cameras", std::size_t(node.camera));
  Camera cam;
  cam.name = !c.name.empty() ? c.name : node.name;
  if (c.type == "perspective") {
    cam.projection = ProjectionType::Perspective;
    if (!(c.perspective.yfov > 0.0) || !(c.perspective.znear > 0.0))
      throw SceneError(cptr + "/perspective", "a perspective camera needs yfov > 0 and znear > 0");
    cam.yfov = float(c.perspective.yfov);
    cam.aspectRatio = float(c.perspective.aspectRatio);
    cam.znear = float(c.perspective.znear);
    cam.zfar = float(c.perspective.zfar);
  } else if (c.type == "orthographic") {
    cam.projection = ProjectionType::Orthographic;
    if (c.orthographic.xmag == 0.0 || c.orthographic.ymag == 0.0 ||
        !(c.orthographic.zfar > c.orthographic.znear))
      throw SceneError(cptr + "/orthographic",
                       "an orthographic camera needs non-zero xmag and ymag and zfar > znear");
    cam.xmag = float(c.orthographic.xmag);
    cam.ymag = float(c.orthographic.ymag);
    cam.znear = float(c.orthographic.znear);
    cam.zfar = float(c.orthographic.zfar);
  } else {
    throw SceneError(cptr + "/type", "unknown camera type \"" + c.type + "\"");
  }
  cam.world = rigid(world);
  cam.fromFile = true;
  scene_.camera = cam;
}

void Converter::addLight(const tinygltf::Value& e, const glm::mat4& world, const std::string& ptr) {
  if (!e.Has("light") || !e.Get("light").IsNumber())
    throw SceneError(ptr + "/extensions/KHR_lights_punctual/light", "the node names no light");
  const int li = e.Get("light").GetNumberAsInt();
  if (li < 0 || std::size_t(li) >= m_.lights.size())
    throw SceneError(ptr + "/extensions/KHR_lights_punctual/light",
                     "light " + std::to_string(li) + " does not exist");
  const auto& g = m_.lights[std::size_t(li)];
  const std::string lptr = pointer("/extensions/KHR_lights_punctual/lights", std::size_t(li));
  Light l;
  l.name = g.name;
  if (g.type == "point") l.type = LightType::Point;
  else if (g.type == "spot") l.type = LightType::Spot;
  else if (g.type == "directional") l.type = LightType::Directional;
  else throw SceneError(lptr + "/type", "unknown light type \"" + g.type + "\"");
  if (g.color.size() == 3) l.color = glm::vec3(g.color[0], g.color[1], g.color[2]);
  l.intensity = float(g.intensity);
  l.range = float(g.range);
  if (l.type == LightType::Spot) {
    l.innerConeAngle = float(g.spot.innerConeAngle);
    l.outerConeAngle = float(g.spot.outerConeAngle);
  }
  l.position = glm::vec3(world * glm::vec4(0, 0, 0, 1));
  const glm::vec3 d = glm::mat3(world) * glm::vec3(0, 0, -1);
  l.direction = glm::length(d) > 0.f ? glm::normalize(d) : glm::vec3(0, 0, -1);
  scene_.lights.push_back(l);
}

Bounds Converter::sceneBounds() const {
  Bounds b;
  for (const auto& m : scene_.meshes) b.extend(m.bounds);
  return b;
}

}  // namespace radiant::gltf
