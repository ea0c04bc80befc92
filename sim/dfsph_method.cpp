// DFSPH's registration (sim/fluid_solver.h): its own scene keys, the defaults and notes it adds, and what it
// asks of a scene, beside its solver (sim/dfsph_solver.h).
#include <algorithm>
#include <string>
#include <vector>

#include "core/scene_fields.h"
#include "sim/dfsph_solver.h"
#include "sim/solver_defaults.h"

namespace surge {
namespace {

// The method's own keys under `solver` (its registration hands them to the scene reader).
void declareDfsphKeys(SceneVisitor& v, SolverSettings& s) {
  using field::atLeast, field::info, field::positive;
  v.integer("max_iterations", s.max_iterations,
            atLeast(1, "DFSPH: the most iterations each of its two solvers takes a step", "", 10000));
  v.real("max_divergence_error", s.max_divergence_error,
         positive("DFSPH: its divergence solver iterates until the average density change that the "
                  "velocity divergence would cause over one step (compression only, a fraction) is under it"));
}

// Its solvers move a particle up to about a spacing a step, as PBF's projection does.
int dfsphPushesPerFrame(const Scene& scene) { return std::max(1, scene.solver.substeps); }

// solver.max_density_error 0 (every other method's "run exactly `iterations`") is 0.0005 for DFSPH.
void dfsphDefaults(Scene& scene) {
  if (scene.solver.max_density_error == 0) scene.solver.max_density_error = 0.0005;
}

}  // namespace

// 800 bytes a particle in 3D, 360 in 2D: a gradient vector and a kernel weight a neighbour pair instead of PBF's
// factor, and five more floats and a vector a particle (679 bytes measured at 3.3 million particles).
const FluidMethod kDfsphMethod = {"dfsph", "Divergence-Free SPH (Bender & Koschier 2015, 2017)",
    &makeMethod<DfsphSolver, 2>, &makeMethod<DfsphSolver, 3>, 360, 800,
    &dfsphPushesPerFrame, &dfsphDefaults, nullptr, &declareDfsphKeys,
    "more solver.substeps or a smaller solver.max_density_error", true, "solver.max_iterations", nullptr, 3.75,
    "128, 93, 18"};

}  // namespace surge
