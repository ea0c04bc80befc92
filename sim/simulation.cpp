#include "sim/simulation.h"

#include <chrono>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "core/errors.h"
#include "sim/pbf_solver.h"

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

std::string statsRow(int frame, double time, size_t particles, int substeps, double iterations,
                     const FluidMeasures& m, double wallSeconds, const PhaseTimes& t) {
  char row[512];
  std::snprintf(row, sizeof row, "%d,%.6f,%zu,%d,%.2f,%.6g,%.6g,%.6g,%.4f,%.2f,%.2f,%.2f,%.2f", frame, time,
                particles, substeps, iterations, m.densityErrorAvg, m.densityErrorMax, m.kineticEnergy,
                wallSeconds, t.neighbors, t.constraint, t.vorticity, t.viscosity);
  return row;
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

template <int Dim>
SimulationSummary run(const Scene& scene, const fs::path& dir, bool resume, Progress& progress) {
  const auto runStart = std::chrono::steady_clock::now();
  const fs::path particleDir = dir / "particles";
  removeStaleFiles(particleDir, !resume);
  fs::create_directories(particleDir);

  PbfSolver<Dim> solver(scene);
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
    stats.add(statsRow(0, 0.0, solver.size(), 0, 0, solver.measure(), 0.0, PhaseTimes{}));
    solver.getParticles(frame);
    writeParticlePly(framePath(dir, "particles", 0, "ply"), frame);
  }

  const int substeps = scene.solver.substeps;
  const float dt = static_cast<float>(1.0 / (scene.output.fps * substeps));
  progress.start("simulate", static_cast<size_t>(scene.output.frames - summary.firstFrame));
  for (int f = summary.firstFrame + 1; f <= scene.output.frames; ++f) {
    Progress::checkInterrupt();
    const auto frameStart = std::chrono::steady_clock::now();
    solver.phaseTimes() = PhaseTimes{};
    int iterations = 0;
    for (int s = 0; s < substeps; ++s) {
      const long bad = solver.step(dt);
      iterations += solver.lastIterations();
      if (bad >= 0) {
        solver.getParticles(frame);
        throw RunError("simulation diverged at frame " + std::to_string(f) + ", substep " + std::to_string(s) +
                       ": particle " + std::to_string(bad) + " (id " + std::to_string(frame.id[bad]) +
                       ") at " + formatVector(frame.position[bad], Dim) + " with velocity " +
                       formatVector(frame.velocity[bad], Dim) + " (not finite or outside the domain)");
      }
    }
    const FluidMeasures measures = solver.measure();
    solver.getParticles(frame);
    writeParticlePly(framePath(dir, "particles", f, "ply"), frame);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - frameStart).count();
    stats.add(statsRow(f, f / scene.output.fps, solver.size(), substeps, double(iterations) / substeps, measures,
                       seconds, solver.phaseTimes()));
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
         "wall_seconds,ms_neighbors,ms_constraint,ms_vorticity,ms_viscosity";
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
  if (scene.solver.method != "pbf") throw InputError("solver.method", "'" + scene.solver.method + "' is not available");
  return scene.dimensions == 2 ? run<2>(scene, dir, resume, progress) : run<3>(scene, dir, resume, progress);
}

}  // namespace surge
