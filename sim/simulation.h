// The frame loop shared by the solvers: initial particles from the scene's fluid boxes, substeps per output
// frame, particle frames and stats.csv written atomically, divergence stops, resume from the last frame.
#pragma once

#include <memory>

#include "core/ply.h"
#include "core/progress.h"
#include "core/scene.h"
#include "sim/colliders.h"
#include "sim/frame_outputs.h"

namespace surge {

// The particles of the scene's fluid boxes on the lattice of particle_spacing, at cell centres, and of its fluid
// shapes, the tank's lattice sites inside them. InputError naming fluids[i] for a shape that holds no site or
// cannot be built (an open mesh).
ParticleFrame initialParticles(const Scene& scene);

// What a run would refuse at its start, checked before anything is written (a scene with fluid shapes, emitters,
// sinks or open faces): InputError for a fluid shape that holds nothing, an emitter inside a collider or a body,
// sinks that hold the whole initial fluid.
void checkSimulationStart(const Scene& scene, std::shared_ptr<const ColliderShapes> shapes);

// Makes `dir` ready for a simulation of `scene`, as `surge sim` and the Python module both do: resumed over
// particle frames, the folder's scene.json must have the same physics (InputError naming the first key that
// differs; the name, surfacing, rendering and frame count may change); a new run removes the later stages' frames
// of an earlier one (removeLaterStagesFrames); scene.json is rewritten only when it changes (its time tells the
// later stages' --resume whether their frames are stale).
void prepareSimulationFolder(const Scene& scene, const fs::path& dir, bool resume);
// Removes the whitewater, surface and render frames of an earlier run in dir (a new simulation makes them stale).
void removeLaterStagesFrames(const fs::path& dir);

struct SimulationSummary {
  int firstFrame = 0;  // the frame the run started from (0, or the frame it resumed from)
  int lastFrame = 0;
  size_t particles = 0;
  size_t removedParticles = 0;  // fluid placed inside colliders, removed at set-up
  double wallSeconds = 0;
  // The steps this run took, and those whose density solver stopped at its cap (FluidSolver::densityIterationCap)
  // rather than at solver.max_density_error, with the first and last frame they fell in.
  size_t steps = 0, cappedSteps = 0;
  int iterationCap = 0, firstCappedFrame = 0, lastCappedFrame = 0;
};

// "stopped at its cap of N iterations in K of M steps (frames a-b)": the summary's capped steps, for a message.
std::string densityCapReport(const SimulationSummary& summary);

// The steps of one frame, the frame loop's rule: each the largest stable one (the solver's stableTimeStep, given
// to next() before every step) shortened so that the steps left end exactly on the frame; with fixedSubsteps > 0,
// that many equal steps while the stable step is no shorter, and stable ones for the rest of the frame once it is.
class FrameSteps {
 public:
  FrameSteps(double frameDuration, int fixedSubsteps);
  bool done() const { return remaining_ <= 0; }
  float next(double stable);

 private:
  double remaining_;
  float fixed_;
  int fixedSubsteps_, steps_ = 0;
  bool shortened_ = false;  // a step of this frame was shorter than the fixed substeps'
};

// Simulates the scene into dir: particles/frame_NNNNN.ply for frames 0..output.frames and stats.csv.
// With resume, continues from the last complete frame in dir (frames are written whole or not at all), and
// ends byte-identical to an uninterrupted run. Throws RunError naming frame, substep and particle if the
// simulation diverges (earlier frames stay intact), Interrupted on Ctrl-C.
// Also writes colliders.csv and the colliders' meshes (colliders/<name>.ply, and colliders/<name>/frame_NNNNN.ply
// for a moving one) when the scene has colliders. `shapes` are the scene's built collider shapes (built here if
// not given; building them first lets a caller refuse bad collider files before writing anything).
// With bodies (sim/rigid_bodies.h): bodies.csv (frames 0..N), bodies/<name>.ply and bodies/<name>/frame_NNNNN.ply
// (each body's mesh in the world), and bodies/frame_NNNNN.txt, the state a resumed run continues from.
SimulationSummary simulate(const Scene& scene, const fs::path& dir, bool resume, Progress& progress);

// The same run a frame at a time, for a caller that looks at the particles between frames (the Python module):
// start() sets it up as simulate() does and writes frame 0 (or picks up the newest frame with resume);
// stepFrame() simulates and writes the next frame, false once the last frame is written. The particles are in
// the solver's order (it sorts them by cell), x, y(, z) a particle, Dim floats each; valid until the next step.
class SimulationRun {
 public:
  static std::unique_ptr<SimulationRun> start(const Scene& scene, std::shared_ptr<const ColliderShapes> shapes,
                                              const fs::path& dir, bool resume);
  virtual ~SimulationRun() = default;
  virtual bool stepFrame() = 0;
  virtual int frame() const = 0;      // the newest frame written
  virtual double time() const = 0;    // its time, frame / output.fps
  virtual int dimensions() const = 0;
  virtual size_t size() const = 0;
  virtual const float* positions() const = 0;
  virtual const float* velocities() const = 0;
  virtual const uint32_t* ids() const = 0;
  virtual const SimulationSummary& summary() const = 0;
  // Irving and Kirkwood's pressure in the ball of `radius` about `centre` (Dim values) at the newest frame
  // (FluidSolver::virialPressureWithin): Pa in 3D, N/m in 2D; NaN for a method without pressures. The run goes on
  // the same bytes whether it is asked or not.
  virtual double pressureWithin(const std::vector<double>& centre, double radius) = 0;
};

SimulationSummary simulate(const Scene& scene, std::shared_ptr<const ColliderShapes> shapes, const fs::path& dir,
                           bool resume, Progress& progress);

// The dam-break measures of stats.csv, in metres, from one frame (deterministic: a sort of a copy).
// The start wall is the x wall the first fluid box touches (the nearer one if it touches neither, domain.min.x if
// both); distances are measured from it, so a dam break against either wall reads the same.
//   frontX      the leading edge of the water, as a distance from the start wall: sort the particles' distances,
//               start at the median (inside the body) and walk forwards while consecutive distances are less
//               than one kernel radius apart; a particle further than that ahead of all behind it has no
//               neighbour in the body, so it is a detached droplet and the walk stops before it. Plus half a
//               spacing (the particle radius), so a block at rest reads its box's width exactly.
//   backHeight  the height of the water column at the start wall: the particles within one kernel radius of
//               it, walked up from the floor the same way (0 if none touches the floor there), plus half a
//               spacing, measured from domain.min.y.
DamBreakMeasures measureDamBreak(const Scene& scene, const ParticleFrame& frame);

// The fluid's potential energy against the tank's floor, sum over particles of m g . (c - x), c the tank's
// corner lowest along gravity: 0 for fluid on the floor's plane, growing with height (J; J/m in 2D, as the
// kinetic energy). Summed in the frame's order, the same at any thread count.
double potentialEnergy(const Scene& scene, const ParticleFrame& frame, double particleMass);

// True for a scene whose fluid is one box on the floor against one x wall (and not the other): a dam break,
// whose front_x and back_height can be compared with experiments (Martin & Moyce 1952) and across runs.
bool isDamBreak(const Scene& scene);


}  // namespace surge
