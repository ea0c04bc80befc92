#include "sim/solver_defaults.h"
#include "sim/surface_tension.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>

#include "core/errors.h"
#include "core/process.h"
#include "geometry/mass_properties.h"
#include "sim/fluid_solver.h"
#include "sim/sources.h"
#include "sim/viscosity.h"

namespace surge {
namespace {

// The fastest an emitter pushes fluid out (its speed, or a keyframe's).
double fastestEmitter(const Scene& scene) {
  double speed = 0;
  for (const EmitterSettings& e : scene.emitters) {
    speed = std::max(speed, e.speed);
    for (const EmitterKeyframe& k : e.motion) speed = std::max(speed, k.speed);
  }
  return speed;
}

// The smallest radius or half-width of the scene's moving solids of simple shape (spheres, capsules, cylinders,
// boxes; bodies and keyframed colliders), scaled, with its name; {0, ""} when it has none.
std::pair<double, std::string> smallestMovingSolid(const Scene& scene) {
  std::pair<double, std::string> smallest{0, ""};
  const auto consider = [&](const ColliderSettings& c) {
    double a = 0;
    if (c.shape == "sphere" || c.shape == "capsule" || c.shape == "cylinder") a = c.radius;
    else if (c.shape == "box" && !c.size.empty()) a = 0.5 * *std::min_element(c.size.begin(), c.size.end());
    a *= c.scale;
    if (a > 0 && (smallest.first == 0 || a < smallest.first)) smallest = {a, c.name};
  };
  for (const ColliderSettings& c : scene.colliders)
    if (!c.motion.empty()) consider(c);
  for (const BodySettings& b : scene.bodies) consider(b.solid);
  return smallest;
}

// A figure for a note, to three significant digits.
std::string threeFigures(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", value);
  return text;
}

// Viscous drag on solids depends on the step (docs/viscosity.md, "The pressure the viscosity solve sees"): DFSPH
// meets Faxen's within 10% at nu dt / a^2 <= 0.15 (a disc 4 spacings in radius; 0.76 of it at 0.93); PBF's falls
// short at any practical step and WCSPH's builds up through a run.
void viscousDragNote(const Scene& scene, std::vector<std::string>& notes) {
  if (!sceneHasViscosity(scene)) return;
  const auto [a, name] = smallestMovingSolid(scene);
  if (a == 0) return;
  if (scene.solver.method != "dfsph") {
    std::string method = scene.solver.method;
    for (char& c : method) c = char(std::toupper(static_cast<unsigned char>(c)));
    notes.push_back(method + "'s drag on a solid moving through a viscous fluid falls short where the "
                    "fluid must flow round it (a disc dragged through honey: PBF 0.35 of Faxen's drag at 4 steps a "
                    "frame; WCSPH's builds up through the run; along a flat plate it holds, 2.4% in couette); DFSPH "
                    "meets it within 10% at short steps (docs/viscosity.md)");
    return;
  }
  const double nu = largestViscosity(scene);
  const double step = scene.solver.time_step > 0 ? scene.solver.time_step
                                                 : 1 / (scene.output.fps * std::max(1, scene.solver.substeps));
  const double ratio = nu * step / (a * a);
  if (ratio <= 0.15) return;
  notes.push_back("the drag on a solid moving through a viscous fluid comes within 10% once nu dt / a^2 is under "
                  "0.15 (a its radius or half-width; DFSPH's disc felt 0.76 of it at 0.93): here it is " +
                  threeFigures(ratio) +
                  " for " + name + " (a = " + threeFigures(a) + " m) at the largest step, " + threeFigures(step) +
                  " s; solver.time_step " + threeFigures(0.15 * a * a / nu) + " gives 0.15 (docs/viscosity.md)");
}

}  // namespace

double initialFluidVolume(const Scene& scene) {
  const int d = scene.dimensions;
  double volume = 0;
  for (size_t i = 0; i < scene.fluids.size(); ++i) {
    const FluidBlock& fluid = scene.fluids[i];
    if (!fluid.shaped()) {
      volume += (fluid.box.max - fluid.box.min).head(d).prod();
      continue;
    }
    const ColliderShape shape = buildSolidShape(scene, fluid.solid, "fluids[" + std::to_string(i) + "]", true);
    volume += massProperties(shape, fluid.solid.scale, d, 1.0).volume;
  }
  return volume;
}

int stableSubsteps(const Scene& scene) {
  const int d = scene.dimensions;
  const Eigen::VectorXd gravity = scene.gravity.head(d);
  const double g = gravity.norm();
  if (!(g > 0)) return 1;
  // The depth of the pool the fluid settles into: its volume over the tank's floor, the floor being the tank's
  // section across the axis gravity is mostly along.
  int down = 0;
  gravity.cwiseAbs().maxCoeff(&down);
  double floor = 1;
  for (int k = 0; k < d; ++k)
    if (k != down) floor *= scene.domain.max[k] - scene.domain.min[k];
  // What the emitters bring stays, unless the tank lets fluid out.
  double volume = initialFluidVolume(scene);
  if (scene.sinks.empty() && scene.open.empty())
    volume += double(mostEmittedParticles(scene, scene.output.frames / scene.output.fps)) *
              std::pow(scene.particle_spacing, d);
  const double depth = std::min(volume / floor, scene.domain.max[down] - scene.domain.min[down]);
  if (!(depth > 0)) return 1;
  const double longest = depthStableStep(scene.particle_spacing, g, depth);
  const double steps = std::ceil(1.0 / (scene.output.fps * longest) - 1e-9);
  return int(std::min(steps, 100000.0));
}

double depthStableStep(double spacing, double g, double depth) {
  return g > 0 && depth > 0 ? 0.9 * spacing / std::sqrt(g * depth) : INFINITY;
}

int emitterSubsteps(const Scene& scene) {
  const double travel = 0.5 * scene.particle_spacing * scene.output.fps;  // half a spacing a step, per frame
  return int(std::min(std::ceil(fastestEmitter(scene) / travel - 1e-9), 100000.0));
}

void resolveSolverDefaults(Scene& scene) {
  SolverSettings& solver = scene.solver;
  if (solver.substeps == 0) solver.substeps = std::max({4, stableSubsteps(scene), emitterSubsteps(scene)});
  if (solver.speed_of_sound == 0) {
    // Ten times the fastest the water can move by falling through the tank (or by its initial velocity):
    // density then varies by about 1% (Monaghan 1994).
    double speed = std::sqrt(2 * scene.gravity.norm() * (scene.domain.max - scene.domain.min)[1]);
    for (const FluidBlock& fluid : scene.fluids) speed = std::max(speed, fluid.velocity.norm());
    speed = std::max(speed, fastestEmitter(scene));
    solver.speed_of_sound = 10 * std::max(speed, 1.0);
  }
  if (solver.gas_constant == 0) solver.gas_constant = solver.speed_of_sound * solver.speed_of_sound;
  // The strain's operator is stiff along a rope: at 0.01 its warm-started solve lags and a column of honey creeps
  // in jerks at 2.5 times Trouton's rate (docs/viscosity.md).
  if (solver.viscosity_max_error == 0)
    solver.viscosity_max_error = solver.viscosity_operator == "strain" ? 1e-3 : 1e-2;
  const FluidMethod& method = fluidMethod(solver.method, scene.source);
  if (method.resolveDefaults) method.resolveDefaults(scene);
}

double sceneSpeed(const Scene& scene) {
  const int d = scene.dimensions;
  const double diagonal = (scene.domain.max - scene.domain.min).head(d).norm();
  double fluid = 0, bodies = 0, colliders = 0, attractor = 0;
  for (const FluidBlock& block : scene.fluids) fluid = std::max(fluid, block.velocity.head(d).norm());
  fluid = std::max(fluid, fastestEmitter(scene));
  for (const BodySettings& body : scene.bodies)
    bodies = std::max(bodies, body.velocity.head(d).norm() + body.angular_velocity.norm() * diagonal);
  for (const ColliderSettings& collider : scene.colliders)
    for (size_t k = 1; k < collider.motion.size(); ++k) {
      const ColliderKeyframe &a = collider.motion[k - 1], &b = collider.motion[k];
      const double dt = b.time - a.time;
      if (!(dt > 0)) continue;
      const double turn = std::abs(b.rotation.degrees - a.rotation.degrees) * M_PI / 180.0 +
                          (a.rotation.axis != b.rotation.axis ? 2 * M_PI : 0.0);
      colliders = std::max(colliders, ((b.position - a.position).head(d).norm() + turn * diagonal) / dt);
    }
  if (!scene.attractor.keyframes.empty()) {
    double moving = 0;  // the attractor's fastest keyframed speed
    for (size_t k = 1; k < scene.attractor.keyframes.size(); ++k) {
      const AttractorKeyframe &a = scene.attractor.keyframes[k - 1], &b = scene.attractor.keyframes[k];
      if (b.time > a.time) moving = std::max(moving, (b.position - a.position).head(d).norm() / (b.time - a.time));
    }
    attractor = std::sqrt(std::abs(scene.attractor.strength) * scene.attractor.radius) + moving;
  }
  const double fall = std::sqrt(2 * scene.gravity.head(d).norm() * diagonal);
  // Surface energy turned into motion: a capillary wave a spacing long moves at about sqrt(2 sigma / (rho_0 dx)).
  const double capillary = std::sqrt(2 * sceneSurfaceTension(scene) / (scene.solver.rest_density * scene.particle_spacing));
  return fluid + bodies + 2 * colliders + attractor + fall + capillary;
}

double runawaySpeed(const Scene& scene) {
  const double solver = scene.particle_spacing * scene.output.fps *
                        fluidMethod(scene.solver.method, scene.source).pushesPerFrame(scene);
  return 10 * (sceneSpeed(scene) + solver);
}

size_t bytesPerParticleEstimate(int dimensions, const std::string& method) {
  const FluidMethod& m = fluidMethod(method);
  return dimensions == 3 ? m.bytesPerParticle3d : m.bytesPerParticle2d;
}

size_t mostParticles(const Scene& scene) {
  const bool shaped =
      std::any_of(scene.fluids.begin(), scene.fluids.end(), [](const FluidBlock& f) { return f.shaped(); });
  const size_t initial =
      shaped ? size_t(initialFluidVolume(scene) / std::pow(scene.particle_spacing, scene.dimensions)) + 1
             : scene.particleCount();
  return initial + mostEmittedParticles(scene, scene.output.frames / scene.output.fps);
}

void checkSimulationMemory(const Scene& scene) {
  const size_t count = mostParticles(scene);
  const double bytes = double(count) * double(bytesPerParticleEstimate(scene.dimensions, scene.solver.method));
  const MemoryLimit memory = memoryLimit();
  if (count > (size_t(1) << 31) || bytes > 0.8 * memory.bytes)
    throw InputError(scene.source, "particle_spacing",
                     std::to_string(count) + " particles need about " + formatBytes(bytes) + " to simulate, more than " +
                         memory.source + " " + formatBytes(memory.bytes) + " allow (80%)");
}

std::vector<std::string> solverNotes(const Scene& scene) {
  const FluidMethod& method = fluidMethod(scene.solver.method, scene.source);
  std::vector<std::string> notes = method.notes ? method.notes(scene) : std::vector<std::string>{};
  // Adhesion is a share of the fluid's cohesion (sim/surface_tension.h): without surface tension it does nothing.
  if (sceneHasAdhesion(scene) && sceneSurfaceTension(scene) == 0)
    notes.push_back("adhesion is set on a collider or body, but the fluid has no surface_tension: adhesion is a "
                    "share of the fluid's cohesion and does nothing without it");
  const double support = scene.solver.kernel_radius / scene.particle_spacing, own = defaultKernelSupport(scene);
  const bool adhesion = sceneHasAdhesion(scene) && sceneSurfaceTension(scene) > 0;
  std::string name = method.name;
  std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return char(std::toupper(c)); });
  // In 3D the adhesion's calibration is measured at 2, 2.5 and 3 spacings of support (adhesionCalibration).
  if (adhesion && scene.dimensions == 3 && adhesionCalibration(3, support) == 0) {
    notes.push_back(
        "adhesion is calibrated at 2, 2.5 and 3 spacings of kernel support (a drop on a plate at 116, 88, 64, "
        "117, 93, 61 and 120, 91, 53 degrees at adhesion 0.25, 0.5, 0.75, Young's 120, 90, 60); with " +
        threeFigures(support) +
        " spacings it may not give Young's angle: measured, 2.25 wets more (113 and 76 degrees at 0.25 and "
        "0.5, a film at 0.75) (docs/surface-tension.md)");
  }
  // It meets Young's angle in DFSPH and WCSPH; where a method's does not, its registration gives the angles it reads at
  // the 3D default support (FluidMethod::adhesionAngles).
  if (adhesion && scene.dimensions == 3 && method.adhesionAngles) {
    notes.push_back(
        "adhesion is calibrated in DFSPH (a drop on a plate at 117, 93, 61 degrees for adhesion 0.25, 0.5, "
        "0.75 at 2.5 spacings of kernel support; Young's 120, 90, 60); in " +
        name + " the same drop reads " + method.adhesionAngles +
        " degrees: its contact line comes to rest anywhere within a wider band about Young's angle than DFSPH's, "
        "and a drop set down square rests at the band's edge (docs/surface-tension.md, \"Advancing and receding\")");
  }
  // In 2D each method's angles are measured at its own 2D support (FluidMethod::adhesionAngles2d).
  if (adhesion && scene.dimensions == 2 && method.adhesionAngles2d) {
    const std::string elsewhere =
        std::abs(support - own) > 0.05 ? "; at this scene's " + threeFigures(support) + " it is not measured" : "";
    notes.push_back("adhesion in 2D: a 12 mm square of water on a plate in " + name + " at its own " +
                    threeFigures(own) + " spacings of kernel support reads " + method.adhesionAngles2d +
                    " degrees at adhesion 0.25, 0.5, 0.75, where Young's angle is 120, 90, 60" + elsewhere +
                    " (docs/surface-tension.md)");
  }
  // Cohesion over 2 spacings of support holds the lattice: in 2D as a crystal, in 3D in a set; the default's
  // wider support (defaultKernelSupport) lets a drop round and ring (docs/surface-tension.md, "The 2D support",
  // "The 3D support"). In 2D a support from the method's roundingSupport2d up rounds a drop too.
  const double rounds = scene.dimensions == 2 ? std::min(own, method.roundingSupport2d) : own;
  if (sceneSurfaceTension(scene) > 0 && support < rounds - 1e-9) {
    const bool flat = scene.dimensions == 2;
    char text[400];
    std::snprintf(text, sizeof text,
                  "surface tension in %dD with %.3g spacings of kernel support holds the particles %s; "
                  "solver.kernel_radius 0 gives %s%.3g spacings (%g here), with which %s (docs/surface-tension.md)",
                  scene.dimensions, support,
                  flat ? "as a crystal: a drop keeps its shape instead of rounding"
                       : "in a set: at 2 a 2:1:1 box of water stays 2.3% off round and a drop does not ring at "
                         "Rayleigh's frequency",
                  flat ? (name + " ").c_str() : "", own, own * scene.particle_spacing, flat ? "it rounds" : "they do");
    notes.push_back(text);
  }
  // The transport velocity pushes particles out of a free surface.
  if (scene.solver.background_pressure > 0) {
    double tank = 1;
    for (int k = 0; k < scene.dimensions; ++k) tank *= scene.domain.max[k] - scene.domain.min[k];
    const double fluid = double(scene.particleCount()) * std::pow(scene.particle_spacing, scene.dimensions);
    if (!scene.emitters.empty() || fluid < 0.99 * tank)
      notes.push_back("solver.background_pressure pushes the particles of a free surface out of it: it is meant for "
                      "fluid that fills its domain (a periodic box, a closed cavity), and this fluid fills " +
                      std::to_string(int(std::lround(100 * fluid / tank))) + "% of the tank");
  }
  viscousDragNote(scene, notes);
  return notes;
}

}  // namespace surge
