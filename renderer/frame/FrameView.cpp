#include "renderer/frame/FrameView.h"

#include "renderer/scene/Environment.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "api/Types.h"

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
  v.lights = scene.lights;
  v.sceneLights = static_cast<int>(scene.lights.size());
  v.media = scene.media;
  v.media.insert(v.media.end(), request.media.begin(), request.media.end());
  if (!v.media.empty()) v.mediaKey = api::mediaDigest(v.media);
  if (environment) {
    v.environment = environment;
    v.environmentKey = request.environment;
    v.ambient = environmentAverage(*environment);
  }
  const float aspect = static_cast<float>(request.width) / static_cast<float>(request.height);
  Camera cam = scene.camera;
  const Bounds& bounds = scene.features.bounds;
  const glm::vec3 center = bounds.center();
  // The point a camera looks at: the bounds centre for the automatic one, else the point on its axis
  // nearest to that centre (at least a unit ahead).
  auto targetOf = [&](const Camera& c) {
    const glm::vec3 eye(c.world[3]), forward = -glm::normalize(glm::vec3(c.world[2]));
    if (!c.fromFile) return bounds.empty() ? eye + forward : center;
    return eye + forward * std::max(glm::dot(center - eye, forward), 1e-3f * std::max(bounds.radius(), 1.f));
  };
  v.cameraSource = scene.camera.fromFile ? "file" : "auto";
  v.target = targetOf(cam);
  if (request.camera) {
    const auto& o = *request.camera;
    const bool whole = (o.hasPosition || o.orbit) && o.hasTarget && o.hasUp && o.hasYfov;
    const float baseYfov = scene.camera.projection == ProjectionType::Perspective ? scene.camera.yfov : 0.6911f;
    const float yfov = o.hasYfov ? glm::radians(o.yfovDegrees) : baseYfov;
    // The camera whose fields the override keeps: the file's, or the automatic framing for this
    // image's aspect and field of view (so a narrower yfov alone moves the camera back to keep the fit).
    const Camera base = scene.camera.fromFile ? scene.camera : defaultCameraFor(bounds, aspect, yfov);
    const glm::vec3 target = o.hasTarget ? o.target : targetOf(base);
    glm::vec3 position = o.hasPosition ? o.position : glm::vec3(base.world[3]);
    if (o.orbit) {
      // model-viewer's camera-orbit (three.js Spherical.setFromSphericalCoords): theta about +Y from +Z
      // towards +X, phi from +Y. Computed in double: a small radius around a far target stays exact.
      const double theta = glm::radians(o.orbit->thetaDeg), phi = glm::radians(o.orbit->phiDeg);
      const double radius = o.orbit->radius > 0 ? o.orbit->radius : glm::length(glm::dvec3(position) - glm::dvec3(target));
      const glm::dvec3 dir(std::sin(phi) * std::sin(theta), std::cos(phi), std::sin(phi) * std::cos(theta));
      position = glm::vec3(glm::dvec3(target) + radius * dir);
      // The eye is stored in single precision: a radius below the target's rounding step would put
      // it on the target, or (one axis surviving) somewhere else on the sphere. Refuse an orbit the
      // stored eye misses by more than 1% of its radius.
      const double reached = glm::length(glm::dvec3(position) - glm::dvec3(target));
      if (!(std::abs(reached - radius) <= 0.01 * radius))
        throw api::ApiError(422, "invalid-value", "Invalid value",
                            "/camera/orbit/radius: too small for the target's single-precision coordinates (the eye "
                            "would land " + std::to_string(reached) + " from the target instead of " + std::to_string(radius) + ")",
                            "/camera/orbit/radius");
    }
    glm::vec3 up = o.hasUp ? o.up : glm::normalize(glm::vec3(base.world[1]));
    if (!(glm::length(target - position) > 0.f))
      throw api::ApiError(422, "invalid-value", "Invalid value",
                          std::string("/camera: the camera position equals its target (") +
                              (o.hasPosition ? "target" : "position") + " taken from the scene camera)",
                          o.hasPosition ? "/camera/position" : "/camera/target");
    const glm::vec3 dir = glm::normalize(target - position);
    if (glm::length(glm::cross(dir, glm::normalize(up))) < 1e-6f) {
      if (o.hasUp)
        throw api::ApiError(422, "invalid-value", "Invalid value", "/camera/up: parallel to the view direction", "/camera/up");
      up = std::abs(dir.y) < 0.99f ? glm::vec3(0, 1, 0) : glm::vec3(0, 0, -1);  // looking straight up or down
    }
    cam = Camera{};
    cam.name = "request";
    cam.projection = ProjectionType::Perspective;
    cam.yfov = yfov;
    cam.world = glm::inverse(glm::lookAt(position, target, up));
    // Near plane relative to the scene size keeps depth precision at any scale.
    cam.znear = std::max(1e-6f, 1e-3f * std::max(bounds.radius(), 1e-6f));
    v.target = target;
    v.cameraSource = whole ? "request" : "request+" + v.cameraSource;
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

glm::vec3 viewForward(const FrameView& view) { return -glm::normalize(glm::vec3(view.camera.world[2])); }

gpu::FrameConstants frameConstants(const FrameView& view) {
  gpu::FrameConstants c;
  c.view = view.view;
  c.proj = view.proj;
  c.viewProj = view.viewProj;
  c.invViewProj = view.invViewProj;
  c.eye = glm::vec4(view.eye, 0.f);
  c.viewForward = glm::vec4(viewForward(view), 0.f);
  c.background = glm::vec4(view.ambient, 0.f);
  c.flags = glm::ivec4(view.camera.projection == ProjectionType::Orthographic ? 1 : 0, view.environment ? 1 : 0, 0, 0);
  return c;
}

}  // namespace radiant
