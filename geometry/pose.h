// Where a collider is at a time: scale, then rotation, then translation of its shape's own frame, from the
// scene's placement or interpolated between its motion keyframes.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/scene.h"

namespace surge {

struct Pose {
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  double scale = 1;

  Eigen::Vector3d toWorld(const Eigen::Vector3d& local) const { return translation + rotation * (scale * local); }
  Eigen::Vector3d toLocal(const Eigen::Vector3d& world) const {
    return rotation.conjugate() * (world - translation) / scale;
  }
};

// The unit quaternion of a scene rotation (axis normalised; a zero angle is the identity whatever the axis).
inline Eigen::Quaterniond toQuaternion(const Rotation& r) {
  if (r.degrees == 0) return Eigen::Quaterniond::Identity();
  return Eigen::Quaterniond(Eigen::AngleAxisd(r.degrees * M_PI / 180.0, r.axis.normalized()));
}

// The collider's pose at `time`: its placement, or its keyframes interpolated linearly in position and by
// spherical interpolation in rotation (which is linear in the angle about a fixed axis), held before the first
// keyframe and after the last.
inline Pose colliderPose(const ColliderSettings& c, double time) {
  Pose pose;
  pose.scale = c.scale;
  if (c.motion.empty()) {
    pose.rotation = toQuaternion(c.rotation);
    pose.translation = c.position;
    return pose;
  }
  const auto& keys = c.motion;
  if (time <= keys.front().time || keys.size() == 1) {
    pose.rotation = toQuaternion(keys.front().rotation);
    pose.translation = keys.front().position;
    return pose;
  }
  if (time >= keys.back().time) {
    pose.rotation = toQuaternion(keys.back().rotation);
    pose.translation = keys.back().position;
    return pose;
  }
  size_t k = 1;
  while (keys[k].time < time) ++k;
  const ColliderKeyframe &a = keys[k - 1], &b = keys[k];
  const double span = b.time - a.time;
  const double f = span > 0 ? (time - a.time) / span : 1.0;
  pose.translation = (1 - f) * a.position + f * b.position;
  pose.rotation = toQuaternion(a.rotation).slerp(f, toQuaternion(b.rotation));
  return pose;
}

inline bool isMoving(const ColliderSettings& c) { return c.motion.size() > 1; }

}  // namespace surge
