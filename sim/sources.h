// Where fluid enters and leaves the tank: the scene's emitters, sinks and open faces (domain.open). Between two
// steps the frame loop asks FluidSources for an edit (FluidSolver::editParticles): the particles inside a sink
// or past an open face go, the particles in an emitter's nozzle take its velocity, and the layers the emitters
// owe by then come in.
//
// An emitter's face holds a fixed set of lattice sites: a segment of round(2r / s) sites (2D), a sunflower disc
// of round(pi r^2 / s^2) (3D), or a grid of round(w / s) x round(h / s) (a rectangle). Layer k leaves when the
// distance D(t) the emitter has pushed fluid, the integral of its speed since `start`, passes k times the
// pitch, the layer's volume over the face's area (within half a site of s): the flux is then area x speed
// exactly, averaged over a layer. Layer k starts at D(t) - k pitch in front of the face, so a jet is unbroken at
// any speed, and everything is a function of time: a resumed run emits what an uninterrupted one does, and ids
// (the initial count plus the sites of every layer before) are the same. A site inside a collider, a body, a
// sink, outside the tank or within half a spacing of another particle stays empty (its id unused).
#pragma once

#include <memory>
#include <vector>

#include "core/scene.h"
#include "geometry/collider_shape.h"
#include "geometry/pose.h"
#include "sim/energy_ledger.h"
#include "sim/fluid_solver.h"

namespace surge {

// One emitter's face, motion and schedule (independent of the dimension).
class EmitterSchedule {
 public:
  EmitterSchedule(const EmitterSettings& settings, double spacing, int dimensions);

  size_t sitesPerLayer() const { return sites_.size(); }
  double pitch() const { return pitch_; }
  // D(t): how far the emitter has pushed fluid by `time` (m).
  double pushed(double time) const;
  // Layers that have left by `time`: those k with k pitch < D(time).
  size_t layersBy(double time) const;
  // Its position, unit direction and speed at `time`; the speed is 0 before start and after stop.
  Eigen::Vector3d position(double time) const;
  Eigen::Vector3d direction(double time) const;
  // How fast its keyframes move it at `time` (0 standing still, and before the first and after the last).
  Eigen::Vector3d velocity(double time) const;
  double speed(double time) const;
  // Site j of the face with the face at `centre` facing `direction` (unit).
  Eigen::Vector3d site(size_t j, const Eigen::Vector3d& centre, const Eigen::Vector3d& direction) const;
  // How far a point may lie from the axis and still be in front of the face (the face's half-diagonal).
  double reach() const { return reach_; }

 private:
  double keyedSpeed(double time) const;         // the keyframes' speed, ignoring start and stop
  double speedIntegral(double from, double to) const;
  EmitterSettings settings_;
  int dimensions_;
  std::vector<Eigen::Vector2d> sites_;  // in the face's (u, w) plane
  double pitch_ = 0, reach_ = 0;
};

template <int Dim>
class FluidSources {
 public:
  using VecD = Vec<Dim>;

  // `firstId`: the id of the first site the emitters make (the initial lattice's count). `time`: when the run
  // starts (0, or the frame it resumes from). InputError for a sink that cannot be built.
  FluidSources(const Scene& scene, uint32_t firstId, double time);
  ~FluidSources();

  // At the start of a fresh run: InputError when an emitter's centre lies inside a collider or a body, or the
  // sinks hold every particle of the initial fluid.
  void checkStart(const std::vector<VecD>& particles, const Colliders<Dim>& colliders) const;

  // After the step that ended at `time`: the edit to apply (also counted in emitted and removed, and its energy
  // in work).
  void apply(FluidSolver<Dim>& solver, double time);
  size_t emitted = 0, removed = 0;  // since the counts were last cleared
  // The mechanical energy the edits brought in since it was last cleared (J): the new particles', the work of
  // pushing them in under water (their flow work), the change of the steered ones' and the work of holding the
  // nozzle's layers on their sites against the water, less the removed particles' (sim/energy_ledger.h).
  double work = 0;

 private:
  void emit(size_t e, FluidSolver<Dim>& solver, double time);
  double editEnergy(const FluidSolver<Dim>& solver) const;
  double massOf(const FluidSolver<Dim>& solver, size_t i) const;  // particle i's mass (kg)
  // How deep the water stands above c (along -gravity), in a column of `reach` around it: 0 where none does.
  float waterAbove(const VecD& c, float reach, const std::vector<VecD>& x) const;
  VecD outOfNozzle(const VecD& r, float along, float across, const VecD& d, float reach, float depth) const;
  bool inSink(const VecD& p) const;
  void placeSinks(double time);  // the moving sinks' poses and bounds at `time`
  bool pastOpenFace(const VecD& p) const;

  struct Sink;
  const Scene& scene_;
  float spacing_;
  VecD domainMin_, domainMax_;
  int openFaces_ = 0;  // bits: axis k's lower face 1 << 2k, upper 1 << (2k + 1)
  std::vector<EmitterSchedule> emitters_;
  std::vector<size_t> layers_;          // layers each emitter has made
  std::vector<uint8_t> emittedFluid_;   // the fluid each emitter brings (0 in a scene of one fluid)
  std::vector<double> fluidMassRatio_;  // each fluid's particle mass over the solver's particleMass()
  uint32_t nextId_;
  double lastTime_, stepTime_ = 0;  // the last apply's time, and the step since the one before
  std::vector<std::unique_ptr<Sink>> sinks_;
  GravityPotential potential_;
  double flowWork_ = 0, heldWork_ = 0;  // this edit's new particles' flow work, and the held layers' work
  ParticleEdit<Dim> edit_;  // reused: no allocation once its capacity suffices
  std::vector<VecD> nearby_;    // where the particles near an emitter's face are after the edit
  std::vector<VecD> heldAt_, heldVelocity_;  // the nozzle's sites, by layer, and their velocities
  std::vector<uint8_t> held_;                // 1 once a particle rides the site
};

// The most particles the scene's emitters can make by `time` (every site filled): the memory check's count.
size_t mostEmittedParticles(const Scene& scene, double time);

extern template class FluidSources<2>;
extern template class FluidSources<3>;

}  // namespace surge
