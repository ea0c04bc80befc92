// surge export --format usd: one USD stage in ASCII, DIR/export/scene.usda, written by hand (Debian has no USD
// library). The fluid surface is a Mesh whose points, topology and per-vertex velocities are time-sampled, the
// particles a Points prim with time-sampled points, velocities and ids, each collider and body a Mesh in its own
// frame under animated translate and orient ops. A time code is a frame number, timeCodesPerSecond the scene's
// fps; metres, y up. Numbers are the shortest text that reads back to the same float.
#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdlib>
#include <functional>
#include <map>
#include <ostream>

#include "apps/export.h"
#include "core/errors.h"
#include "core/parallel.h"
#include "core/ply.h"
#include "geometry/pose.h"

namespace surge {
namespace {

template <typename T>
void appendNumber(std::string& text, T value) {
  char buffer[32];
  const auto end = std::to_chars(buffer, buffer + sizeof buffer, value).ptr;
  text.append(buffer, end);
}

template <typename Vector>
void appendTuple(std::string& text, const Vector& v) {
  text += '(';
  for (int k = 0; k < int(v.size()); ++k) {
    if (k) text += ", ";
    appendNumber(text, v[k]);
  }
  text += ')';
}

void appendVectors(std::string& text, const std::vector<Eigen::Vector3f>& vectors) {
  text += '[';
  for (size_t i = 0; i < vectors.size(); ++i) {
    if (i) text += ", ";
    appendTuple(text, vectors[i]);
  }
  text += ']';
}

template <typename Integer>
void appendIntegers(std::string& text, const std::vector<Integer>& values) {
  text += '[';
  for (size_t i = 0; i < values.size(); ++i) {
    if (i) text += ", ";
    appendNumber(text, values[i]);
  }
  text += ']';
}

// The box around points, USD's `extent`: [(min), (max)].
void appendExtent(std::string& text, const std::vector<Eigen::Vector3f>& points) {
  Eigen::Vector3f low = Eigen::Vector3f::Zero(), high = Eigen::Vector3f::Zero();
  if (!points.empty()) low = high = points.front();
  for (const Eigen::Vector3f& p : points) low = low.cwiseMin(p), high = high.cwiseMax(p);
  text += '[';
  appendTuple(text, low);
  text += ", ";
  appendTuple(text, high);
  text += ']';
}

// A prim name USD accepts: letters, digits and underscores, not starting with a digit.
std::string primName(const std::string& name) {
  std::string id;
  for (char c : name) id += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  if (id.empty() || std::isdigit(static_cast<unsigned char>(id[0]))) id = "_" + id;
  return id;
}

// Writes `declaration.timeSamples = { frame: value, ... }`, the values formatted a batch of frames at a time on
// every core and written in frame order, a progress step a frame.
void writeTimeSamples(std::ostream& out, const std::string& declaration, const std::vector<int>& frames,
                      const std::function<void(int, std::string&)>& format, Progress& progress) {
  out << "        " << declaration << ".timeSamples = {\n";
  const size_t batch = size_t(std::max(2, 2 * ThreadLimit::available()));
  std::vector<std::string> texts(batch);
  for (size_t first = 0; first < frames.size(); first += batch) {
    const size_t count = std::min(batch, frames.size() - first);
    parallelFor(
        0, count,
        [&](size_t begin, size_t end) {
          for (size_t i = begin; i < end; ++i) {
            Progress::checkInterrupt();
            texts[i].clear();
            format(frames[first + i], texts[i]);
          }
        },
        1);
    for (size_t i = 0; i < count; ++i) out << "            " << frames[first + i] << ": " << texts[i] << ",\n";
    progress.advance(count);
  }
  out << "        }\n";
}

// "rightHanded" when the triangles' winding agrees with the mesh's vertex normals (or it has none), else
// "leftHanded": USD takes a face's front from its winding, our meshes say it with their normals.
std::string orientation(const TriangleMesh& mesh) {
  if (mesh.normals.size() != mesh.positions.size()) return "rightHanded";
  double agreement = 0;
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3f& a = mesh.positions[t[0]];
    const Eigen::Vector3f winding = (mesh.positions[t[1]] - a).cross(mesh.positions[t[2]] - a);
    agreement += winding.dot(mesh.normals[t[0]] + mesh.normals[t[1]] + mesh.normals[t[2]]) >= 0 ? 1 : -1;
  }
  return agreement >= 0 ? "rightHanded" : "leftHanded";
}

void appendTopology(std::string& counts, std::string& indices, const TriangleMesh& mesh) {
  counts += '[';
  indices += '[';
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    counts += t ? ", 3" : "3";
    for (int k = 0; k < 3; ++k) {
      if (t || k) indices += ", ";
      appendNumber(indices, mesh.triangles[t][size_t(k)]);
    }
  }
  counts += ']';
  indices += ']';
}

// What a point-based prim samples: positions, and velocities and ids where the frames have them.
struct PointSamples {
  std::vector<Eigen::Vector3f> position, velocity;
  std::vector<uint32_t> id;
};

// points, extent, and (when the first frame has them) velocities and ids, sampled from samplesOf(frame); four
// progress steps a frame.
void writePointSamples(std::ostream& out, const std::vector<int>& frames,
                       const std::function<PointSamples(int)>& samplesOf, Progress& progress) {
  const PointSamples first = samplesOf(frames.front());
  writeTimeSamples(
      out, "point3f[] points", frames, [&](int f, std::string& text) { appendVectors(text, samplesOf(f).position); },
      progress);
  writeTimeSamples(
      out, "float3[] extent", frames, [&](int f, std::string& text) { appendExtent(text, samplesOf(f).position); },
      progress);
  if (first.velocity.empty())
    progress.advance(frames.size());
  else
    writeTimeSamples(
        out, "vector3f[] velocities", frames,
        [&](int f, std::string& text) { appendVectors(text, samplesOf(f).velocity); }, progress);
  if (first.id.empty())
    progress.advance(frames.size());
  else
    writeTimeSamples(
        out, "int64[] ids", frames, [&](int f, std::string& text) { appendIntegers(text, samplesOf(f).id); }, progress);
}

// The colour of the fluid whose surface series `kind` is: surface the first fluid's, surface_<name> that fluid's.
Eigen::Vector3d surfaceColor(const Scene& scene, const std::string& kind) {
  if (scene.fluids.empty()) return scene.render.water_color;
  for (size_t b : scene.laterFluids())
    if (kind == "surface_" + scene.fluids[b].name) return scene.fluidColor(b);
  return scene.fluidColor(0);
}

// A fluid surface series: points, topology, extent and (where its meshes carry them) velocities, all sampled, in
// its fluid's colour.
void writeSurface(std::ostream& out, const ExportRun& run, const FrameSeries& series, Progress& progress) {
  auto mesh = [&](int frame) { return readMeshPly(framePath(run.dir, series.kind, frame, "ply")); };
  TriangleMesh first;
  for (int f : series.frames)
    if (!(first = mesh(f)).triangles.empty()) break;
  std::string color;
  appendTuple(color, surfaceColor(run.scene, series.kind));
  out << "    def Mesh \"" << primName(series.kind) << "\"\n    {\n"
      << "        uniform token subdivisionScheme = \"none\"\n"
      << "        uniform token orientation = \"" << orientation(first) << "\"\n"
      << "        color3f[] primvars:displayColor = [" << color << "]\n";
  auto samples = [&](int f) {
    TriangleMesh m = mesh(f);
    return PointSamples{std::move(m.positions), std::move(m.velocities), {}};
  };
  writePointSamples(out, series.frames, samples, progress);
  for (const bool counts : {true, false}) {
    auto topology = [&](int f, std::string& text) {
      std::string other;
      if (counts)
        appendTopology(text, other, mesh(f));
      else
        appendTopology(other, text, mesh(f));
    };
    writeTimeSamples(out, counts ? "int[] faceVertexCounts" : "int[] faceVertexIndices", series.frames, topology,
                     progress);
  }
  out << "    }\n";
}

// Particles (or whitewater) as Points: points, extent, velocities and ids sampled, one width (the spacing).
void writePoints(std::ostream& out, const ExportRun& run, const FrameSeries& series, Progress& progress) {
  std::string width;
  appendNumber(width, float(run.scene.particle_spacing));
  out << "    def Points \"" << primName(series.kind) << "\"\n    {\n"
      << "        float[] widths = [" << width << "] (interpolation = \"constant\")\n";
  auto samples = [&](int f) {
    const fs::path path = framePath(run.dir, series.kind, f, "ply");
    if (series.kind == "particles") {
      ParticleFrame frame = readParticlePly(path);
      return PointSamples{std::move(frame.position), std::move(frame.velocity), std::move(frame.id)};
    }
    DiffuseFrame frame = readDiffusePly(path);
    return PointSamples{std::move(frame.position), std::move(frame.velocity), std::move(frame.id)};
  };
  writePointSamples(out, series.frames, samples, progress);
  out << "    }\n";
}

// Where a solid is at a frame: its translation and rotation.
struct SolidPose {
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
};

// Each body's pose at each frame from bodies.csv: its centre of mass and orientation.
std::map<std::string, std::map<int, SolidPose>> readBodyPoses(const fs::path& path) {
  const CsvTable table = readCsvTable(path);
  std::vector<int> columns;
  for (const char* name : {"frame", "body", "x", "y", "z", "qw", "qx", "qy", "qz"}) {
    columns.push_back(table.column(name));
    if (columns.back() < 0) throw InputError(path.string(), name, "column missing");
  }
  std::map<std::string, std::map<int, SolidPose>> poses;
  for (const std::vector<std::string>& row : table.rows) {
    double v[9];
    for (int k = 0; k < 9; ++k) v[k] = k == 1 ? 0 : std::atof(row[size_t(columns[size_t(k)])].c_str());
    SolidPose pose;
    pose.translation = Eigen::Vector3d(v[2], v[3], v[4]);
    pose.rotation = Eigen::Quaterniond(v[5], v[6], v[7], v[8]).normalized();
    poses[row[size_t(columns[1])]][int(v[0])] = pose;
  }
  return poses;
}

// A collider or body: its frame-0 mesh taken into its own frame (pose at frame 0 undone) and, when it moves,
// its pose at every frame as translate and orient samples; a standing one stays in the world.
void writeSolid(std::ostream& out, const ExportRun& run, const SolidFiles& solid, const std::map<int, SolidPose>& poses,
                Progress& progress) {
  TriangleMesh mesh = readMeshPly(run.dir / solid.folder / (solid.settings.name + ".ply"));
  const bool moving = !poses.empty();
  if (moving) {
    if (!poses.count(0)) throw InputError((run.dir / "bodies.csv").string(), solid.settings.name, "no row at frame 0");
    const SolidPose& start = poses.at(0);
    for (Eigen::Vector3f& p : mesh.positions)
      p = (start.rotation.conjugate() * (p.cast<double>() - start.translation)).cast<float>();
    for (Eigen::Vector3f& n : mesh.normals) n = (start.rotation.conjugate() * n.cast<double>()).cast<float>();
  }
  std::string points, counts, indices, color;
  appendVectors(points, mesh.positions);
  appendTopology(counts, indices, mesh);
  appendTuple(color, solid.settings.color);
  out << "        def Mesh \"" << primName(solid.settings.name) << "\"\n        {\n"
      << "            uniform token subdivisionScheme = \"none\"\n"
      << "            uniform token orientation = \"" << orientation(mesh) << "\"\n"
      << "            color3f[] primvars:displayColor = [" << color << "]\n"
      << "            point3f[] points = " << points << "\n"
      << "            int[] faceVertexCounts = " << counts << "\n"
      << "            int[] faceVertexIndices = " << indices << "\n";
  if (moving) {
    std::string translate, orient;
    for (int f : run.frames) {
      const auto it = poses.find(f);
      if (it == poses.end()) continue;
      translate += "                " + std::to_string(f) + ": ";
      appendTuple(translate, it->second.translation);
      translate += ",\n";
      orient += "                " + std::to_string(f) + ": ";
      const Eigen::Quaternionf q = it->second.rotation.cast<float>();
      appendTuple(orient, Eigen::Vector4f(q.w(), q.x(), q.y(), q.z()));
      orient += ",\n";
    }
    out << "            double3 xformOp:translate.timeSamples = {\n"
        << translate << "            }\n"
        << "            quatf xformOp:orient.timeSamples = {\n"
        << orient << "            }\n"
        << "            uniform token[] xformOpOrder = [\"xformOp:translate\", \"xformOp:orient\"]\n";
  }
  out << "        }\n";
  progress.advance();
}

}  // namespace

std::vector<fs::path> exportUsd(const ExportRun& run, Progress& progress) {
  const fs::path path = run.dir / "export" / "scene.usda";
  size_t total = run.solids.size();
  for (const FrameSeries& s : run.series) total += s.frames.size() * (s.mesh ? 6 : 4);
  progress.start("export usd", total);
  // The moving solids' poses: a body's from bodies.csv, a keyframed collider's from its motion.
  std::map<std::string, std::map<int, SolidPose>> bodyPoses;
  if (!run.scene.bodies.empty()) bodyPoses = readBodyPoses(run.dir / "bodies.csv");
  writeFileAtomically(path, [&](std::ostream& out) {
    out << "#usda 1.0\n(\n"
        << "    defaultPrim = \"" << primName(run.scene.name) << "\"\n"
        << "    doc = \"surge export --format usd\"\n"
        << "    metersPerUnit = 1\n    upAxis = \"Y\"\n"
        << "    startTimeCode = " << run.frames.front() << "\n    endTimeCode = " << run.frames.back() << "\n";
    std::string fps;
    appendNumber(fps, run.scene.output.fps);
    out << "    timeCodesPerSecond = " << fps << "\n    framesPerSecond = " << fps << "\n)\n\n"
        << "def Xform \"" << primName(run.scene.name) << "\"\n{\n";
    for (const FrameSeries& series : run.series) {
      if (series.mesh)
        writeSurface(out, run, series, progress);
      else
        writePoints(out, run, series, progress);
    }
    for (const std::string folder : {"colliders", "bodies"}) {
      bool opened = false;
      for (const SolidFiles& solid : run.solids) {
        if (solid.folder != folder) continue;
        if (!opened) out << "    def Xform \"" << folder << "\"\n    {\n";
        opened = true;
        std::map<int, SolidPose> poses;
        if (folder == "bodies") {
          const auto it = bodyPoses.find(solid.settings.name);
          if (it == bodyPoses.end())
            throw InputError((run.dir / "bodies.csv").string(), solid.settings.name, "the body has no rows");
          poses = it->second;
        } else if (solid.moving) {
          for (int f : run.frames) {
            const Pose pose = colliderPose(solid.settings, run.time(f));
            poses[f] = {pose.translation, pose.rotation};
          }
          const Pose start = colliderPose(solid.settings, 0.0);
          poses[0] = {start.translation, start.rotation};
        }
        writeSolid(out, run, solid, poses, progress);
      }
      if (opened) out << "    }\n";
    }
    out << "}\n";
  });
  progress.finish();
  return {path};
}

}  // namespace surge
