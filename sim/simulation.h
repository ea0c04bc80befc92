// The frame loop shared by the solvers: initial particles from the scene's fluid boxes, substeps per output
// frame, particle frames and stats.csv written atomically, divergence stops, resume from the last frame.
#pragma once

#include "core/ply.h"
#include "core/progress.h"
#include "core/scene.h"

namespace surge {

// The particles of the scene's fluid boxes on the lattice of particle_spacing, at cell centres.
ParticleFrame initialParticles(const Scene& scene);

struct SimulationSummary {
  int firstFrame = 0;  // the frame the run started from (0, or the frame it resumed from)
  int lastFrame = 0;
  size_t particles = 0;
  double wallSeconds = 0;
};

// Simulates the scene into dir: particles/frame_NNNNN.ply for frames 0..output.frames and stats.csv.
// With resume, continues from the last complete frame in dir (frames are written whole or not at all), and
// ends byte-identical to an uninterrupted run. Throws RunError naming frame, substep and particle if the
// simulation diverges (earlier frames stay intact), Interrupted on Ctrl-C.
SimulationSummary simulate(const Scene& scene, const fs::path& dir, bool resume, Progress& progress);

// The columns of stats.csv, in order.
const char* statsCsvHeader();

}  // namespace surge
