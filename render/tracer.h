// The ray-traced world of one frame, built with Embree 3: the water mesh, the colliders, a large ground plane
// at the tank's floor and the tank (render.tank: its edges as thin dark bars, its four side walls as thin
// glass, or nothing). Embree's types stay in tracer.cpp; the rest of render/ asks only "what does this ray
// hit" and "is this segment blocked".
#pragma once

#include <Eigen/Core>
#include <memory>

#include "core/ply.h"
#include "core/scene.h"
#include "render/camera.h"
#include "render/colliders.h"
#include "render/whitewater_spheres.h"

namespace surge {

// One Embree device. Creating it starts Embree's worker setup, so a stage makes one and renders every frame
// with it. Throws RunError if Embree cannot start.
class RayDevice {
 public:
  RayDevice();
  ~RayDevice();
  RayDevice(const RayDevice&) = delete;
  RayDevice& operator=(const RayDevice&) = delete;

  struct Impl;
  Impl& impl() const { return *impl_; }

 private:
  std::unique_ptr<Impl> impl_;
};

enum class SurfaceKind { Water, Ground, TankEdge, TankGlass, Collider, Whitewater };

struct Hit {
  SurfaceKind kind = SurfaceKind::Ground;
  float distance = 0;
  Eigen::Vector3f point = Eigen::Vector3f::Zero();
  Eigen::Vector3f geometricNormal = Eigen::Vector3f::UnitY();  // unit, facing the incoming ray
  Eigen::Vector3f normal = Eigen::Vector3f::UnitY();           // shading normal, unit, same side as above
  // Where shadow and reflection rays start: the point lifted off the surface on the ray's side.
  Eigen::Vector3f leavePoint = Eigen::Vector3f::Zero();
  // Where refracted rays start: the point pushed just through the surface.
  Eigen::Vector3f passPoint = Eigen::Vector3f::Zero();
  Eigen::Vector3f albedo = Eigen::Vector3f::Zero();  // a collider's or a whitewater particle's colour
  uint8_t fluid = 0;  // a water hit's fluid (TriangleMesh::fluid; 0 in a scene of one)
};

class RayScene {
 public:
  // Keeps references to `water` and `colliders`, which must outlive this object. Of a one-sided collider only
  // the triangles facing the scene's camera are built (trianglesFacing). Throws InputError if a triangle of
  // `water` names a vertex it does not have, RunError if Embree fails.
  // `whitewater`, when given, must outlive this object too: its spheres are Embree sphere points.
  RayScene(const RayDevice& device, const TriangleMesh& water, const Scene& scene,
           const std::vector<ColliderMesh>& colliders, const WhitewaterSpheres* whitewater = nullptr);
  RayScene(const RayDevice& device, const TriangleMesh& water, const Scene& scene);
  ~RayScene();
  RayScene(const RayScene&) = delete;
  RayScene& operator=(const RayScene&) = delete;

  // The nearest hit along the ray closer than maxDistance, if any; a shadow ray sees only what casts
  // shadows (not the tank's edges; glass walls and water only filter the light).
  bool intersect(const Ray& ray, float maxDistance, Hit& hit, bool shadowRay = false) const;
  // True if anything that casts shadows (not the tank's edges; glass and water count as blocking here) lies
  // on the segment from origin along the unit direction up to maxDistance.
  bool occluded(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction, float maxDistance) const;

 private:
  static const std::vector<ColliderMesh>& noColliders();

  struct Impl;
  std::unique_ptr<Impl> impl_;
  float offset_ = 1e-4f;  // how far secondary rays start off a surface, relative to the tank's size
};

}  // namespace surge
