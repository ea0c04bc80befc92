#include "sim/simulation.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "core/errors.h"
#include "sim/pbf_solver.h"
#include "sim/wcsph_solver.h"

namespace surge {
namespace {

std::string formatVector(const Eigen::Vector3f& v, int dimensions) {
  std::ostringstream out;
  out << "(" << v.x() << ", " << v.y();
  if (dimensions == 3) out << ", " << v.z();
  out << ")";
  return out.str();
}

// Rows of stats.csv kept in memory and rewritten whole after every frame, so the file is never half a row.
class StatsFile {
 public:
  StatsFile(fs::path path, bool resume, int resumeFrame) : path_(std::move(path)) {
    if (!resume) return;
    std::ifstream in(path_);
    std::string line;
    std::getline(in, line);  // header
    while (std::getline(in, line)) {
      const int frame = std::atoi(line.c_str());
      if (!line.empty() && frame <= resumeFrame) rows_.push_back(line);
    }
  }
  void add(const std::string& row) {
    rows_.push_back(row);
    writeFileAtomically(path_, [&](std::ostream& out) {
      out << statsCsvHeader() << "\n";
      for (const std::string& r : rows_) out << r << "\n";
    });
  }

 private:
  fs::path path_;
  std::vector<std::string> rows_;
};

// pressureMax is NaN for a solver without pressures (PBF) and written as an empty field.
std::string statsRow(int frame, double time, size_t particles, int substeps, double iterations,
                     const FluidMeasures& m, double wallSeconds, const PhaseTimes& t, double timeStep,
                     double pressureMax, const DamBreakMeasures& dam) {
  char row[512];
  std::snprintf(row, sizeof row, "%d,%.6f,%zu,%d,%.2f,%.6g,%.6g,%.6g,%.4f,%.2f,%.2f,%.2f,%.2f,%.6g,", frame, time,
                particles, substeps, iterations, m.densityErrorAvg, m.densityErrorMax, m.kineticEnergy,
                wallSeconds, t.neighbors, t.constraint, t.vorticity, t.viscosity, timeStep);
  std::string text = row;
  if (!std::isnan(pressureMax)) {
    std::snprintf(row, sizeof row, "%.6g", pressureMax);
    text += row;
  }
  std::snprintf(row, sizeof row, ",%.6g,%.6g", dam.frontX, dam.backHeight);
  return text + row;
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
  if (scene.fluids.empty()) return 1;
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

[[noreturn]] void diverged(int frame, int substep, long particle, const ParticleFrame& state) {
  throw RunError("simulation diverged at frame " + std::to_string(frame) + ", substep " + std::to_string(substep) +
                 ": particle " + std::to_string(particle) + " (id " + std::to_string(state.id[particle]) + ") at " +
                 formatVector(state.position[particle], state.dimensions) + " with velocity " +
                 formatVector(state.velocity[particle], state.dimensions) + " (not finite or outside the domain)");
}

// The frame loop, for either solver. A solver with fixedSubsteps() > 0 takes that many equal steps a frame;
// otherwise each step is the largest stable one (stableTimeStep) shortened so the steps left end exactly on the
// frame: dt = remaining / ceil(remaining / stable).
template <int Dim, typename Solver>
SimulationSummary run(const Scene& scene, const fs::path& dir, bool resume, Progress& progress) {
  const auto runStart = std::chrono::steady_clock::now();
  const fs::path particleDir = dir / "particles";
  removeStaleFiles(particleDir, !resume);
  fs::create_directories(particleDir);

  Solver solver(scene);
  SimulationSummary summary;
  const std::vector<int> existing = resume ? listFrames(dir, "particles", "ply") : std::vector<int>{};
  if (!existing.empty()) {
    summary.firstFrame = std::min(existing.back(), scene.output.frames);
    const fs::path path = framePath(dir, "particles", summary.firstFrame, "ply");
    const ParticleFrame frame = readParticlePly(path);
    if (frame.dimensions != Dim) throw InputError(path.string(), "dimensions", "differs from the scene's");
    solver.setParticles(frame);
  } else {
    solver.setParticles(initialParticles(scene));
  }
  const bool fresh = existing.empty();
  StatsFile stats(dir / "stats.csv", !fresh, summary.firstFrame);
  ParticleFrame frame;
  if (fresh) {
    solver.getParticles(frame);
    stats.add(statsRow(0, 0.0, solver.size(), 0, 0, solver.measure(), 0.0, PhaseTimes{}, 0.0, NAN,
                       measureDamBreak(scene, frame)));
    writeParticlePly(framePath(dir, "particles", 0, "ply"), frame);
  }

  const double frameDuration = 1.0 / scene.output.fps;
  constexpr int kMostSteps = 1000000;
  progress.start("simulate", static_cast<size_t>(scene.output.frames - summary.firstFrame));
  for (int f = summary.firstFrame + 1; f <= scene.output.frames; ++f) {
    Progress::checkInterrupt();
    const auto frameStart = std::chrono::steady_clock::now();
    solver.phaseTimes() = PhaseTimes{};
    double time = (f - 1) * frameDuration;
    solver.beginFrame(time);
    int iterations = 0, steps = 0;
    float smallestStep = INFINITY;
    double remaining = frameDuration;
    while (remaining > 0) {
      float dt;
      if (solver.fixedSubsteps() > 0) {
        dt = static_cast<float>(frameDuration / solver.fixedSubsteps());
        remaining = steps + 1 == solver.fixedSubsteps() ? 0 : remaining - dt;
      } else {
        const double stable = solver.stableTimeStep();
        const double count = std::max(1.0, std::ceil(remaining / stable - 1e-9));
        dt = static_cast<float>(remaining / count);
        remaining = count == 1 ? 0 : remaining - dt;
      }
      const long bad = solver.step(dt, time);
      time += dt;
      smallestStep = std::min(smallestStep, dt);
      iterations += solver.lastIterations();
      if (bad >= 0) {
        solver.getParticles(frame);
        diverged(f, steps, bad, frame);
      }
      if (++steps >= kMostSteps)
        throw RunError("simulation stalled at frame " + std::to_string(f) + ": a million steps of " +
                       std::to_string(dt) + " s did not finish the frame (the stable step collapsed)");
    }
    const FluidMeasures measures = solver.measure();
    solver.getParticles(frame);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - frameStart).count();
    // The row first, the frame second: a run killed between them resumes from the frame before, whose rows
    // are the ones kept, so stats.csv never misses a frame that is on disk.
    stats.add(statsRow(f, f * frameDuration, solver.size(), steps, double(iterations) / steps, measures, seconds,
                       solver.phaseTimes(), smallestStep, solver.maxPressure(), measureDamBreak(scene, frame)));
    writeParticlePly(framePath(dir, "particles", f, "ply"), frame);
    progress.advance();
  }
  progress.finish();
  summary.lastFrame = scene.output.frames;
  summary.particles = solver.size();
  summary.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - runStart).count();
  return summary;
}

}  // namespace

const char* statsCsvHeader() {
  return "frame,time,particles,substeps,iterations,density_error_avg,density_error_max,kinetic_energy,"
         "wall_seconds,ms_neighbors,ms_constraint,ms_vorticity,ms_viscosity,time_step,pressure_max,front_x,back_height";
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
  if (scene.fluids.size() != 1) return false;
  const Box& box = scene.fluids.front().box;
  const double tolerance = 0.5 * scene.particle_spacing;
  const bool onFloor = box.min.y() <= scene.domain.min.y() + tolerance;
  const bool atMin = box.min.x() <= scene.domain.min.x() + tolerance;
  const bool atMax = box.max.x() >= scene.domain.max.x() - tolerance;
  return onFloor && atMin != atMax;
}

ParticleFrame initialParticles(const Scene& scene) {
  ParticleFrame frame;
  frame.dimensions = scene.dimensions;
  const size_t total = scene.particleCount();
  frame.position.reserve(total);
  frame.velocity.reserve(total);
  frame.id.reserve(total);
  const double spacing = scene.particle_spacing;
  for (const FluidBlock& fluid : scene.fluids) {
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
  return frame;
}

SimulationSummary simulate(const Scene& scene, const fs::path& dir, bool resume, Progress& progress) {
  const bool wcsph = scene.solver.method == "wcsph";
  if (scene.dimensions == 2)
    return wcsph ? run<2, WcsphSolver<2>>(scene, dir, resume, progress) : run<2, PbfSolver<2>>(scene, dir, resume, progress);
  return wcsph ? run<3, WcsphSolver<3>>(scene, dir, resume, progress) : run<3, PbfSolver<3>>(scene, dir, resume, progress);
}

}  // namespace surge
