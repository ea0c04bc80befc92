// The whitewater as both renderers draw it (whitewater/frame_NNNNN.ply, when the folder has it): each diffuse
// particle a sphere of whitewater.particle_size times its kind's render size, varied per particle between 0.6 and
// 1.4 times by a hash of its id (not every particle the same size), in its kind's albedo.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "core/hash.h"
#include "core/ply.h"
#include "core/scene.h"

namespace surge {

struct WhitewaterSpheres {
  std::vector<Eigen::Vector4f> spheres;  // centre and radius
  std::vector<Eigen::Vector3f> albedo;
  bool empty() const { return spheres.empty(); }
};

inline WhitewaterSpheres whitewaterSpheres(const DiffuseFrame& frame, const Scene& scene) {
  const RenderSettings& r = scene.render;
  const double base = scene.whitewater.particle_size;  // resolved by the scene reader
  const float size[3] = {float(base * r.spray_size), float(base * r.foam_size), float(base * r.bubble_size)};
  const Eigen::Vector3f colour[3] = {r.spray_color.cast<float>(), r.foam_color.cast<float>(),
                                     r.bubble_color.cast<float>()};
  WhitewaterSpheres out;
  out.spheres.reserve(frame.size());
  out.albedo.reserve(frame.size());
  for (size_t i = 0; i < frame.size(); ++i) {
    const int kind = frame.type[i];  // 0, 1 or 2: readDiffusePly checks
    const float radius = size[kind] * (0.6f + 0.8f * unitFromBits(hashBits(frame.id[i] ^ 0x5bd1e995U)));
    out.spheres.emplace_back(frame.position[i].x(), frame.position[i].y(), frame.position[i].z(), radius);
    out.albedo.push_back(colour[kind]);
  }
  return out;
}

// The frame's whitewater spheres, or none when the folder has no whitewater frame for it.
inline WhitewaterSpheres whitewaterSpheresAt(const fs::path& dir, int frame, const Scene& scene) {
  DiffuseFrame diffuse;
  if (!readDiffusePlyIfPresent(framePath(dir, "whitewater", frame, "ply"), diffuse)) return {};
  return whitewaterSpheres(diffuse, scene);
}

}  // namespace surge
