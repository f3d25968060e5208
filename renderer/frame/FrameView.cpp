#include "renderer/frame/FrameView.h"

#include "renderer/scene/Environment.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

namespace radiant {

glm::mat4 reversedZPerspective(float yfov, float aspect, float znear) {
  const float f = 1.f / std::tan(0.5f * yfov);
  glm::mat4 p(0.f);
  p[0][0] = f / aspect;
  p[1][1] = f;
  p[2][3] = -1.f;   // w_clip = -z_view
  p[3][2] = znear;  // z_clip = znear  ->  depth = znear / -z_view
  return p;
}

glm::mat4 reversedZOrthographic(float xmag, float ymag, float znear, float zfar) {
  glm::mat4 p(1.f);
  p[0][0] = 1.f / xmag;
  p[1][1] = 1.f / ymag;
  // depth = (zfar + z_view) / (zfar - znear): 1 at z_view = -znear, 0 at z_view = -zfar.
  p[2][2] = 1.f / (zfar - znear);
  p[3][2] = zfar / (zfar - znear);
  return p;
}

FrameView makeFrameView(const Scene& scene, const api::RenderRequest& request, const Image* environment) {
  FrameView v;
  v.width = request.width;
  v.height = request.height;
  v.exposure = request.exposure;
  v.seed = request.seed;
  v.ambient = request.ambient;
  if (environment) {
    v.environment = environment;
    v.environmentKey = request.environment;
    v.ambient = environmentAverage(*environment);
  }
  const float aspect = static_cast<float>(request.width) / static_cast<float>(request.height);
  Camera cam = scene.camera;
  if (request.camera) {
    const auto& o = *request.camera;
    cam = Camera{};
    cam.projection = ProjectionType::Perspective;
    cam.yfov = glm::radians(o.yfovDegrees);
    cam.world = glm::inverse(glm::lookAt(o.position, o.target, o.up));
    // Near plane relative to the scene size keeps depth precision at any scale.
    cam.znear = std::max(1e-6f, 1e-3f * std::max(scene.features.bounds.radius(), 1e-6f));
  }
  // The image decides the aspect (glTF allows it; a stretched image is never what a user wants), and
  // the reference renderer receives the same camera.
  cam.aspectRatio = aspect;
  v.camera = cam;
  v.view = glm::inverse(cam.world);
  v.eye = glm::vec3(cam.world[3]);
  if (cam.projection == ProjectionType::Perspective) {
    v.proj = reversedZPerspective(cam.yfov, aspect, cam.znear);
  } else {
    float zfar = cam.zfar > cam.znear ? cam.zfar : cam.znear + 4.f * scene.features.bounds.radius() + 1.f;
    v.proj = reversedZOrthographic(cam.xmag, cam.ymag, cam.znear, zfar);
  }
  v.viewProj = v.proj * v.view;
  v.invViewProj = glm::inverse(v.viewProj);
  return v;
}

}  // namespace radiant
