// The one interface every fluid method implements, and the registry that makes the scene's method.
//
// The frame loop (sim/simulation.cpp), the rigid bodies' coupling (sim/rigid_bodies.h) and the benchmarks see a
// solver only through FluidSolver<Dim>. A method is its solver (a class deriving from ParticleSolver,
// sim/particle_solver.h), its FluidMethod (sim/<method>_method.cpp) and one line in the registry
// (sim/fluid_solver.cpp), or one call of registerFluidMethod for a method outside the library. What the rest of Surge knows of a method it learns
// from its FluidMethod, never by comparing its name. Its own scene keys are declared beside it, through
// its FluidMethod (declareKeys); `solver.method`'s choices are the registry's (core/scene.h, solverMethodCatalog).
// A method allocates only what its scene turns on, so a scene pays only for what its method uses.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/ply.h"
#include "core/scene.h"
#include "core/scene_fields.h"
#include "sim/colliders.h"
#include "sim/measures.h"

namespace surge {

// Particles entering and leaving between two steps (sim/sources.h): the indices (in the solver's current order)
// to remove, in increasing order; particles given a new position and velocity (an emitter's nozzle); and new
// particles.
template <int Dim>
struct ParticleEdit {
  std::vector<uint32_t> remove;
  std::vector<uint32_t> steer;
  std::vector<Vec<Dim>> steerPosition, steerVelocity;
  std::vector<Vec<Dim>> addPosition, addVelocity;
  std::vector<uint32_t> addId;
  std::vector<uint8_t> addFluid;  // each new particle's fluid (Scene::fluidOf; 0 in a scene of one fluid)

  bool empty() const { return remove.empty() && steer.empty() && addPosition.empty(); }
  void clear() {
    remove.clear();
    steer.clear();
    steerPosition.clear();
    steerVelocity.clear();
    addPosition.clear();
    addVelocity.clear();
    addId.clear();
    addFluid.clear();
  }
};

template <int Dim>
class FluidSolver {
 public:
  virtual ~FluidSolver() = default;

  virtual void setParticles(const ParticleFrame& frame) = 0;
  virtual void getParticles(ParticleFrame& frame) const = 0;
  virtual size_t size() const = 0;
  // The particles in the solver's current order (it reorders them by grid cell), and their mass.
  virtual const std::vector<Vec<Dim>>& positions() const = 0;
  virtual const std::vector<Vec<Dim>>& velocities() const = 0;
  virtual const std::vector<uint32_t>& ids() const = 0;
  virtual float particleMass() const = 0;
  // Each particle's mass over particleMass() in a scene of several fluids (empty in a scene of one).
  virtual const std::vector<float>& massRatios() const = 0;

  // Steps a frame: > 0 for a method that takes at least that many equal steps, shorter ones when stableTimeStep
  // (read before every step) is below them; 0 for one that chooses each step's length from stableTimeStep.
  virtual int fixedSubsteps() const = 0;
  virtual float stableTimeStep() = 0;
  // The start of an output frame at `time`. A method that keeps state between steps beyond positions and
  // velocities either forgets it here (WCSPH's stored accelerations) or carries it (below), so that a run
  // resumed from a frame file continues exactly as an uninterrupted one.
  virtual void beginFrame(double time) = 0;
  // What a method carries from frame to frame beyond positions and velocities (DFSPH's warm starts), in the
  // order of getParticles, as channels of one float a particle one after another: the frame loop writes it
  // beside each particle frame and gives it back on resume. Empty for a method that carries nothing.
  virtual std::vector<float> carriedState() const { return {}; }
  virtual void restoreCarriedState(const std::vector<float>&) {}
  // Between two steps: steers, removes and adds particles (ParticleEdit). Surviving particles keep their order
  // and carried state, new ones come last with none; no allocation unless the count outgrows the capacity,
  // which then grows by half.
  virtual void editParticles(const ParticleEdit<Dim>& edit) = 0;
  // One step of dt from `time`. Returns the index of the first particle that is not finite, left the tank or
  // ran away (firstParticleOutside), or -1 if all are well.
  virtual long step(float dt, double time) = 0;

  // What stats.csv reports: the measures of the current state, the last step's solver iterations (density, and
  // divergence for a method with a divergence solver, else -1), the largest pressure this frame (NaN for a
  // method without pressures) and the time spent per phase.
  virtual FluidMeasures measure() = 0;
  virtual int lastIterations() const = 0;
  // The most density iterations a step may take where the method iterates to solver.max_density_error (a step
  // that takes them all stopped short of it); 0 for a method that takes a fixed count or none.
  virtual int densityIterationCap() const { return 0; }
  virtual int lastDivergenceIterations() const { return -1; }
  // The implicit viscosity solve's iterations in the last step (0 explicit), or -1 without viscosity.
  virtual int lastViscosityIterations() const { return -1; }
  virtual float maxPressure() const { return NAN; }
  // Irving and Kirkwood's mechanical pressure in a ball (a disc in 2D) of the fluid at the current positions:
  // the virial x_ij . F_ij of every pair force (the method's pressure force and surface tension's cohesion and
  // curvature), each pair counted by the share of the segment between its particles inside the ball, plus the
  // momentum flux m v v of the particles inside, v relative to their mean, over d times the ball's volume. At
  // rest it is the radial stress on the ball's surface; where cohesion holds the fluid, the pressure Laplace's law
  // speaks of (docs/surface-tension.md, "Laplace's pressure"). NaN for a method without pressures.
  virtual double virialPressureWithin(const Vec<Dim>& centre, float radius) {
    (void)centre;
    (void)radius;
    return NAN;
  }
  virtual PhaseTimes& phaseTimes() = 0;
  // The work the method's cohesive forces (surface tension, adhesion) did on the fluid since the last call (J):
  // surface energy turned into motion, which the energy account counts as a source's work.
  virtual double takeForceWork() { return 0; }
  // The energy the fluid holds in its compression now (J), which a compressible method gives back as motion: a
  // jittered start's (fluids[i].jitter), which the energy account counts as a source's work. 0 for the methods
  // that project the compression away.
  virtual double compressionEnergy() { return 0; }

  // The colliders and bodies the fluid meets (empty without them); the bodies' coupling sets their poses.
  virtual Colliders<Dim>& colliders() = 0;
  // Each collider's mean force and torque from the fluid since the last call, over `duration` seconds.
  std::vector<Wrench> takeColliderWrenches(double duration) { return colliders().takeFrameWrenches(duration); }
};

// A method as the registry holds it: how to make it and what it asks of a scene.
struct FluidMethod {
  const char* name;
  const char* description;  // its paper, for `surge keys`
  std::unique_ptr<FluidSolver<2>> (*make2)(const Scene&, std::shared_ptr<const ColliderShapes>);
  std::unique_ptr<FluidSolver<3>> (*make3)(const Scene&, std::shared_ptr<const ColliderShapes>);
  // Bytes a particle needs at peak, in 2D and 3D, for the memory check (sim/solver_defaults.h).
  size_t bytesPerParticle2d, bytesPerParticle3d;
  // How many times a frame the method's own push can move a particle by a spacing (the runaway speed).
  int (*pushesPerFrame)(const Scene&);
  // Fills the method's own settings that the file left 0, after the shared ones; null for none.
  void (*resolveDefaults)(Scene&);
  // The notes `surge sim` prints before it starts (a setting the scene may regret); null for none.
  std::vector<std::string> (*notes)(const Scene&);
  // Declares the method's own keys under `solver` (their defaults, ranges and docs text) to the scene reader,
  // writer and key table; null for none. Their values live in SolverSettings (core/scene.h).
  void (*declareKeys)(SceneVisitor&, SolverSettings&);
  // The settings that make its steps more careful, for the energy stop's remedy (sim/energy_ledger.h): "more
  // solver.substeps or solver.iterations"; null says shorter steps.
  const char* steadier = nullptr;
  // False for a method whose emitters make energy the account cannot see, so that the energy stop leaves its runs
  // with emitters alone (WCSPH: a nozzle opening under water throws the pool about, docs/speed-accuracy.md).
  bool emittersAccounted = true;
  // The key that caps its density iterations where it iterates to solver.max_density_error (FluidSolver::
  // densityIterationCap), for surge sim's report and the energy stop's remedy; null for none.
  const char* iterationCapKey = nullptr;
  // Where the adhesion's calibration misses Young's angle in this method in 3D: the test's drop on a plate at
  // adhesion 0.25, 0.5, 0.75 at the 3D default support with surface tension (2.5 spacings), in degrees, for surge
  // sim's note (docs/surface-tension.md, "By method"); null where it holds.
  const char* adhesionAngles = nullptr;
  // The kernel's support, in spacings, that solver.kernel_radius 0 gives a 2D scene with surface tension: at 2
  // spacings its cohesion holds a 2D drop as a crystal; the method's own width lets it round and ring at
  // Rayleigh's frequency, and DFSPH's and WCSPH's 3.75 is where the calibration's sum is the same on any
  // arrangement of the particles (docs/surface-tension.md, "The 2D support", "The calibration's lattice").
  double surfaceTensionSupport2d = 2;
  // The same drop in 2D at that support, in degrees, for surge sim's note (docs/surface-tension.md, "Adhesion in
  // 2D"); null for none measured.
  const char* adhesionAngles2d = nullptr;
  // The narrowest 2D support, in spacings, at which its cohesion lets a drop round: below it the lattice holds as a
  // crystal, and surge sim says so (DFSPH's is one at 2.5; PBF's, under Wendland's kernels, rounds there).
  double roundingSupport2d = 2.75;
};

// FluidMethod::make2 and make3 for a solver class template.
template <template <int> class Method, int Dim>
std::unique_ptr<FluidSolver<Dim>> makeMethod(const Scene& scene, std::shared_ptr<const ColliderShapes> shapes) {
  return std::make_unique<Method<Dim>>(scene, std::move(shapes));
}

// The method registered as `name`; InputError naming `source` and solver.method if there is none.
const FluidMethod& fluidMethod(const std::string& name, const std::string& source = "scene");
// Adds a method to the registry (a method outside the library: a test's, a plug-in's).
void registerFluidMethod(const FluidMethod& method);
// Takes a method registerFluidMethod added out of the registry again (a test's, so that the next test in the same
// process sees the built-in methods' key table); nothing if it is not there.
void unregisterFluidMethod(const std::string& name);

// The solver of scene.solver.method. `shapes`: the scene's collider shapes, built once by the caller (null
// builds them). InputError if the method is not registered.
template <int Dim>
std::unique_ptr<FluidSolver<Dim>> makeFluidSolver(const Scene& scene,
                                                  std::shared_ptr<const ColliderShapes> shapes = nullptr);

// The registered methods, in registration order.
std::vector<std::string> fluidSolverMethods();

}  // namespace surge
