// Rigid bodies in the water, two-way coupled (docs/bodies.md):
//  - the fluid pushes a body: each step, the force and torque its particles received from the body's boundary
//    (sim/colliders.h sums them) act on it over the next step, beside gravity;
//  - contacts, stacking and friction between bodies, the colliders and the tank are Bullet's (a discrete
//    dynamics world in double precision, one thread, rebuilt from the bodies' state at every frame so that a
//    resumed run steps exactly as an uninterrupted one);
//  - the body pushes the fluid: its pose at the end of each step places its collider there, whose motion over
//    the step is the wall velocity the particles feel.
// Mass, centre of mass and inertia come from the shape at the body's density (geometry/mass_properties.h).
// In 2D the bodies move in the plane z = 0 and turn about z only.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <memory>
#include <string>
#include <vector>

#include "core/scene.h"
#include "geometry/mass_properties.h"
#include "geometry/pose.h"
#include "sim/colliders.h"

namespace surge {

struct BodyState {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // the centre of mass, in the world
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  // of the shape's frame
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  // of the centre of mass
  Eigen::Vector3d angularVelocity = Eigen::Vector3d::Zero();
  Wrench fluid;  // the fluid's mean force and torque (about the centre of mass) over the last step
};

class RigidBodies {
 public:
  // shapes: the scene's colliders' and then its bodies' (buildColliderShapes). InputError if two bodies overlap
  // at the start.
  RigidBodies(const Scene& scene, std::shared_ptr<const ColliderShapes> shapes);
  ~RigidBodies();
  RigidBodies(const RigidBodies&) = delete;
  RigidBodies& operator=(const RigidBodies&) = delete;

  bool empty() const { return states_.empty(); }
  size_t size() const { return states_.size(); }
  const std::vector<BodyState>& states() const { return states_; }
  const MassProperties& massProperties(size_t b) const { return mass_[b]; }

  // Replaces the state (a resumed run) and rebuilds the world from it.
  void setStates(const std::vector<BodyState>& states);
  // Rebuilds Bullet's world from the state at `time`: contact caches start afresh at every frame.
  void beginFrame(double time);
  // Advances every body by dt from `time`: gravity, the fluid's wrench of the last step, contacts. Returns the
  // first body whose state is no longer finite, or -1.
  long step(double time, double dt);
  // The fluid's wrenches of the step just taken: every solid's, bodies from `firstBody` on.
  void setFluidWrenches(const std::vector<Wrench>& solids, size_t firstBody);

  // Body b's shape frame in the world (for its collider and its mesh).
  Pose pose(size_t b) const;

 private:
  struct World;
  const Scene& scene_;
  std::shared_ptr<const ColliderShapes> shapes_;
  std::vector<BodyState> states_;
  std::vector<MassProperties> mass_;
  std::vector<Eigen::Matrix3d> principal_;
  std::vector<double> innerRadius_;  // for continuous collision  // shape frame to Bullet's principal frame (columns: axes)
  std::unique_ptr<World> world_;
};

// Places every body's collider where the body stands (its pose at both ends of the coming step).
template <int Dim>
void placeBodies(const RigidBodies& bodies, Colliders<Dim>& colliders) {
  for (size_t b = 0; b < bodies.size(); ++b)
    for (int twice = 0; twice < 2; ++twice)
      colliders.setBodyPose(b, bodies.pose(b), bodies.states()[b].position);
}

// One step of the fluid and the bodies, coupled: the bodies move first (under the fluid's wrench of the last
// step), their colliders take their new poses, the fluid steps against them, and what it gave them is kept for
// the next step. Returns the fluid solver's bad particle (or -1); `badBody` gets the first body whose state is
// not finite (or -1).
template <int Dim, typename Solver>
long coupledStep(Solver& solver, RigidBodies* bodies, float dt, double time, long& badBody) {
  badBody = -1;
  if (!bodies || bodies->empty()) return solver.step(dt, time);
  badBody = bodies->step(time, dt);
  Colliders<Dim>& colliders = solver.colliders();
  for (size_t b = 0; b < bodies->size(); ++b)
    colliders.setBodyPose(b, bodies->pose(b), bodies->states()[b].position);
  const long bad = solver.step(dt, time);
  bodies->setFluidWrenches(colliders.takeStepWrenches(dt), colliders.firstBody());
  return bad;
}

// Throws InputError naming `key`.shape if Bullet cannot move a body of this kind (sim/rigid_bodies.cpp's
// table of Bullet shapes; buildBodyShape refuses such a body first, by geometry/shapes.h).
void checkBodyShape(ShapeKind kind, const std::string& where, const std::string& key);

// The bodies' state at a frame, exactly (hexadecimal floating point): one line a body, "name" then position,
// orientation (w x y z), velocity, angular velocity, fluid force and torque. Written atomically.
void writeBodyStates(const fs::path& path, const Scene& scene, const std::vector<BodyState>& states);
// Reads it back; InputError naming the file if it does not match the scene's bodies.
std::vector<BodyState> readBodyStates(const fs::path& path, const Scene& scene);

}  // namespace surge
