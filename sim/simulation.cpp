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

#include "core/errors.h"
#include "geometry/pose.h"
#include "sim/fluid_solver.h"
#include "sim/rigid_bodies.h"
#include "sim/solver_defaults.h"

namespace surge {
namespace {

std::string formatVector(const Eigen::Vector3f& v, int dimensions) {
  std::ostringstream out;
  out << "(" << v.x() << ", " << v.y();
  if (dimensions == 3) out << ", " << v.z();
  out << ")";
  return out.str();
}

// A per-frame table (stats.csv, colliders.csv, bodies.csv). Opening it writes the header, and on resume the rows
// of the frames up to the one resumed from, as a whole new file; each frame's rows are then appended by one
// write, so that a run of 10^7 frames costs its rows once, not the file again at every frame. A row cut short
// by a kill (no newline) is dropped on resume, as are the rows of frames after the one resumed from.
class CsvFile {
 public:
  CsvFile(fs::path path, const std::string& header, bool resume, int resumeFrame) : path_(std::move(path)) {
    std::string kept = header + "\n";
    if (resume) {
      std::error_code error;
      const std::string text = fs::exists(path_, error) ? readTextFile(path_) : std::string();
      size_t begin = text.find('\n');  // after the header
      while (begin != std::string::npos && begin + 1 < text.size()) {
        const size_t end = text.find('\n', begin + 1);
        if (end == std::string::npos) break;  // the last row, cut short
        const std::string line = text.substr(begin + 1, end - begin - 1);
        if (!line.empty() && std::atoi(line.c_str()) <= resumeFrame) kept += line + "\n";
        begin = end;
      }
    }
    writeFileAtomically(path_, [&](std::ostream& out) { out << kept; });
  }
  void add(const std::string& row) {
    const std::string line = row + "\n";
    const int file = ::open(path_.c_str(), O_WRONLY | O_APPEND);
    if (file < 0) throw RunError("cannot append to " + path_.string() + ": " + writeFailure(errno));
    errno = 0;
    const ssize_t written = ::write(file, line.data(), line.size());
    const int error = written < 0 ? errno : ENOSPC;  // a short write: the disk filled during it
    ::close(file);
    if (written != ssize_t(line.size())) throw RunError("cannot append to " + path_.string() + ": " + writeFailure(error));
  }

 private:
  fs::path path_;
};

// pressureMax is NaN for a solver without pressures (PBF), divergenceIterations for one without a divergence
// solver (PBF, WCSPH); either is then written as an empty field.
std::string statsRow(int frame, double time, size_t particles, int substeps, double iterations,
                     const FluidMeasures& m, double wallSeconds, const PhaseTimes& t, double timeStep,
                     double pressureMax, const DamBreakMeasures& dam, double divergenceIterations) {
  char row[512];
  std::snprintf(row, sizeof row, "%d,%.6f,%zu,%d,%.2f,%.6g,%.6g,%.6g,%.4f,%.2f,%.2f,%.2f,%.2f,%.6g,", frame, time,
                particles, substeps, iterations, m.densityErrorAvg, m.densityErrorMax, m.kineticEnergy,
                wallSeconds, t.neighbors, t.pressure, t.vorticity, t.forces, timeStep);
  std::string text = row;
  if (!std::isnan(pressureMax)) {
    std::snprintf(row, sizeof row, "%.6g", pressureMax);
    text += row;
  }
  text += ",";
  if (!std::isnan(divergenceIterations)) {
    std::snprintf(row, sizeof row, "%.2f", divergenceIterations);
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

// One colliders.csv row a collider: the frame's mean force (N) and torque about the collider's position (N m).
std::string colliderRows(const Scene& scene, int frame, const std::vector<Wrench>& wrenches) {
  std::string rows;
  for (size_t c = 0; c < wrenches.size(); ++c) {
    char row[512];
    const Wrench& w = wrenches[c];
    std::snprintf(row, sizeof row, "%d,%s,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g", frame, scene.colliders[c].name.c_str(),
                  w.force.x(), w.force.y(), w.force.z(), w.torque.x(), w.torque.y(), w.torque.z());
    rows += (rows.empty() ? "" : "\n") + std::string(row);
  }
  return rows;
}

// A shape's mesh placed in the world by `pose`.
TriangleMesh placedMesh(TriangleMesh mesh, const Pose& pose) {
  for (Eigen::Vector3f& p : mesh.positions) p = pose.toWorld(p.cast<double>()).cast<float>();
  for (Eigen::Vector3f& n : mesh.normals) n = (pose.rotation * n.cast<double>()).cast<float>();
  return mesh;
}

// A collider's mesh placed in the world at `time`.
TriangleMesh placedMesh(const ColliderSettings& settings, const ColliderShape& shape, double time) {
  return placedMesh(shape.mesh, colliderPose(settings, time));
}

// colliders/<name>.ply: each collider's mesh in the world as it stands at time 0, so that the later stages and
// Blender never reload the scene's own files. A new run starts the folder afresh.
void writeColliderMeshes(const Scene& scene, const ColliderShapes& shapes, const fs::path& dir, bool resume) {
  const fs::path folder = dir / "colliders";
  std::error_code error;
  if (!resume) fs::remove_all(folder, error);
  fs::create_directories(folder);
  for (size_t c = 0; c < scene.colliders.size(); ++c) {
    writeMeshPly(folder / (scene.colliders[c].name + ".ply"), placedMesh(scene.colliders[c], shapes[c], 0.0));
    if (isMoving(scene.colliders[c])) {
      fs::create_directories(folder / scene.colliders[c].name);
      const fs::path first = framePath(folder, scene.colliders[c].name, 0, "ply");
      if (!fs::exists(first, error)) writeMeshPly(first, placedMesh(scene.colliders[c], shapes[c], 0.0));
    }
  }
}

// colliders/<name>/frame_NNNNN.ply: a moving collider's mesh at each frame.
void writeMovingColliderMeshes(const Scene& scene, const ColliderShapes& shapes, const fs::path& dir, int frame) {
  for (size_t c = 0; c < scene.colliders.size(); ++c)
    if (isMoving(scene.colliders[c]))
      writeMeshPly(framePath(dir / "colliders", scene.colliders[c].name, frame, "ply"),
                   placedMesh(scene.colliders[c], shapes[c], frame / scene.output.fps));
}

// One bodies.csv row a body: its state at the frame's end and the fluid's mean wrench on it over the frame.
std::string bodyRows(const Scene& scene, int frame, const std::vector<BodyState>& states,
                     const std::vector<Wrench>& wrenches) {
  std::string rows;
  for (size_t b = 0; b < states.size(); ++b) {
    const BodyState& s = states[b];
    const Wrench& w = wrenches[b];
    char row[768];
    std::snprintf(row, sizeof row,
                  "%d,%s,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g",
                  frame, scene.bodies[b].solid.name.c_str(), s.position.x(), s.position.y(), s.position.z(),
                  s.orientation.w(), s.orientation.x(), s.orientation.y(), s.orientation.z(), s.velocity.x(),
                  s.velocity.y(), s.velocity.z(), s.angularVelocity.x(), s.angularVelocity.y(),
                  s.angularVelocity.z(), w.force.x(), w.force.y(), w.force.z(), w.torque.x(), w.torque.y(),
                  w.torque.z());
    rows += (rows.empty() ? "" : "\n") + std::string(row);
  }
  return rows;
}

// bodies/<name>/frame_NNNNN.ply: each body's mesh in the world at the frame (and bodies/<name>.ply at frame 0),
// and bodies/frame_NNNNN.txt, the exact state a resumed run starts from.
void writeBodyFrame(const Scene& scene, const ColliderShapes& shapes, const RigidBodies& bodies,
                    const fs::path& dir, int frame) {
  const fs::path folder = dir / "bodies";
  for (size_t b = 0; b < bodies.size(); ++b) {
    const TriangleMesh mesh = placedMesh(shapes[scene.colliders.size() + b].mesh, bodies.pose(b));
    const std::string& name = scene.bodies[b].solid.name;
    fs::create_directories(folder / name);
    if (frame == 0) writeMeshPly(folder / (name + ".ply"), mesh);
    writeMeshPly(framePath(folder, name, frame, "ply"), mesh);
  }
  writeBodyStates(framePath(dir, "bodies", frame, "txt"), scene, bodies.states());
}

// A method's carried state (FluidSolver::carriedState) at frame f: solver/frame_NNNNN.bin, raw floats, written
// before the particle frame (which commits the frame). Only the last two are kept: a run resumes from its last.
void writeCarriedState(const fs::path& dir, int frame, const std::vector<float>& state) {
  fs::create_directories(dir / "solver");
  writeFileAtomically(framePath(dir, "solver", frame, "bin"), [&](std::ostream& out) {
    out.write(reinterpret_cast<const char*>(state.data()), std::streamsize(state.size() * sizeof(float)));
  });
  std::error_code error;
  if (frame >= 2) fs::remove(framePath(dir, "solver", frame - 2, "bin"), error);
}

std::vector<float> readCarriedState(const fs::path& dir, int frame, size_t count) {
  const fs::path path = framePath(dir, "solver", frame, "bin");
  std::error_code error;
  if (!fs::exists(path, error))
    throw RunError("cannot resume from frame " + std::to_string(frame) + ": " + path.string() +
                   ", the solver's state there, is missing");
  const std::string bytes = readTextFile(path);
  if (bytes.size() != count * sizeof(float))
    throw RunError("cannot resume from frame " + std::to_string(frame) + ": " + path.string() + " holds " +
                   std::to_string(bytes.size()) + " bytes, not the " + std::to_string(count * sizeof(float)) +
                   " of this scene's particles");
  std::vector<float> state(count);
  std::memcpy(state.data(), bytes.data(), bytes.size());
  return state;
}

// The frame loop, for any solver. A solver with fixedSubsteps() > 0 takes that many equal steps a frame;
// otherwise each step is the largest stable one (stableTimeStep) shortened so the steps left end exactly on the
// frame: dt = remaining / ceil(remaining / stable).
template <int Dim>
SimulationSummary run(const Scene& scene, std::shared_ptr<const ColliderShapes> shapes, const fs::path& dir,
                      bool resume, Progress& progress) {
  const auto runStart = std::chrono::steady_clock::now();
  const fs::path particleDir = dir / "particles";
  removeStaleFiles(particleDir, !resume);
  removeStaleFiles(dir / "solver", !resume);
  fs::create_directories(particleDir);

  const std::unique_ptr<FluidSolver<Dim>> method = makeFluidSolver<Dim>(scene, shapes);
  FluidSolver<Dim>& solver = *method;
  SimulationSummary summary;
  const bool colliding = !scene.colliders.empty();
  if (colliding) writeColliderMeshes(scene, *shapes, dir, resume);
  std::unique_ptr<RigidBodies> bodies;
  if (!scene.bodies.empty()) {
    bodies = std::make_unique<RigidBodies>(scene, shapes);
    std::error_code error;
    if (!resume) fs::remove_all(dir / "bodies", error);
    fs::create_directories(dir / "bodies");
  }
  const std::vector<int> existing = resume ? listFrames(dir, "particles", "ply") : std::vector<int>{};
  if (!existing.empty()) {
    summary.firstFrame = std::min(existing.back(), scene.output.frames);
    const fs::path path = framePath(dir, "particles", summary.firstFrame, "ply");
    const ParticleFrame frame = readParticlePly(path);
    if (frame.dimensions != Dim) throw InputError(path.string(), "dimensions", "differs from the scene's");
    solver.setParticles(frame);
    const size_t carried = solver.carriedState().size();
    if (carried > 0 && summary.firstFrame < scene.output.frames)
      solver.restoreCarriedState(readCarriedState(dir, summary.firstFrame, carried));
    if (bodies) bodies->setStates(readBodyStates(framePath(dir, "bodies", summary.firstFrame, "txt"), scene));
  } else {
    ParticleFrame initial = initialParticles(scene);
    if (colliding || bodies) {
      summary.removedParticles = removeParticlesInside(solver.colliders(), initial);
      if (initial.size() == 0)
        throw InputError(scene.source, colliding ? "colliders" : "bodies",
                         "every fluid particle lies inside a collider or a body");
    }
    solver.setParticles(initial);
  }
  const bool fresh = existing.empty();
  CsvFile stats(dir / "stats.csv", statsCsvHeader(), !fresh, summary.firstFrame);
  std::unique_ptr<CsvFile> colliderTable, bodyTable;
  if (colliding)
    colliderTable = std::make_unique<CsvFile>(dir / "colliders.csv", collidersCsvHeader(), !fresh, summary.firstFrame);
  if (bodies)
    bodyTable = std::make_unique<CsvFile>(dir / "bodies.csv", bodiesCsvHeader(), !fresh, summary.firstFrame);
  ParticleFrame frame;
  if (fresh) {
    // Measured first: before the first step, measuring sorts the particles into cells, and frame 0 must hold
    // them in the order the run goes on with, or a run resumed from it sorts a different order into the cells
    // and sums its neighbours in another order.
    const FluidMeasures measures = solver.measure();
    solver.getParticles(frame);
    stats.add(statsRow(0, 0.0, solver.size(), 0, 0, measures, 0.0, PhaseTimes{}, 0.0, NAN,
                       measureDamBreak(scene, frame), solver.lastDivergenceIterations() < 0 ? NAN : 0.0));
    if (bodies) {
      bodyTable->add(bodyRows(scene, 0, bodies->states(), std::vector<Wrench>(bodies->size())));
      writeBodyFrame(scene, *shapes, *bodies, dir, 0);
    }
    const std::vector<float> state = solver.carriedState();
    if (!state.empty()) writeCarriedState(dir, 0, state);
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
    if (bodies) {
      bodies->beginFrame(time);
      placeBodies(*bodies, solver.colliders());
    }
    int iterations = 0, divergenceIterations = 0, steps = 0;
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
      long badBody = -1;
      const long bad = coupledStep<Dim>(solver, bodies.get(), dt, time, badBody);
      time += dt;
      if (badBody >= 0)
        throw RunError("simulation diverged at frame " + std::to_string(f) + ", substep " + std::to_string(steps) +
                       ": body " + scene.bodies[badBody].solid.name + " (its state is not finite)");
      smallestStep = std::min(smallestStep, dt);
      iterations += solver.lastIterations();
      divergenceIterations += solver.lastDivergenceIterations();
      if (bad >= 0) {
        solver.getParticles(frame);
        diverged(scene, f, steps, bad, frame);
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
                       solver.phaseTimes(), smallestStep, solver.maxPressure(), measureDamBreak(scene, frame),
                       divergenceIterations < 0 ? NAN : double(divergenceIterations) / steps));
    if (colliding || bodies) {
      std::vector<Wrench> wrenches = solver.takeColliderWrenches(frameDuration);
      const auto firstBody = wrenches.begin() + std::ptrdiff_t(scene.colliders.size());
      if (bodies) {
        bodyTable->add(bodyRows(scene, f, bodies->states(), std::vector<Wrench>(firstBody, wrenches.end())));
        writeBodyFrame(scene, *shapes, *bodies, dir, f);
      }
      wrenches.erase(firstBody, wrenches.end());
      if (colliding) {
        colliderTable->add(colliderRows(scene, f, wrenches));
        writeMovingColliderMeshes(scene, *shapes, dir, f);
      }
    }
    const std::vector<float> state = solver.carriedState();
    if (!state.empty()) writeCarriedState(dir, f, state);
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
         "wall_seconds,ms_neighbors,ms_constraint,ms_vorticity,ms_viscosity,time_step,pressure_max,divergence_iterations,"
         "front_x,back_height";
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
  return simulate(scene, buildColliderShapes(scene), dir, resume, progress);
}

SimulationSummary simulate(const Scene& scene, std::shared_ptr<const ColliderShapes> shapes, const fs::path& dir,
                           bool resume, Progress& progress) {
  return scene.dimensions == 2 ? run<2>(scene, shapes, dir, resume, progress)
                               : run<3>(scene, shapes, dir, resume, progress);
}

const char* collidersCsvHeader() { return "frame,collider,fx,fy,fz,tx,ty,tz"; }
const char* bodiesCsvHeader() {
  return "frame,body,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz,fx,fy,fz,tx,ty,tz";
}

}  // namespace surge
