// What the frame loop (sim/simulation.cpp) leaves of each frame, behind one small interface: stats.csv's row,
// colliders.csv and the moving colliders' meshes, bodies.csv with the bodies' meshes and states, the method's
// carried state, and the particle frame, which is written last and commits the frame. A new per-frame output is
// a FrameOutput (or a column of stats.csv, kStatsColumns), not more lines in the loop.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/files.h"
#include "core/ply.h"
#include "core/scene.h"
#include "sim/colliders.h"
#include "sim/measures.h"

namespace surge {

class RigidBodies;

// The dam-break measures of stats.csv (sim/simulation.h).
struct DamBreakMeasures {
  double frontX = 0, backHeight = 0;
};

// What the loop knows of a frame once its steps are done.
struct FrameRecord {
  int frame = 0;
  double time = 0;
  const ParticleFrame* particles = nullptr;  // the state at the frame's end, in the solver's order
  FluidMeasures measures;
  DamBreakMeasures dam;
  int steps = 0;                 // 0 for frame 0
  double iterations = 0;         // a step, on average
  double divergenceIterations = NAN;  // a step, on average; NaN for a method without a divergence solver
  double viscosityIterations = NAN;   // the implicit viscosity solve's, a step on average; NaN without viscosity
  double smallestStep = 0, wallSeconds = 0;
  double pressureMax = NAN;      // NaN for a method without pressures
  double potentialEnergy = 0;    // the fluid's, against the tank's floor (potentialEnergy, sim/simulation.h)
  double sourceWork = 0;         // the sources' work on the fluid since frame 0 (sim/energy_ledger.h)
  size_t emitted = 0, removed = 0;  // particles the emitters added, and the sinks and open faces removed
  PhaseTimes phases;
  std::vector<Wrench> colliderWrenches, bodyWrenches;  // the frame's mean; empty at frame 0
  std::vector<float> carriedState;                     // FluidSolver::carriedState
};

class FrameOutput {
 public:
  virtual ~FrameOutput() = default;
  virtual void write(const FrameRecord& record) = 0;
};

// The outputs a scene has, in the order they are written (particles last). `continuing`: a run resumed from
// `firstFrame`, whose tables keep their rows up to it; without `resume` the colliders' meshes start anew.
std::vector<std::unique_ptr<FrameOutput>> makeFrameOutputs(const Scene& scene,
                                                           std::shared_ptr<const ColliderShapes> shapes,
                                                           const RigidBodies* bodies, const fs::path& dir,
                                                           bool resume, bool continuing, int firstFrame);

// The columns of stats.csv, colliders.csv and bodies.csv, in order.
const char* statsCsvHeader();
const char* collidersCsvHeader();
const char* bodiesCsvHeader();

// A method's carried state at `frame` (solver/frame_NNNNN.bin), for a resumed run; RunError if it is missing or
// does not hold `count` floats.
std::vector<float> readCarriedState(const fs::path& dir, int frame, size_t count);

}  // namespace surge
