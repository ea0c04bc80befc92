// What a scene's physics asks of the simulator, decided once here for every method from the registrations
// (sim/fluid_solver.h): the defaults the file left 0, the speed that marks a particle as run away, the memory a
// run needs, and the notes `surge sim` prints before it starts.
#pragma once

#include <string>
#include <vector>

#include "core/scene.h"

namespace surge {

// The volume of the scene's fluid at the start (m^3, m^2 in 2D): the boxes', and the shapes' (their mass
// properties; a shape's file is read).
double initialFluidVolume(const Scene& scene);
// The most particles a run can hold: the initial fluid's (shapes estimated from their volume) and all the
// emitters can make by the last frame.
size_t mostParticles(const Scene& scene);

// The fewest steps a frame with which a PBF column of fluid stays at rest: dt <= 0.9 spacing / sqrt(|g| H), H the
// depth of the pool the fluid settles into (its volume over the tank's floor, with what the emitters bring when
// neither a sink nor an open face lets it out). Each step gravity moves every
// particle by g dt^2, and a column of H / spacing layers sags by g dt^2 H / spacing before the iterations push it
// back; near a spacing the layers pass through each other and the pool boils (docs/speed-accuracy.md).
int stableSubsteps(const Scene& scene);
// That criterion's longest step for a column `depth` deep under gravity `g` (also PbfSolver::stableTimeStep's, on
// the deepest column as the fluid stands).
double depthStableStep(double spacing, double g, double depth);

// The fewest steps a frame with which the fastest emitter's jet moves at most half a spacing a step: faster,
// PBF's corrections push the layer just emitted back onto the next one's sites, which then stay empty (a 1 m/s
// inflow at spacing 0.01 delivered 90% of its flux at 4 steps a frame, all of it at 5; docs/sources.md).
int emitterSubsteps(const Scene& scene);

// Fills the solver keys the file left 0 (SolverDefaults, core/scene.h): solver.substeps to max(4,
// stableSubsteps, emitterSubsteps), speed_of_sound to ten times the fastest the water can move by falling through the tank,
// gas_constant to its square, and then the scene's method's own (FluidMethod::resolveDefaults).
void resolveSolverDefaults(Scene& scene);

// The speed that marks a particle as run away (a diverged solver): ten times the fastest the scene can give a
// particle, which is the sum of its initial speeds (fluid and emitters, bodies, with their spin over the tank's diagonal),
// twice the fastest collider (a wall moving at V throws what it meets at up to 2 V), the attractor's pull
// (sqrt(strength radius), the speed of a fall into it) and its own speed, a free fall across the tank's diagonal
// (sqrt(2 g L)), and the method's own push (a spacing each of FluidMethod::pushesPerFrame). Stable runs stay
// well under a tenth of it; a blow-up passes it within a few steps.
double runawaySpeed(const Scene& scene);
// The fastest the scene itself can move the fluid: runawaySpeed's terms but the method's push, not times ten.
double sceneSpeed(const Scene& scene);

// Bytes the scene's method needs per particle at peak (FluidMethod::bytesPerParticle).
size_t bytesPerParticleEstimate(int dimensions, const std::string& method);

// Refuses (InputError naming scene.source and particle_spacing) a scene whose particles would need more than
// 80% of memoryLimit() (core/process.h) to simulate, or more than 2^31 of them. Only the simulation asks:
// surfacing and rendering read frames one at a time, and a render node may have less memory than the
// simulation needed.
void checkSimulationMemory(const Scene& scene);

// The lines `surge sim` prints before it starts about the scene's settings (its method's), or none.
std::vector<std::string> solverNotes(const Scene& scene);

}  // namespace surge
