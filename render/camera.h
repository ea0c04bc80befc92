// A pinhole camera: y is up, the image's x grows to the right and its y downwards, so a camera looking down
// -z shows world +x on the right of the image. The vertical field of view is in degrees.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "core/scene.h"

namespace surge {

struct Ray {
  Eigen::Vector3f origin = Eigen::Vector3f::Zero();
  Eigen::Vector3f direction = Eigen::Vector3f::UnitZ();  // unit length
};

// The scene's camera, or where it leaves position == look_at, one that frames the domain: looking at its centre
// from the front, raised and turned a little (straight on in 2D), far enough back that the tank fills the image
// of render.width x render.height with a margin (the quality presets keep that aspect ratio).
inline CameraSettings framedCamera(const Scene& s) {
  CameraSettings camera = s.render.camera;
  if (camera.position != camera.look_at) return camera;
  const int d = s.dimensions;
  const Eigen::Vector3d centre = 0.5 * (s.domain.min + s.domain.max);
  const Eigen::Vector3d extent = s.domain.max - s.domain.min;
  const double tanHalf = std::tan(camera.fov * M_PI / 360.0);
  const double aspect = double(s.render.width) / double(s.render.height);
  const double fitHeight = 0.5 * extent.y() / tanHalf;
  const double fitWidth = 0.5 * extent.x() / (tanHalf * aspect);
  const double distance = 1.4 * std::max(fitHeight, fitWidth) + 0.5 * extent.z();
  const Eigen::Vector3d direction = d == 2 ? Eigen::Vector3d(0, 0, 1) : Eigen::Vector3d(0.35, 0.55, 1.0).normalized();
  camera.look_at = centre - (d == 2 ? Eigen::Vector3d::Zero() : Eigen::Vector3d(0, 0.15 * extent.y(), 0));
  camera.position = camera.look_at + distance * direction;
  return camera;
}

class PinholeCamera {
 public:
  PinholeCamera(const CameraSettings& settings, int width, int height)
      : position_(settings.position.cast<float>()), width_(float(width)), height_(float(height)) {
    forward_ = (settings.look_at - settings.position).cast<float>().normalized();
    // Looking straight up or down leaves "up" undefined: take -z (or +z) as the image's up then.
    Eigen::Vector3f worldUp = Eigen::Vector3f::UnitY();
    if (std::abs(forward_.dot(worldUp)) > 0.999f)
      worldUp = forward_.y() > 0 ? Eigen::Vector3f(0, 0, 1) : Eigen::Vector3f(0, 0, -1);
    right_ = forward_.cross(worldUp).normalized();
    up_ = right_.cross(forward_);
    tanHalfHeight_ = float(std::tan(settings.fov * M_PI / 360.0));
    tanHalfWidth_ = tanHalfHeight_ * width_ / height_;
  }

  // The ray through image point (x, y) in pixels: (0, 0) is the top-left corner of the image, (width, height)
  // the bottom-right one, and the centre of pixel (i, j) is (i + 0.5, j + 0.5).
  Ray rayThrough(float x, float y) const {
    const float sx = (2.0f * x / width_ - 1.0f) * tanHalfWidth_;
    const float sy = (1.0f - 2.0f * y / height_) * tanHalfHeight_;
    Ray ray;
    ray.origin = position_;
    ray.direction = (forward_ + sx * right_ + sy * up_).normalized();
    return ray;
  }

  // Where a world point lands in the image, in the pixel units of rayThrough; false if it is behind the
  // camera.
  bool project(const Eigen::Vector3f& point, float& x, float& y) const {
    const Eigen::Vector3f d = point - position_;
    const float depth = d.dot(forward_);
    if (depth <= 0) return false;
    x = 0.5f * width_ * (1.0f + d.dot(right_) / (depth * tanHalfWidth_));
    y = 0.5f * height_ * (1.0f - d.dot(up_) / (depth * tanHalfHeight_));
    return true;
  }

  // The camera's frame, for rasterisers that need it as a matrix: unit forward, right and up vectors, and the
  // tangents of half the field of view across and up.
  const Eigen::Vector3f& position() const { return position_; }
  const Eigen::Vector3f& forward() const { return forward_; }
  const Eigen::Vector3f& right() const { return right_; }
  const Eigen::Vector3f& up() const { return up_; }
  float tanHalfWidth() const { return tanHalfWidth_; }
  float tanHalfHeight() const { return tanHalfHeight_; }

 private:
  Eigen::Vector3f position_, forward_, right_, up_;
  float width_, height_, tanHalfWidth_ = 1, tanHalfHeight_ = 1;
};

}  // namespace surge
