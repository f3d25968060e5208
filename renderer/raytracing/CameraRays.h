#pragma once
// The glTF camera as the ray-tracing core sees it, in both directions:
// - ray(px, py): the primary ray through image position (px, py) (pixels, row 0 = top), for the path
//   tracer;
// - connect(p): the pixel that sees the world point p, the shadow ray back to the camera, and the
//   camera's importance at p, for the light tracer (Veach 1997 §10.3, pbrt-v4 `PerspectiveCamera::Wi`).
//
// Pixel measure: a pixel's value is the mean radiance over its area on the image plane (a box filter),
// which is what the path tracer's uniform jitter estimates. With image-plane coordinates q at view
// depth 1 (tan space, so the plane spans [-tan(yfov/2) aspect, +..] x [-tan(yfov/2), +..]) and the
// direction d(q) = M (q, -1) (M = the camera's rotation and scale), the pixel value is
//   I_j = 1/A_pixel \int_pixel L(d(q)) dq,   dq = |M q'|^3 / |det M| dw   (q' = (q, -1)),
// the solid angle of the plane element dq seen from the eye (|q'|^3 = 1/cos^3 for an orthonormal M).
// A surface point p at distance r seen under |cos_p| subtends dw = |cos_p| dA / r^2, so a particle of
// flux beta scattering towards the eye adds
//   beta f |cos_p| |M q'|^3 / (|det M| A_pixel r^2)
// to pixel j; connect() returns every factor but beta f |cos_p| as `importance`.
// Orthographic: I_j = 1/A_pixel \int_pixel L dq over the plane z = 0 of the camera, dq = |cos_p| dA /
// |(M x) x (M y) . d| (the plane element's world area projected along the view direction), so
// importance = 1 / (A_pixel |(M x) x (M y) . d|).
// Visibility: the path tracer's primary rays start at view depth znear (in the camera's local units),
// so connect() rejects points nearer than znear, and the shadow ray ends there.
#include <algorithm>
#include <cmath>

#include <glm/glm.hpp>

#include "renderer/raytracing/RayScene.h"
#include "renderer/scene/Scene.h"

namespace radiant::rt {

class CameraRays {
public:
  CameraRays(const Camera& cam, int width, int height)
      : cam_(cam), width_(width), height_(height), rot_(cam.world), org_(cam.world[3]),
        invWorld_(glm::inverse(cam.world)) {
    aspect_ = cam.aspectRatio > 0.f ? cam.aspectRatio : static_cast<float>(width) / height;
    tanY_ = std::tan(0.5f * cam.yfov);
    const glm::vec3 forward = rot_ * glm::vec3(0.f, 0.f, -1.f);
    forwardLength_ = glm::length(forward);
    forward_ = forward / forwardLength_;
    detM_ = std::abs(glm::determinant(rot_));
    if (cam.projection == ProjectionType::Orthographic) {
      pixelArea_ = (2.f * cam.xmag / width) * (2.f * cam.ymag / height);
      const glm::vec3 mx = rot_ * glm::vec3(1.f, 0.f, 0.f), my = rot_ * glm::vec3(0.f, 1.f, 0.f);
      orthoProjectedArea_ = std::abs(glm::dot(glm::cross(mx, my), forward_));
    } else {
      pixelArea_ = (2.f * tanY_ * aspect_ / width) * (2.f * tanY_ / height);
    }
  }

  bool orthographic() const { return cam_.projection == ProjectionType::Orthographic; }

  // The primary ray through image position (px, py) in pixels (row 0 = top), starting at view depth znear.
  Ray ray(float px, float py) const {
    const float sx = 2.f * px / width_ - 1.f;
    const float sy = 1.f - 2.f * py / height_;
    Ray r;
    if (orthographic()) {
      r.org = glm::vec3(cam_.world * glm::vec4(sx * cam_.xmag, sy * cam_.ymag, 0.f, 1.f));
      r.dir = forward_;
      r.tnear = std::max(0.f, cam_.znear) * forwardLength_;
    } else {
      const glm::vec3 d = rot_ * glm::vec3(sx * tanY_ * aspect_, sy * tanY_, -1.f);
      const float len = glm::length(d);
      r.org = org_;
      r.dir = d / len;
      r.tnear = std::max(0.f, cam_.znear) * len;  // the point at view depth znear
    }
    r.tfar = kInf;
    return r;
  }

  struct Connection {
    int x = 0, y = 0;            // the pixel
    glm::vec3 toCamera{0.f};     // unit direction from p towards the eye (or against the view direction)
    float distance = 0.f;        // shadow-ray length from p to where primary rays start
    float importance = 0.f;      // see the header comment
  };
  // The pixel that sees p and the camera's importance there; false when p is outside the image,
  // behind the camera or nearer than znear.
  bool connect(const glm::vec3& p, Connection& c) const {
    const glm::vec3 local = glm::vec3(invWorld_ * glm::vec4(p, 1.f));
    const float depth = -local.z;
    const float znear = std::max(0.f, cam_.znear);
    if (!(depth > 0.f) || depth < znear) return false;
    float sx, sy;
    if (orthographic()) {
      sx = local.x / cam_.xmag;
      sy = local.y / cam_.ymag;
    } else {
      sx = local.x / depth / (tanY_ * aspect_);
      sy = local.y / depth / tanY_;
    }
    const float px = 0.5f * (sx + 1.f) * width_, py = 0.5f * (1.f - sy) * height_;
    if (!(px >= 0.f && px < width_ && py >= 0.f && py < height_)) return false;
    c.x = std::min(width_ - 1, static_cast<int>(px));
    c.y = std::min(height_ - 1, static_cast<int>(py));
    if (orthographic()) {
      c.toCamera = -forward_;
      c.distance = (depth - znear) * forwardLength_;
      c.importance = 1.f / (pixelArea_ * orthoProjectedArea_);
    } else {
      const glm::vec3 d = org_ - p;
      const float r2 = glm::dot(d, d);
      const float r = std::sqrt(r2);
      c.toCamera = d / r;
      c.distance = r * (1.f - znear / depth);  // primary rays start at view depth znear
      const glm::vec3 q(local.x / depth, local.y / depth, -1.f);  // on the image plane at depth 1
      const float mq = glm::length(rot_ * q);
      c.importance = mq * mq * mq / (detM_ * pixelArea_ * r2);
    }
    return std::isfinite(c.importance) && c.importance > 0.f;
  }

private:
  Camera cam_;
  int width_, height_;
  glm::mat3 rot_;
  glm::vec3 org_;
  glm::mat4 invWorld_;
  float aspect_ = 1.f, tanY_ = 1.f;
  glm::vec3 forward_{0.f, 0.f, -1.f};
  float forwardLength_ = 1.f, detM_ = 1.f, pixelArea_ = 1.f, orthoProjectedArea_ = 1.f;
};

}  // namespace radiant::rt
