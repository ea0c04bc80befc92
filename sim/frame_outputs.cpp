#include "sim/frame_outputs.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "core/errors.h"
#include "geometry/pose.h"
#include "sim/rigid_bodies.h"

namespace surge {
namespace {

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

// A stats.csv column: its name and its value in a frame's row (empty where a method has none).
struct StatsColumn {
  const char* name;
  std::string (*value)(const FrameRecord&);
};

// `value` printed with `format`, or nothing if it is NaN.
std::string printed(const char* format, double value) {
  if (std::isnan(value)) return "";
  char text[64];
  std::snprintf(text, sizeof text, format, value);
  return text;
}

// The columns in order; DESIGN.md's contract names the first ones.
const StatsColumn kStatsColumns[] = {
    {"frame", [](const FrameRecord& r) { return std::to_string(r.frame); }},
    {"time", [](const FrameRecord& r) { return printed("%.6f", r.time); }},
    {"particles", [](const FrameRecord& r) { return std::to_string(r.particles->size()); }},
    {"substeps", [](const FrameRecord& r) { return std::to_string(r.steps); }},
    {"iterations", [](const FrameRecord& r) { return printed("%.2f", r.iterations); }},
    {"density_error_avg", [](const FrameRecord& r) { return printed("%.6g", r.measures.densityErrorAvg); }},
    {"density_error_max", [](const FrameRecord& r) { return printed("%.6g", r.measures.densityErrorMax); }},
    {"kinetic_energy", [](const FrameRecord& r) { return printed("%.6g", r.measures.kineticEnergy); }},
    {"wall_seconds", [](const FrameRecord& r) { return printed("%.4f", r.wallSeconds); }},
    {"ms_neighbors", [](const FrameRecord& r) { return printed("%.2f", r.phases.neighbors); }},
    {"ms_constraint", [](const FrameRecord& r) { return printed("%.2f", r.phases.pressure); }},
    {"ms_vorticity", [](const FrameRecord& r) { return printed("%.2f", r.phases.vorticity); }},
    {"ms_viscosity", [](const FrameRecord& r) { return printed("%.2f", r.phases.forces); }},
    {"time_step", [](const FrameRecord& r) { return printed("%.6g", r.smallestStep); }},
    {"pressure_max", [](const FrameRecord& r) { return printed("%.6g", r.pressureMax); }},
    {"divergence_iterations", [](const FrameRecord& r) { return printed("%.2f", r.divergenceIterations); }},
    {"front_x", [](const FrameRecord& r) { return printed("%.6g", r.dam.frontX); }},
    {"back_height", [](const FrameRecord& r) { return printed("%.6g", r.dam.backHeight); }},
    {"emitted", [](const FrameRecord& r) { return std::to_string(r.emitted); }},
    {"removed", [](const FrameRecord& r) { return std::to_string(r.removed); }},
    {"potential_energy", [](const FrameRecord& r) { return printed("%.6g", r.potentialEnergy); }},
    {"source_work", [](const FrameRecord& r) { return printed("%.9g", r.sourceWork); }},
    {"viscosity_iterations", [](const FrameRecord& r) { return printed("%.2f", r.viscosityIterations); }},
};

class StatsOutput final : public FrameOutput {
 public:
  StatsOutput(const fs::path& dir, bool continuing, int firstFrame)
      : table_(dir / "stats.csv", statsCsvHeader(), continuing, firstFrame) {}
  void write(const FrameRecord& record) override {
    std::string row;
    for (const StatsColumn& column : kStatsColumns) row += (row.empty() ? "" : ",") + column.value(record);
    table_.add(row);
  }

 private:
  CsvFile table_;
};

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

class ColliderOutput final : public FrameOutput {
 public:
  ColliderOutput(const Scene& scene, std::shared_ptr<const ColliderShapes> shapes, const fs::path& dir, bool resume,
                 bool continuing, int firstFrame)
      : scene_(scene), shapes_(std::move(shapes)), dir_(dir),
        table_(dir / "colliders.csv", collidersCsvHeader(), continuing, firstFrame) {
    writeColliderMeshes(scene_, *shapes_, dir_, resume);
  }
  void write(const FrameRecord& record) override {
    if (record.frame == 0) return;  // colliders.csv starts at frame 1: a wrench is a frame's mean
    table_.add(colliderRows(scene_, record.frame, record.colliderWrenches));
    writeMovingColliderMeshes(scene_, *shapes_, dir_, record.frame);
  }

 private:
  const Scene& scene_;
  std::shared_ptr<const ColliderShapes> shapes_;
  fs::path dir_;
  CsvFile table_;
};

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

class BodyOutput final : public FrameOutput {
 public:
  BodyOutput(const Scene& scene, std::shared_ptr<const ColliderShapes> shapes, const RigidBodies& bodies,
             const fs::path& dir, bool continuing, int firstFrame)
      : scene_(scene), shapes_(std::move(shapes)), bodies_(bodies), dir_(dir),
        table_(dir / "bodies.csv", bodiesCsvHeader(), continuing, firstFrame) {}
  void write(const FrameRecord& record) override {
    const std::vector<Wrench> none(bodies_.size());
    table_.add(bodyRows(scene_, record.frame, bodies_.states(), record.frame == 0 ? none : record.bodyWrenches));
    writeBodyFrame(scene_, *shapes_, bodies_, dir_, record.frame);
  }

 private:
  const Scene& scene_;
  std::shared_ptr<const ColliderShapes> shapes_;
  const RigidBodies& bodies_;
  fs::path dir_;
  CsvFile table_;
};

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

class CarriedStateOutput final : public FrameOutput {
 public:
  explicit CarriedStateOutput(const fs::path& dir) : dir_(dir) {}
  void write(const FrameRecord& record) override {
    if (!record.carriedState.empty()) writeCarriedState(dir_, record.frame, record.carriedState);
  }

 private:
  fs::path dir_;
};

class ParticleOutput final : public FrameOutput {
 public:
  explicit ParticleOutput(const fs::path& dir) : dir_(dir) {}
  void write(const FrameRecord& record) override {
    writeParticlePly(framePath(dir_, "particles", record.frame, "ply"), *record.particles);
  }

 private:
  fs::path dir_;
};

}  // namespace

std::vector<std::unique_ptr<FrameOutput>> makeFrameOutputs(const Scene& scene,
                                                           std::shared_ptr<const ColliderShapes> shapes,
                                                           const RigidBodies* bodies, const fs::path& dir,
                                                           bool resume, bool continuing, int firstFrame) {
  std::vector<std::unique_ptr<FrameOutput>> outputs;
  outputs.push_back(std::make_unique<StatsOutput>(dir, continuing, firstFrame));
  if (bodies) outputs.push_back(std::make_unique<BodyOutput>(scene, shapes, *bodies, dir, continuing, firstFrame));
  if (!scene.colliders.empty())
    outputs.push_back(std::make_unique<ColliderOutput>(scene, shapes, dir, resume, continuing, firstFrame));
  outputs.push_back(std::make_unique<CarriedStateOutput>(dir));
  outputs.push_back(std::make_unique<ParticleOutput>(dir));
  return outputs;
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


const char* statsCsvHeader() {
  static const std::string header = [] {
    std::string names;
    for (const StatsColumn& column : kStatsColumns) names += (names.empty() ? "" : ",") + std::string(column.name);
    return names;
  }();
  return header.c_str();
}

const char* collidersCsvHeader() { return "frame,collider,fx,fy,fz,tx,ty,tz"; }
const char* bodiesCsvHeader() {
  return "frame,body,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz,fx,fy,fz,tx,ty,tz";
}

}  // namespace surge
