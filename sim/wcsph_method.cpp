// WCSPH's registration (sim/fluid_solver.h): its own scene keys, the defaults and notes it adds, and what it
// asks of a scene, beside its solver (sim/wcsph_solver.h).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "core/scene_fields.h"
#include "sim/wcsph_solver.h"
#include "sim/solver_defaults.h"
#include "sim/surface_tension.h"
#include "sim/viscosity.h"

namespace surge {
namespace {

// The method's own keys under `solver` (its registration hands them to the scene reader).
void declareWcsphKeys(SceneVisitor& v, SolverSettings& s) {
  using field::atLeast, field::info, field::positive;
  v.choice("equation_of_state", s.equation_of_state, {"tait", "linear"},
           info("WCSPH: tait, p = rho_0 c^2 / 7 ((rho / rho_0)^7 - 1); linear, p = k (rho - rho_0); negative "
                "pressures are clamped to 0"));
  v.real("speed_of_sound", s.speed_of_sound,
         atLeast(0, "WCSPH speed of sound c; 0 means 10 x the speed of a fall through the tank's height", "m/s"));
  v.real("gas_constant", s.gas_constant,
         atLeast(0, "WCSPH linear law's k; 0 means speed_of_sound^2", "m^2/s^2"));
  v.choice("integrator", s.integrator, {"velocity_verlet", "symplectic_euler"},
           info("WCSPH time integration: velocity Verlet (kick-drift-kick) or semi-implicit Euler"));
  v.real("artificial_viscosity", s.artificial_viscosity,
         atLeast(0,
                 "WCSPH: Monaghan's artificial viscosity alpha; 0 turns it off; left out: 0.05, or 0.01 in a 3D "
                 "scene with surface tension"));
  v.real("kinematic_viscosity", s.kinematic_viscosity,
         atLeast(0, "WCSPH: laminar viscosity nu (Morris 1997); 0 turns it off", "m^2/s"));
  v.real("near_pressure", s.near_pressure,
         atLeast(0, "WCSPH: near-pressure stiffness of Clavet et al. 2005's double density relaxation, as a "
                    "force; keeps surface particles apart; 0 turns it off", "m^2/s^2"));
}

// Monaghan's term is a viscosity nu = alpha c h / (2 (d + 2)): at alpha 0.05 and c = 10 m/s, 1.25e-5 m^2/s, twelve
// times water's. A 3D drop's l = 2 ringing follows it: 0.86 of Rayleigh's half period at 0.05, 0.95 at 0.01
// (DualSPHysics's usual alpha), where it still rounds. A 2D drop rings at Rayleigh's at 0.05 and rounds within
// 2% by 1.5 s (16.6% at 0.01), so 2D keeps it (docs/surface-tension.md, "WCSPH 3D by alpha").
void resolveWcsphDefaults(Scene& scene) {
  SolverSettings& s = scene.solver;
  if (std::isnan(s.artificial_viscosity) && scene.dimensions == 3 && sceneSurfaceTension(scene) > 0)
    s.artificial_viscosity = 0.01;
}

// The pressure only turns the energy of compression, which the fall gave, back into motion: a spacing a frame, so
// that a scene with nothing moving (no gravity) still has a runaway speed above zero.
int wcsphPushesPerFrame(const Scene&) { return 1; }

// A jittered start is compressed, and WCSPH gives that back as motion. Its explicit viscosity (Morris 1997)
// limits the step to 0.125 (h/2)^2 / nu (over d + 2 with the strain's operator, sim/viscosity.cpp): where that is
// under a quarter of the sound's step cfl (h/2) / c, the implicit solve takes the sound's (honey's rope at
// nu = 0.5: 166,667 steps a frame explicit, 692 implicit; docs/viscosity.md).
std::vector<std::string> wcsphNotes(const Scene& scene) {
  std::vector<std::string> notes;
  for (size_t i = 0; i < scene.fluids.size(); ++i)
    if (scene.fluids[i].jitter > 0) {
      notes.push_back("fluids[" + std::to_string(i) + "].jitter starts WCSPH's fluid compressed, and it gives that "
                      "energy back as motion (the energy account credits it in frame 1's source_work)");
      break;
    }
  if (sceneHasViscosity(scene) && !implicitViscosity(scene)) {
    const SolverSettings& s = scene.solver;
    const double viscous = explicitViscosityStep(scene, static_cast<float>(s.kernel_radius));
    const double sound = s.cfl * 0.5 * s.kernel_radius / s.speed_of_sound;
    if (viscous < 0.25 * sound) {
      char text[320];
      std::snprintf(text, sizeof text,
                    "WCSPH's explicit viscosity limits its step to %.3g s here, %.0f times shorter than the sound's "
                    "(about %.3g steps a frame): solver.viscosity_solver implicit takes the sound's step",
                    viscous, sound / viscous, 1 / (scene.output.fps * viscous));
      notes.push_back(text);
    }
  }
  return notes;
}

}  // namespace

// Less than PBF's 400 and 250 bytes a particle (no stored pair factors), counted as those.
const FluidMethod kWcsphMethod = {"wcsph", "weakly compressible SPH (Monaghan 1994, Becker & Teschner 2007)",
    &makeMethod<WcsphSolver, 2>, &makeMethod<WcsphSolver, 3>, 250, 400,
    &wcsphPushesPerFrame, &resolveWcsphDefaults, &wcsphNotes, &declareWcsphKeys,
    "a smaller solver.cfl or solver.time_step", false, nullptr, nullptr, 3.75, "126, 94, 47"};

}  // namespace surge
