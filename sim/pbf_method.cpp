// PBF's registration (sim/fluid_solver.h): its own scene keys, the defaults and notes it adds, and what it
// asks of a scene, beside its solver (sim/pbf_solver.h).
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/scene_fields.h"
#include "sim/pbf_solver.h"
#include "sim/solver_defaults.h"
#include "sim/surface_tension.h"

namespace surge {
namespace {

// The method's own keys under `solver` (its registration hands them to the scene reader).
void declarePbfKeys(SceneVisitor& v, SolverSettings& s) {
  using field::atLeast, field::info, field::positive;
  v.integer("iterations", s.iterations,
            atLeast(0,
                    "PBF: Jacobi iterations per step; 0: 4, 8 where surface tension holds a fluid under gravity "
                    "(docs/surface-tension.md), or where the fluids' densities differ at most 30, to "
                    "max_density_error (0.001 if 0; docs/several-fluids.md)",
                    "", 10000));
  v.real("relaxation_epsilon", s.relaxation_epsilon,
         atLeast(0,
                 "PBF eq. 11 relaxation epsilon, as a fraction of the rest lattice's sum of squared "
                 "constraint gradients (0.01 softens the constraint by 1%); left out: 0.01, or 0.8 in 2D with "
                 "surface tension at a kernel support wider than 3 spacings (its default 3.5: a wider 2D lattice's "
                 "Jacobi iterations overshoot; docs/surface-tension.md)"));
  v.real("warm_start", s.warm_start,
         atLeast(0, "PBF, experimental: the share of the last step's lambda sums applied as one correction "
                    "before the Jacobi iterations (a warm start, as DFSPH's); fewer iterations, but it adds "
                    "kinetic energy to a deep 2D dam break (docs/speed-accuracy.md); 0 turns it off", "", 0.9));
  static_assert(SolverSettings::kChebyshevLeastIterations == 8, "chebyshev_rho's description names the cap");
  v.real("chebyshev_rho", s.chebyshev_rho,
         atLeast(0,
                 "PBF, when iterating to max_density_error with iterations >= 8: the Jacobi iterations' "
                 "spectral radius that their Chebyshev acceleration assumes (Wang 2015); the larger, the "
                 "fewer iterations for the same density error, up to where it overshoots (0.95 blows a dam "
                 "break up; docs/speed-accuracy.md); 0 turns it off; left out: 0.85, or 0 in 3D at a kernel "
                 "support wider than 2 spacings (a pool there blows up at 0.85)",
                 "", 0.95));
  v.real("scorr_k", s.scorr_k,
         atLeast(0,
                 "PBF eq. 13 artificial pressure k, in units of the rest lattice's lambda; 0 turns s_corr off (as "
                 "a domain periodic along every axis does: no spray or sheets there); left out: 0.1, or 0 where "
                 "the fluids' densities differ and none has surface tension, and in 2D with surface tension at a "
                 "kernel support wider than 3 spacings (its push damps a drop's ringing)"));
  v.integer("scorr_n", s.scorr_n, atLeast(1, "PBF eq. 13 exponent n", "", 16));
  {
    FieldInfo dq = positive("PBF eq. 13 delta q, as a fraction of the kernel radius (paper: 0.1 to 0.3)");
    dq.max = 1;
    v.real("scorr_delta_q", s.scorr_delta_q, dq);
  }
  v.real("vorticity_epsilon", s.vorticity_epsilon,
         atLeast(0, "PBF eq. 16 vorticity confinement epsilon; 0 turns it off", "m/s"));
}

// Where s_corr is off unless the file sets it: the fluids' densities differ and none has surface tension.
bool scorrOffByDefault(const Scene& scene) {
  return scene.densitiesDiffer() && sceneSurfaceTension(scene) == 0;
}

// True where the kernel's support is wider than `spacings` particle spacings (a radius set to exactly that is not).
bool supportWiderThan(const Scene& scene, double spacings) {
  return scene.solver.kernel_radius > spacings * scene.particle_spacing * (1 + 1e-9);
}

// Where surface tension holds a fluid under gravity: its wider support's 4 iterations leave a standing fluid
// compressed, and a pool 40 particles deep blows up within its first frame; 8 hold it (docs/surface-tension.md, "A
// pool under gravity"). Iterated to an average density error instead, a drop into a thin layer stops on the energy
// check: the layer at rest meets the error with no iteration, and the impact goes uncorrected.
bool standingWithSurfaceTension(const Scene& scene) {
  return sceneSurfaceTension(scene) > 0 && scene.gravity.squaredNorm() > 0;
}

// A 2D scene with surface tension at a support wider than 3 spacings (PBF's own there is 3.5): its drop rings at
// Rayleigh's frequency swing after swing, where at 2.5 the lattice yields in bursts and its later swings run 5 to
// 16% slow. Its Jacobi iterations overshoot there (the rest lattice's largest eigenvalue 4.40 against 2.47 at 2.5):
// relaxation 0.8 holds a 40 x 40 square; s_corr's push, a step's, damps the ringing (docs/surface-tension.md, "PBF
// 2D at 3.5 spacings").
bool wide2dWithSurfaceTension(const Scene& scene) {
  return scene.dimensions == 2 && sceneSurfaceTension(scene) > 0 && supportWiderThan(scene, 3);
}

// Where the fluids' densities differ PBF iterates to a density error of 0.1% (at most 30 iterations), and without
// surface tension leaves s_corr off, unless the file says otherwise: under 4 fixed iterations a heavy column sags
// for 0.05 s before its pressure holds it, and s_corr's push, a step's, holds the converged interior against the
// flow. Rayleigh-Taylor's growth read 0.60 to 0.84 of theory at 4 to 32 steps a frame with them, 0.86 to 0.95
// without. A drop held by surface tension keeps s_corr: converged without it, oil in water stays 2.4 to 3.1% off
// round where it rounds to 1.4 to 1.8% with it (docs/several-fluids.md). Chebyshev's acceleration, measured at 2
// spacings, overshoots at 3D's wider support with surface tension: a pool 20 particles deep there gains energy within
// a frame at 0.85 and settles at 0. A fluid surface tension holds under gravity takes 8 iterations.
void resolvePbfDefaults(Scene& scene) {
  SolverSettings& s = scene.solver;
  if (std::isnan(s.chebyshev_rho) && scene.dimensions == 3 && supportWiderThan(scene, 2)) s.chebyshev_rho = 0;
  if (wide2dWithSurfaceTension(scene)) {
    if (std::isnan(s.relaxation_epsilon)) s.relaxation_epsilon = 0.8;
    if (std::isnan(s.scorr_k)) s.scorr_k = 0;
  }
  if (!scene.densitiesDiffer()) {
    if (s.iterations == 0 && standingWithSurfaceTension(scene)) s.iterations = 8;
    return;
  }
  if (s.iterations == 0) {
    s.iterations = 30;
    if (s.max_density_error == 0) s.max_density_error = 0.001;
  }
  if (std::isnan(s.scorr_k) && scorrOffByDefault(scene)) s.scorr_k = 0;
}

// The projection moves a particle up to about a spacing a step (the velocity is that move over the step).
int pbfPushesPerFrame(const Scene& scene) { return std::max(1, scene.solver.substeps); }

std::vector<std::string> pbfNotes(const Scene& scene) {
  std::vector<std::string> notes;
  const int stable = stableSubsteps(scene);
  if (stable > scene.solver.substeps)
    notes.push_back("solver.substeps " + std::to_string(scene.solver.substeps) + " is below the " +
                    std::to_string(stable) +
                    " a PBF pool this deep needs to stay at rest (dt <= 0.9 particle_spacing / sqrt(g depth)): its "
                    "steps will be shortened to them while the fluid stands that deep");
  // PBF's own kernels (poly6, spiky) wider than 2.5 spacings stir a fluid at rest (docs/speed-accuracy.md); a 2D
  // scene with surface tension takes Wendland's (pbfUsesWendland).
  const double spacings = scene.solver.kernel_radius / scene.particle_spacing;
  if (supportWiderThan(scene, 2.5) && !pbfUsesWendland(scene))
    notes.push_back("solver.kernel_radius is " + formatNumber(spacings) + " spacings: PBF's kernels wider than 2.5 "
                    "spacings stir a fluid at rest (a 2D pool at 3 keeps six times the kinetic energy it keeps at 2; "
                    "at 3.5 it gains energy until the energy check stops it)");
  // Where the fluids' densities differ, the settings their defaults avoid (resolvePbfDefaults).
  if (scene.densitiesDiffer() && scene.solver.max_density_error == 0)
    notes.push_back("solver.iterations " + std::to_string(scene.solver.iterations) +
                    " fixed where the fluids' densities differ: a heavy column sags under fixed iterations before its "
                    "pressure holds it (a Rayleigh-Taylor mode grows at 0.75 of theory at 4); left out, PBF "
                    "iterates to a density error of 0.1%, at most 30 times a step");
  else if (standingWithSurfaceTension(scene) && scene.solver.iterations < 8 && scene.solver.max_density_error == 0)
    notes.push_back("solver.iterations " + std::to_string(scene.solver.iterations) +
                    " where surface tension holds a fluid under gravity: at its wider kernel support a standing "
                    "fluid stays compressed under them (a 2D pool 40 particles deep blows up within its first frame "
                    "at 4); left out, PBF takes 8 in such a scene");
  if (scorrOffByDefault(scene) && scene.solver.scorr_k > 0)
    notes.push_back("solver.scorr_k where the fluids' densities differ: s_corr's push, a step's, holds the interior "
                    "against the flow (a Rayleigh-Taylor mode grows at 0.60 of theory at 32 steps a frame); left out, "
                    "it is 0 in such a scene");
  // PBF's push keeps a flow's particles even (a Taylor-Green vortex within 2.3%), but stirs a fluid at rest.
  if (scene.solver.background_pressure > 0)
    notes.push_back("solver.background_pressure in PBF keeps a flow's particles even but stirs a fluid at rest: a "
                    "periodic box at rest gains energy within a few frames and the energy check stops it "
                    "(docs/viscosity.md)");
  return notes;
}

}  // namespace

// 400 bytes a particle in 3D: about 340 of channels (x, v, x* and a scratch copy, ids, lambdas, the grid's) and
// 30 neighbours with their gradient factors, the frame being written, and the allocator's slack; 250 in 2D
// (docs/performance.md).
// clang-format off
const FluidMethod kPbfMethod = {"pbf", "Position Based Fluids (Macklin & Mueller 2013)",
    &makeMethod<PbfSolver, 2>, &makeMethod<PbfSolver, 3>, 250, 400,
    &pbfPushesPerFrame, &resolvePbfDefaults, &pbfNotes, &declarePbfKeys,
    "more solver.substeps or solver.iterations (at many steps a frame, a smaller solver.scorr_k: its push is a step's)",
    true, "solver.iterations", "116, 96, 76", 3.5, "116, 81, 20", 2.5};
// clang-format on

}  // namespace surge
