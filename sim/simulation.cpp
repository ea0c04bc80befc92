#include "sim/simulation.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "core/errors.h"
#include "core/expression.h"
#include "core/parallel.h"
#include "core/scene_fields.h"
#include "geometry/collider_shape.h"
#include "geometry/pose.h"
#include "sim/attractor.h"
#include "sim/energy_ledger.h"
#include "sim/surface_tension.h"
#include "sim/fluid_solver.h"
#include "sim/frame_outputs.h"
#include "sim/rigid_bodies.h"
#include "sim/sources.h"
#include "sim/solver_defaults.h"
#include "sim/viscosity.h"

namespace surge {
namespace {

std::string formatVector(const Eigen::Vector3f& v, int dimensions) {
  std::ostringstream out;
  out << "(" << v.x() << ", " << v.y();
  if (dimensions == 3) out << ", " << v.z();
  out << ")";
  return out.str();
}

void removeStaleFiles(const fs::path& folder, bool framesToo) {
  std::error_code error;
  if (!fs::is_directory(folder, error)) return;
  for (const auto& entry : fs::directory_iterator(folder)) {
    const std::string name = entry.path().filename().string();
    const bool temporary = name.find(".tmp") != std::string::npos;
    if (temporary || (framesToo && name.rfind("frame_", 0) == 0)) fs::remove(entry.path(), error);
  }
}

// The x wall the fluid started against: +1 for domain.min.x, -1 for domain.max.x.
int startWallSide(const Scene& scene) {
  if (scene.fluids.empty() || scene.fluids.front().shaped()) return 1;
  const Box& box = scene.fluids.front().box;
  const double tolerance = 0.5 * scene.particle_spacing;
  if (box.min.x() <= scene.domain.min.x() + tolerance) return 1;
  if (box.max.x() >= scene.domain.max.x() - tolerance) return -1;
  return box.min.x() - scene.domain.min.x() <= scene.domain.max.x() - box.max.x() ? 1 : -1;
}

// From the sorted values, starting at index `start`, the last value reached by steps shorter than `gap`.
float walkWhileContiguous(const std::vector<float>& sorted, size_t start, float gap) {
  size_t i = start;
  while (i + 1 < sorted.size() && sorted[i + 1] - sorted[i] < gap) ++i;
  return sorted[i];
}

[[noreturn]] void diverged(const Scene& scene, int frame, int substep, long particle, const ParticleFrame& state) {
  char limit[32];
  std::snprintf(limit, sizeof limit, "%.4g", runawaySpeed(scene));
  throw RunError("simulation diverged at frame " + std::to_string(frame) + ", substep " + std::to_string(substep) +
                 ": particle " + std::to_string(particle) + " (id " + std::to_string(state.id[particle]) + ") at " +
                 formatVector(state.position[particle], state.dimensions) + " with velocity " +
                 formatVector(state.velocity[particle], state.dimensions) +
                 " (not finite, outside the domain, or faster than " + limit +
                 " m/s, ten times the fastest the scene can give it)");
}

// The work the attractor's kick of a step dt from `time` does on the fluid (J): sum of m a . (v + a dt / 2) dt
// at the step's start, a = a(x). Exact for a method that kicks first (PBF, DFSPH: v += dt a, so the kinetic
// energy gains m a . v dt + m |a|^2 dt^2 / 2); in the solver's order.
template <int Dim>
double attractorWork(const Attractor<Dim>& attractor, const FluidSolver<Dim>& solver, double time, float dt) {
  const Vec<Dim> centre = attractor.position(time);
  const std::vector<Vec<Dim>>&x = solver.positions(), &v = solver.velocities();
  const double work = parallelSum<double>(0, x.size(), [&](size_t b, size_t e) {
    double sum = 0;
    for (size_t i = b; i < e; ++i) {
      const Vec<Dim> a = attractor.acceleration(x[i], centre);
      sum += double(a.dot(v[i] + 0.5f * dt * a));
    }
    return sum;
  });
  return solver.particleMass() * work * dt;
}

// Gravity along a periodic axis (domain.periodic) has no floor to stand against: a particle that falls through
// the seam comes back in on the other side. Its pull is work done on the fluid, counted as the attractor's is
// above, and GravityPotential leaves it out.
template <int Dim>
double periodicGravityWork(const Vec<Dim>& g, const FluidSolver<Dim>& solver, float dt) {
  const std::vector<Vec<Dim>>& v = solver.velocities();
  const std::vector<float>& ratio = solver.massRatios();
  const double work = parallelSum<double>(0, v.size(), [&](size_t b, size_t e) {
    double sum = 0;
    for (size_t i = b; i < e; ++i) sum += double(g.dot(v[i] + 0.5f * dt * g)) * (ratio.empty() ? 1.0f : ratio[i]);
    return sum;
  });
  return solver.particleMass() * work * dt;
}

// The particles run() starts from: the newest frame of a resumed run (with the method's carried state and the
// bodies' states there), or the scene's fluid less what lies inside colliders and bodies. Returns the initial
// lattice's count, where the emitters' ids begin.
template <int Dim>
uint32_t startParticles(const Scene& scene, const fs::path& dir, bool resume, FluidSolver<Dim>& solver,
                        RigidBodies* bodies, SimulationSummary& summary) {
  const std::vector<int> existing = resume ? listFrames(dir, "particles", "ply") : std::vector<int>{};
  if (existing.empty()) {
    ParticleFrame initial = initialParticles(scene);
    const auto firstEmittedId = static_cast<uint32_t>(initial.size());
    if (!scene.colliders.empty() || bodies) {
      summary.removedParticles = removeParticlesInside(solver.colliders(), initial);
      if (initial.size() == 0 && scene.emitters.empty())
        throw InputError(scene.source, scene.colliders.empty() ? "bodies" : "colliders",
                         "every fluid particle lies inside a collider or a body");
    }
    solver.setParticles(initial);
    return firstEmittedId;
  }
  summary.firstFrame = std::min(existing.back(), scene.output.frames);
  const fs::path path = framePath(dir, "particles", summary.firstFrame, "ply");
  const ParticleFrame frame = readParticlePly(path);
  if (frame.dimensions != Dim) throw InputError(path.string(), "dimensions", "differs from the scene's");
  solver.setParticles(frame);
  const size_t carried = solver.carriedState().size();
  if (carried > 0 && summary.firstFrame < scene.output.frames)
    solver.restoreCarriedState(readCarriedState(dir, summary.firstFrame, carried));
  if (bodies) bodies->setStates(readBodyStates(framePath(dir, "bodies", summary.firstFrame, "txt"), scene));
  // A resumed run's emitters go on from the initial lattice's count; without emitters it is not needed.
  return scene.emitters.empty() ? 0 : static_cast<uint32_t>(initialParticles(scene).size());
}

}  // namespace

FrameSteps::FrameSteps(double frameDuration, int fixedSubsteps)
    : remaining_(frameDuration),
      fixed_(fixedSubsteps > 0 ? static_cast<float>(frameDuration / fixedSubsteps) : 0),
      fixedSubsteps_(fixedSubsteps) {}

float FrameSteps::next(double stable) {
  float dt;
  if (fixed_ > 0 && !shortened_ && stable >= fixed_) {
    dt = fixed_;
    remaining_ = steps_ + 1 == fixedSubsteps_ ? 0 : remaining_ - dt;
  } else {
    shortened_ = fixed_ > 0;
    const double longest = fixed_ > 0 ? std::min<double>(stable, fixed_) : stable;
    const double count = std::max(1.0, std::ceil(remaining_ / longest - 1e-9));
    dt = static_cast<float>(remaining_ / count);
    remaining_ = count == 1 ? 0 : remaining_ - dt;
  }
  ++steps_;
  return dt;
}

std::string densityCapReport(const SimulationSummary& summary) {
  return "stopped at its cap of " + std::to_string(summary.iterationCap) + " iterations in " +
         std::to_string(summary.cappedSteps) + " of " + std::to_string(summary.steps) + " steps (frames " +
         std::to_string(summary.firstCappedFrame) + "-" + std::to_string(summary.lastCappedFrame) + ")";
}

namespace {

// The frame loop, for any solver, its steps as FrameSteps chooses them (a frame whose steps all meet the stable
// step runs as before the need was checked). Each frame's record goes to every FrameOutput. The constructor sets the run up and writes frame 0 (when it starts afresh); stepFrame() runs one
// frame and writes it.
template <int Dim>
class FrameLoop final : public SimulationRun {
 public:
  FrameLoop(const Scene& scene, std::shared_ptr<const ColliderShapes> shapes, const fs::path& dir, bool resume)
      : scene_(scene), frameDuration_(1.0 / scene.output.fps), attractor_(scene.attractor) {
    for (int k = 0; k < Dim; ++k)
      if (scene.isPeriodic(k)) periodicGravity_[k] = static_cast<float>(scene.gravity[k]);
    // Everything below is made from the run's own copy of the scene, which lives as long as it does.
    removeStaleFiles(dir / "particles", !resume);
    removeStaleFiles(dir / "solver", !resume);
    fs::create_directories(dir / "particles");

    method_ = makeFluidSolver<Dim>(scene_, shapes);
    FluidSolver<Dim>& solver = *method_;
    if (!scene_.bodies.empty()) {
      bodies_ = std::make_unique<RigidBodies>(scene_, shapes);
      std::error_code error;
      if (!resume) fs::remove_all(dir / "bodies", error);
      fs::create_directories(dir / "bodies");
    }
    const uint32_t firstEmittedId = startParticles<Dim>(scene_, dir, resume, solver, bodies_.get(), summary_);
    const bool fresh = !resume || listFrames(dir, "particles", "ply").empty();
    if (scene_.hasSources()) {
      sources_ = std::make_unique<FluidSources<Dim>>(scene_, firstEmittedId, summary_.firstFrame * frameDuration_);
      if (fresh) sources_->checkStart(solver.positions(), solver.colliders());
    }
    outputs_ = makeFrameOutputs(scene_, shapes, bodies_.get(), dir, resume, !fresh, summary_.firstFrame);
    record_.particles = &frame_;
    const FluidMethod& registered = fluidMethod(scene_.solver.method, scene_.source);
    // The ledger's floor is the fluid moving at a hundredth of the scene's speed, or of a spacing a frame where
    // the scene gives it none (zero gravity, nothing moving): what rounding stirs in a fluid at rest is no gain.
    const double speed = sceneSpeed(scene_);
    // A nozzle holding a viscous thread does work on it that the account sees only in part (a honey thread
    // hanging from it gains 3 to 5% in its first 0.1 s in DFSPH and PBF, docs/viscosity.md): the account is
    // kept without stopping, as for a method whose nozzle it cannot see.
    const bool accounted = scene_.emitters.empty() || (registered.emittersAccounted && !sceneHasViscosity(scene_));
    ledger_ = std::make_unique<EnergyLedger>(Dim, speed > 0 ? speed : scene_.particle_spacing * scene_.output.fps,
                                             registered.steadier ? registered.steadier : "shorter steps", accounted);
    if (!fresh) ledger_->resume(dir / "stats.csv", summary_.firstFrame);
    // What surface tension may release (sim/surface_tension.h); a resumed run counts it again from its first frame.
    surfaceEnergy_ = sceneSurfaceTension(scene_) > 0 ? surfaceEnergyBound(scene_, initialParticles(scene_)) : 0;
    frameIndex_ = summary_.firstFrame;
    if (fresh) {
      // Measured first: before the first step, measuring sorts the particles into cells, and frame 0 must hold
      // them in the order the run goes on with, or a run resumed from it sums its neighbours in another order.
      record_.measures = solver.measure();
      solver.getParticles(frame_);
      if (solver.lastDivergenceIterations() >= 0) record_.divergenceIterations = 0;
      if (solver.lastViscosityIterations() >= 0) record_.viscosityIterations = 0;
      writeFrame();
      // A jittered start's compression, which a compressible method gives back as motion, is a source's work
      // (in frame 1's source_work).
      if (std::any_of(scene_.fluids.begin(), scene_.fluids.end(), [](const FluidBlock& f) { return f.jitter > 0; }))
        ledger_->add(solver.compressionEnergy());
    }
  }

  int frame() const override { return frameIndex_; }
  double time() const override { return frameIndex_ * frameDuration_; }
  int dimensions() const override { return Dim; }
  size_t size() const override { return method_->size(); }
  const float* positions() const override { return method_->positions().data()->data(); }
  const float* velocities() const override { return method_->velocities().data()->data(); }
  const uint32_t* ids() const override { return method_->ids().data(); }
  const SimulationSummary& summary() const override { return summary_; }
  double pressureWithin(const std::vector<double>& centre, double radius) override {
    Vec<Dim> c;
    for (int k = 0; k < Dim; ++k) c[k] = static_cast<float>(centre.at(k));
    return method_->virialPressureWithin(c, static_cast<float>(radius));
  }

  bool stepFrame() override {
    if (frameIndex_ >= scene_.output.frames) return false;
    const int f = ++frameIndex_;
    FluidSolver<Dim>& solver = *method_;
    EnergyLedger& ledger = *ledger_;
    const auto frameStart = std::chrono::steady_clock::now();
    solver.phaseTimes() = PhaseTimes{};
    if (sources_) {
      sources_->emitted = sources_->removed = 0;
      sources_->work = 0;
    }
    double time = (f - 1) * frameDuration_;
    solver.beginFrame(time);
    if (bodies_) {
      bodies_->beginFrame(time);
      placeBodies(*bodies_, solver.colliders());
    }
    int iterations = 0, divergenceIterations = 0, viscosityIterations = 0, steps = 0;
    float smallestStep = INFINITY;
    FrameSteps schedule(frameDuration_, solver.fixedSubsteps());
    constexpr int kMostSteps = 1000000;
    while (!schedule.done()) {
      const float dt = schedule.next(solver.stableTimeStep());
      long badBody = -1;
      if (attractor_.active()) ledger.add(attractorWork(attractor_, solver, time, dt));
      if (!periodicGravity_.isZero()) ledger.add(periodicGravityWork(periodicGravity_, solver, dt));
      const long bad = coupledStep<Dim>(solver, bodies_.get(), dt, time, badBody);
      time += dt;
      if (badBody >= 0)
        throw RunError("simulation diverged at frame " + std::to_string(f) + ", substep " + std::to_string(steps) +
                       ": body " + scene_.bodies[badBody].solid.name + " (its state is not finite)");
      smallestStep = std::min(smallestStep, dt);
      iterations += solver.lastIterations();
      if (solver.densityIterationCap() > 0 && solver.lastIterations() >= solver.densityIterationCap()) {
        if (summary_.cappedSteps++ == 0) summary_.firstCappedFrame = f;
        summary_.lastCappedFrame = f;
        summary_.iterationCap = solver.densityIterationCap();
      }
      divergenceIterations += solver.lastDivergenceIterations();
      viscosityIterations += solver.lastViscosityIterations();
      if (bad >= 0) {
        solver.getParticles(frame_);
        diverged(scene_, f, steps, bad, frame_);
      }
      if (sources_) sources_->apply(solver, time);
      if (++steps >= kMostSteps)
        throw RunError("simulation stalled at frame " + std::to_string(f) + ": a million steps of " +
                       std::to_string(dt) + " s did not finish the frame (the stable step collapsed)");
    }
    record_ = FrameRecord{};
    record_.particles = &frame_;
    record_.frame = f;
    record_.time = f * frameDuration_;
    record_.measures = solver.measure();
    solver.getParticles(frame_);
    record_.steps = steps;
    summary_.steps += size_t(steps);
    record_.iterations = double(iterations) / steps;
    record_.divergenceIterations = divergenceIterations < 0 ? NAN : double(divergenceIterations) / steps;
    record_.viscosityIterations = viscosityIterations < 0 ? NAN : double(viscosityIterations) / steps;
    record_.smallestStep = smallestStep;
    record_.pressureMax = solver.maxPressure();
    if (sources_) {
      record_.emitted = sources_->emitted;
      record_.removed = sources_->removed;
      ledger.add(sources_->work);
    }
    // Surface tension's work is surface energy released: credited from none up to the most the fluid's surface
    // held. Below none it is credited none: a WCSPH pool at rest sums -8e-4 J/m a frame with no surface stored
    // (docs/surface-tension.md, "A pool under gravity"); a splash that does store some is checked the more loosely.
    forceWork_ += solver.takeForceWork();
    const double credit = std::clamp(forceWork_, 0.0, surfaceEnergy_) - forceCredited_;
    ledger.add(credit);
    forceCredited_ += credit;
    record_.phases = solver.phaseTimes();
    record_.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - frameStart).count();
    if (!scene_.colliders.empty() || bodies_) {
      std::vector<Wrench> wrenches = solver.takeColliderWrenches(frameDuration_);
      const auto firstBody = wrenches.begin() + std::ptrdiff_t(scene_.colliders.size());
      record_.bodyWrenches.assign(firstBody, wrenches.end());
      record_.colliderWrenches.assign(wrenches.begin(), firstBody);
      for (const Wrench& w : wrenches) ledger.add(w.work);
    }
    writeFrame();
    return true;
  }

 private:
  void writeFrame() {
    FluidSolver<Dim>& solver = *method_;
    record_.dam = measureDamBreak(scene_, frame_);
    record_.potentialEnergy = potentialEnergy(scene_, frame_, solver.particleMass());
    record_.sourceWork = ledger_->sourceWork();
    if (record_.frame == 0) ledger_->start(record_.measures.kineticEnergy, record_.potentialEnergy);
    else
      try {
        ledger_->check(record_.frame, record_.measures.kineticEnergy, record_.potentialEnergy,
                       solver.particleMass() * double(frame_.size()));
      } catch (const RunError& stop) {
        // Where the density solver stopped at its cap, more iterations are the remedy too.
        const char* key = fluidMethod(scene_.solver.method, scene_.source).iterationCapKey;
        if (summary_.cappedSteps == 0 || !key) throw;
        throw RunError(std::string(stop.what()) + "; its density solver " + densityCapReport(summary_) +
                       ", where a larger " + key + " lets it converge");
      }
    record_.carriedState = solver.carriedState();
    for (const std::unique_ptr<FrameOutput>& output : outputs_) output->write(record_);
  }

  const Scene scene_;
  const double frameDuration_;
  const Attractor<Dim> attractor_;
  Vec<Dim> periodicGravity_ = Vec<Dim>::Zero();  // gravity's components along the periodic axes
  std::unique_ptr<FluidSolver<Dim>> method_;
  std::unique_ptr<RigidBodies> bodies_;
  std::unique_ptr<FluidSources<Dim>> sources_;
  std::vector<std::unique_ptr<FrameOutput>> outputs_;
  std::unique_ptr<EnergyLedger> ledger_;
  SimulationSummary summary_;
  ParticleFrame frame_;
  FrameRecord record_;
  double surfaceEnergy_ = 0, forceWork_ = 0, forceCredited_ = 0;
  int frameIndex_ = 0;
};

// A fluid given as a shape: the sites of the tank's lattice (domain.min + spacing (i + 1/2)) inside it.
void addShapedFluid(const Scene& scene, size_t index, ParticleFrame& frame) {
  const FluidBlock& fluid = scene.fluids[index];
  const std::string key = "fluids[" + std::to_string(index) + "]";
  const ColliderShape shape = buildSolidShape(scene, fluid.solid, key, true);
  const Pose pose = colliderPose(fluid.solid, 0.0);
  const Eigen::AlignedBox3d world = worldBounds(shape, pose);
  const double s = scene.particle_spacing;
  Eigen::Array3i lo(0, 0, 0), hi(0, 0, 0);
  for (int k = 0; k < scene.dimensions; ++k) {
    const double min = std::max(world.min()[k], scene.domain.min[k]), max = std::min(world.max()[k], scene.domain.max[k]);
    lo[k] = static_cast<int>(std::floor((min - scene.domain.min[k]) / s));
    hi[k] = static_cast<int>(std::ceil((max - scene.domain.min[k]) / s));
  }
  const size_t before = frame.size();
  for (int k = lo[2]; k <= hi[2]; ++k)
    for (int j = lo[1]; j <= hi[1]; ++j)
      for (int i = lo[0]; i <= hi[0]; ++i) {
        Eigen::Vector3d p = scene.domain.min + s * Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5);
        if (scene.dimensions == 2) p.z() = 0;
        if (((p - scene.domain.min).head(scene.dimensions).array() < 0).any() ||
            ((scene.domain.max - p).head(scene.dimensions).array() < 0).any())
          continue;
        if (!(shape.distance(pose.toLocal(p).cast<float>()) < 0)) continue;
        frame.position.push_back(p.cast<float>());
        frame.velocity.push_back(fluid.velocity.cast<float>());
        frame.id.push_back(static_cast<uint32_t>(frame.id.size()));
      }
  if (frame.size() == before)
    throw InputError(scene.source, key, "the shape holds no lattice site at particle_spacing " + formatNumber(s));
}

template <int Dim>
void checkStart(const Scene& scene, std::shared_ptr<const ColliderShapes> shapes) {
  ParticleFrame initial = initialParticles(scene);  // refuses a shape that holds no site, an open mesh, a formula
  if (!scene.hasSources()) return;
  const std::unique_ptr<FluidSolver<Dim>> solver = makeFluidSolver<Dim>(scene, std::move(shapes));
  if (hasSolids(scene)) removeParticlesInside(solver->colliders(), initial);
  std::vector<Vec<Dim>> positions(initial.size());
  for (size_t i = 0; i < initial.size(); ++i) positions[i] = initial.position[i].head<Dim>();
  FluidSources<Dim>(scene, 0, 0.0).checkStart(positions, solver->colliders());
}

}  // namespace

void checkSimulationStart(const Scene& scene, std::shared_ptr<const ColliderShapes> shapes) {
  // A shape that holds no site, a formula not finite somewhere in its block: found by initialParticles.
  const bool built = std::any_of(scene.fluids.begin(), scene.fluids.end(),
                                 [](const FluidBlock& f) { return f.shaped() || !f.velocity_field.empty(); });
  if (!built && !scene.hasSources()) return;
  if (scene.dimensions == 2) checkStart<2>(scene, std::move(shapes));
  else checkStart<3>(scene, std::move(shapes));
}

double potentialEnergy(const Scene& scene, const ParticleFrame& frame, double particleMass) {
  const GravityPotential potential(scene);
  double sum = 0;
  if (frame.fluid.empty()) {
    for (const Eigen::Vector3f& x : frame.position) sum += potential.at(x.cast<double>());
    return particleMass * sum;
  }
  // Several fluids: each particle's mass is its fluid's density on the lattice's volume.
  for (size_t i = 0; i < frame.size(); ++i)
    sum += scene.fluids[frame.fluid[i]].rest_density * potential.at(frame.position[i].cast<double>());
  return particleMass / scene.referenceDensity() * sum;
}

DamBreakMeasures measureDamBreak(const Scene& scene, const ParticleFrame& frame) {
  DamBreakMeasures m;
  if (frame.size() == 0) return m;
  const int side = startWallSide(scene);
  const double wall = side > 0 ? scene.domain.min.x() : scene.domain.max.x();
  const float gap = static_cast<float>(scene.solver.kernel_radius > 0 ? scene.solver.kernel_radius
                                                                        : 2 * scene.particle_spacing);
  const double radius = 0.5 * scene.particle_spacing;
  std::vector<float> distance(frame.size()), height;
  for (size_t i = 0; i < frame.size(); ++i) {
    const float d = static_cast<float>(side * (frame.position[i].x() - wall));
    distance[i] = d;
    if (d < gap) height.push_back(static_cast<float>(frame.position[i].y() - scene.domain.min.y()));
  }
  std::sort(distance.begin(), distance.end());
  m.frontX = walkWhileContiguous(distance, distance.size() / 2, gap) + radius;
  std::sort(height.begin(), height.end());
  if (!height.empty() && height.front() < gap) m.backHeight = walkWhileContiguous(height, 0, gap) + radius;
  return m;
}

bool isDamBreak(const Scene& scene) {
  if (scene.fluids.size() != 1 || scene.fluids.front().shaped()) return false;
  const Box& box = scene.fluids.front().box;
  const double tolerance = 0.5 * scene.particle_spacing;
  const bool onFloor = box.min.y() <= scene.domain.min.y() + tolerance;
  const bool atMin = box.min.x() <= scene.domain.min.x() + tolerance;
  const bool atMax = box.max.x() >= scene.domain.max.x() - tolerance;
  return onFloor && atMin != atMax;
}

// A fixed number in [-0.5, 0.5) for particle `id` and axis `k` (SplitMix64's finaliser): the same for a particle
// whatever the thread count or the run, so that a jittered start (fluids[i].jitter) is reproducible.
static double latticeJitter(uint32_t id, int k) {
  uint64_t z = (uint64_t(id) << 2 | uint64_t(k)) + 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  z ^= z >> 31;
  return double(z >> 11) * 0x1.0p-53 - 0.5;
}

// fluids[f].velocity_field, each component's formula at each particle's starting place, added to its velocity.
static void addVelocityField(const Scene& scene, size_t f, size_t first, ParticleFrame& frame) {
  for (int k = 0; k < scene.dimensions; ++k) {
    const std::string& text = scene.fluids[f].velocity_field[k];
    const Expression formula(text);  // the scene's reader has parsed it once already
    for (size_t i = first; i < frame.size(); ++i) {
      const double value = formula(frame.position[i].cast<double>());
      if (!std::isfinite(value))
        throw InputError(scene.source, "fluids[" + std::to_string(f) + "].velocity_field[" + std::to_string(k) + "]",
                         "'" + text + "' is not finite at " + formatVector(frame.position[i], scene.dimensions));
      frame.velocity[i][k] += static_cast<float>(value);
    }
  }
}

ParticleFrame initialParticles(const Scene& scene) {
  ParticleFrame frame;
  frame.dimensions = scene.dimensions;
  const size_t total = scene.particleCount();
  frame.position.reserve(total);
  frame.velocity.reserve(total);
  frame.id.reserve(total);
  const double spacing = scene.particle_spacing;
  const bool several = scene.severalFluids();
  for (size_t f = 0; f < scene.fluids.size(); ++f) {
    const FluidBlock& fluid = scene.fluids[f];
    const size_t first = frame.size();
    if (fluid.shaped()) {
      addShapedFluid(scene, f, frame);
    } else {
      const Eigen::Array3i n = latticeCounts(scene, fluid.box);
      for (int k = 0; k < n[2]; ++k)
        for (int j = 0; j < n[1]; ++j)
          for (int i = 0; i < n[0]; ++i) {
            Eigen::Vector3d p = fluid.box.min + spacing * Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5);
            if (scene.dimensions == 2) p.z() = 0;
            frame.position.push_back(p.cast<float>());
            frame.velocity.push_back(fluid.velocity.cast<float>());
            frame.id.push_back(static_cast<uint32_t>(frame.id.size()));
          }
    }
    // Each particle of a jittered block up to jitter x half the spacing off its site along each axis.
    if (fluid.jitter > 0)
      for (size_t i = first; i < frame.size(); ++i)
        for (int k = 0; k < scene.dimensions; ++k)
          frame.position[i][k] += static_cast<float>(fluid.jitter * spacing * latticeJitter(frame.id[i], k));
    if (!fluid.velocity_field.empty()) addVelocityField(scene, f, first, frame);
    // Where there are several fluids, each block's particles carry its fluid.
    if (several) frame.fluid.resize(frame.size(), static_cast<uint8_t>(scene.fluidOf(f)));
  }
  return frame;
}

SimulationSummary simulate(const Scene& scene, const fs::path& dir, bool resume, Progress& progress) {
  return simulate(scene, buildColliderShapes(scene), dir, resume, progress);
}

std::unique_ptr<SimulationRun> SimulationRun::start(const Scene& scene, std::shared_ptr<const ColliderShapes> shapes,
                                                   const fs::path& dir, bool resume) {
  if (!shapes) shapes = buildColliderShapes(scene);
  if (scene.dimensions == 2) return std::make_unique<FrameLoop<2>>(scene, std::move(shapes), dir, resume);
  return std::make_unique<FrameLoop<3>>(scene, std::move(shapes), dir, resume);
}

SimulationSummary simulate(const Scene& scene, std::shared_ptr<const ColliderShapes> shapes, const fs::path& dir,
                           bool resume, Progress& progress) {
  const auto runStart = std::chrono::steady_clock::now();
  const std::unique_ptr<SimulationRun> run = SimulationRun::start(scene, std::move(shapes), dir, resume);
  progress.start("simulate", static_cast<size_t>(scene.output.frames - run->frame()));
  while (run->frame() < scene.output.frames) {
    Progress::checkInterrupt();
    run->stepFrame();
    progress.advance();
  }
  progress.finish();
  SimulationSummary summary = run->summary();
  summary.lastFrame = scene.output.frames;
  summary.particles = run->size();
  summary.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - runStart).count();
  return summary;
}

// A resumed simulation must go on with the physics it started with: the scene may change its name, its
// surfacing, its rendering (the fluids' colours among it) and its number of frames, nothing else.
static void checkResumable(const fs::path& previous, const std::string& previousJson, const std::string& json) {
  auto physics = [](nlohmann::json scene) {
    for (const char* key : {"name", "surface", "render"}) scene.erase(key);
    if (scene.contains("fluids"))
      for (auto& fluid : scene["fluids"])
        for (const char* key : {"color", "absorption_distance"}) fluid.erase(key);
    if (scene.contains("output")) scene["output"].erase("frames");
    return scene;
  };
  const nlohmann::json patch = nlohmann::json::diff(physics(nlohmann::json::parse(previousJson)),
                                                    physics(nlohmann::json::parse(json)));
  if (patch.empty()) return;
  std::string key = patch.front().value("path", "");
  for (char& c : key) c = c == '/' ? '.' : c;
  if (!key.empty() && key.front() == '.') key.erase(0, 1);
  throw InputError(previous.string(), key,
                   "differs from the scene this folder was simulated with; --resume needs the same physics "
                   "(run without it to start over)");
}

void removeLaterStagesFrames(const fs::path& dir) {
  // A shorter run would otherwise end in a video of the older run's later frames.
  removeFrames(dir, "whitewater", {"ply"});
  removeFrames(dir, "surface", {"vdb", "ply", "obj"});
  removeFrames(dir, "frames", {"png"});
}

void prepareSimulationFolder(const Scene& scene, const fs::path& dir, bool resume) {
  const std::string json = sceneToJson(scene);
  std::error_code error;
  const bool existing = fs::exists(dir / "scene.json", error);
  const std::string previous = existing ? readTextFile(dir / "scene.json") : std::string();
  if (resume && existing && !listFrames(dir, "particles", "ply").empty())
    checkResumable(dir / "scene.json", previous, json);
  checkOutputFolder(dir);
  if (!resume) removeLaterStagesFrames(dir);
  if (!existing || previous != json)
    writeFileAtomically(dir / "scene.json", [&](std::ostream& out) { out << json; });
}

}  // namespace surge
