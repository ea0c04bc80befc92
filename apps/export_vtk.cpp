// surge export --format vtk: each frame as VTK XML PolyData (.vtp) with its arrays appended raw after the XML,
// and one ParaView collection (.pvd) a kind, so that ParaView opens a run as time series. A particle frame keeps
// every property its PLY holds (x y z the points, vx vy vz one vector `velocity`, the rest scalars of their own
// type) with one vertex cell a particle; a mesh keeps its triangles, normals and velocities.
#include <algorithm>
#include <charconv>
#include <cstring>
#include <limits>
#include <map>
#include <sstream>

#include "apps/export.h"
#include "core/errors.h"
#include "core/parallel.h"
#include "core/ply.h"

namespace surge {
namespace {

// One data array of a .vtp: its section of the piece, name, VTK type, components and little-endian bytes.
struct VtkArray {
  std::string section;  // "PointData", "Points", "Verts" or "Polys"
  std::string name, type;
  int components = 1;
  std::string bytes;
};

template <typename T>
std::string bytesOf(const T* values, size_t count) {
  return std::string(reinterpret_cast<const char*>(values), count * sizeof(T));
}

// Cell connectivity and end offsets, as Int32 while they fit (they always do below 2^31 indices), else Int64.
void addCells(std::vector<VtkArray>& arrays, const std::string& section, const std::vector<int64_t>& connectivity,
              const std::vector<int64_t>& offsets) {
  const bool narrow = connectivity.size() < size_t(std::numeric_limits<int32_t>::max());
  for (const auto* list : {&connectivity, &offsets}) {
    VtkArray array{section, list == &connectivity ? "connectivity" : "offsets", narrow ? "Int32" : "Int64", 1, {}};
    if (narrow) {
      const std::vector<int32_t> values(list->begin(), list->end());
      array.bytes = bytesOf(values.data(), values.size());
    } else {
      array.bytes = bytesOf(list->data(), list->size());
    }
    arrays.push_back(std::move(array));
  }
}

// Writes a .vtp: the XML naming each array's offset into the appended block, then the block, each array's bytes
// after their count (header_type UInt64).
void writePolyData(const fs::path& path, size_t points, size_t verts, size_t polys,
                   const std::vector<VtkArray>& arrays) {
  fs::create_directories(path.parent_path());
  writeFileAtomically(path, [&](std::ostream& out) {
    out << "<?xml version=\"1.0\"?>\n"
        << "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
        << "  <PolyData>\n"
        << "    <Piece NumberOfPoints=\"" << points << "\" NumberOfVerts=\"" << verts
        << "\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"" << polys << "\">\n";
    uint64_t offset = 0;
    for (const char* section : {"PointData", "Points", "Verts", "Polys"}) {
      std::ostringstream items;
      std::string hints;
      for (const VtkArray& a : arrays) {
        if (a.section != section) continue;
        if (a.name == "velocity") hints += " Vectors=\"velocity\"";
        if (a.name == "Normals") hints += " Normals=\"Normals\"";
        items << "        <DataArray type=\"" << a.type << "\" Name=\"" << a.name << "\" NumberOfComponents=\""
              << a.components << "\" format=\"appended\" offset=\"" << offset << "\"/>\n";
        offset += sizeof(uint64_t) + a.bytes.size();
      }
      if (items.tellp() > 0 || std::strcmp(section, "Points") == 0)
        out << "      <" << section << hints << ">\n" << items.str() << "      </" << section << ">\n";
    }
    out << "    </Piece>\n  </PolyData>\n  <AppendedData encoding=\"raw\">\n   _";
    for (const char* section : {"PointData", "Points", "Verts", "Polys"})
      for (const VtkArray& a : arrays) {
        if (a.section != section) continue;
        const uint64_t size = a.bytes.size();
        out.write(reinterpret_cast<const char*>(&size), sizeof size);
        out.write(a.bytes.data(), static_cast<std::streamsize>(a.bytes.size()));
      }
    out << "\n  </AppendedData>\n</VTKFile>\n";
  });
}

template <typename T>
std::string interleave(const std::vector<const PlyColumn*>& columns) {
  const size_t n = columns.front()->values.size();
  std::vector<T> values(n * columns.size());
  for (size_t i = 0; i < n; ++i)
    for (size_t k = 0; k < columns.size(); ++k) values[i * columns.size() + k] = static_cast<T>(columns[k]->values[i]);
  return bytesOf(values.data(), values.size());
}

// A VTK data type: its name and the bytes of PLY columns interleaved in it.
struct VtkType {
  std::string name;
  std::string (*interleave)(const std::vector<const PlyColumn*>&);
};

// The VTK type of a PLY property type (core/ply's names); Float64 for any other.
const VtkType& vtkType(const std::string& plyType) {
  static const VtkType int8{"Int8", interleave<int8_t>}, uint8{"UInt8", interleave<uint8_t>},
      int16{"Int16", interleave<int16_t>}, uint16{"UInt16", interleave<uint16_t>}, int32{"Int32", interleave<int32_t>},
      uint32{"UInt32", interleave<uint32_t>}, float32{"Float32", interleave<float>},
      float64{"Float64", interleave<double>};
  static const std::map<std::string, const VtkType*> types = {
      {"char", &int8},     {"int8", &int8},       {"uchar", &uint8},    {"uint8", &uint8},
      {"short", &int16},   {"int16", &int16},     {"ushort", &uint16},  {"uint16", &uint16},
      {"int", &int32},     {"int32", &int32},     {"uint", &uint32},    {"uint32", &uint32},
      {"float", &float32}, {"float32", &float32}, {"double", &float64}, {"float64", &float64}};
  const auto it = types.find(plyType);
  return it == types.end() ? float64 : *it->second;
}

// An array of one or three PLY columns, in their own type when they share one, else Float64.
VtkArray columnArray(const std::string& section, const std::string& name,
                     const std::vector<const PlyColumn*>& columns) {
  const VtkType* type = &vtkType(columns.front()->type);
  for (const PlyColumn* c : columns)
    if (vtkType(c->type).name != type->name) type = &vtkType("double");
  return {section, name, type->name, int(columns.size()), type->interleave(columns)};
}

// A particle (or whitewater) frame: every vertex property, one vertex cell a particle.
void writePointsFrame(const fs::path& ply, const fs::path& vtp) {
  const std::vector<PlyColumn> columns = readVertexColumns(ply);
  std::map<std::string, const PlyColumn*> byName;
  for (const PlyColumn& c : columns) byName[c.name] = &c;
  for (const char* axis : {"x", "y", "z"})
    if (!byName.count(axis)) throw InputError(ply.string(), std::string("property ") + axis, "missing");
  const size_t n = byName["x"]->values.size();
  std::vector<VtkArray> arrays;
  arrays.push_back(columnArray("Points", "Points", {byName["x"], byName["y"], byName["z"]}));
  const bool velocity = byName.count("vx") && byName.count("vy") && byName.count("vz");
  if (velocity) arrays.push_back(columnArray("PointData", "velocity", {byName["vx"], byName["vy"], byName["vz"]}));
  for (const PlyColumn& c : columns) {
    const bool spatial = c.name == "x" || c.name == "y" || c.name == "z";
    const bool inVelocity = velocity && (c.name == "vx" || c.name == "vy" || c.name == "vz");
    if (!spatial && !inVelocity) arrays.push_back(columnArray("PointData", c.name, {&c}));
  }
  std::vector<int64_t> connectivity(n), offsets(n);
  for (size_t i = 0; i < n; ++i) connectivity[i] = int64_t(i), offsets[i] = int64_t(i + 1);
  addCells(arrays, "Verts", connectivity, offsets);
  writePolyData(vtp, n, n, 0, arrays);
}

// A mesh (surface, collider, body): its triangles, and its normals and velocities where it has them.
void writeMeshFrame(const fs::path& ply, const fs::path& vtp) {
  const TriangleMesh mesh = readMeshPly(ply);
  const size_t n = mesh.positions.size();
  std::vector<VtkArray> arrays;
  auto vectors = [&](const std::string& section, const std::string& name, const std::vector<Eigen::Vector3f>& v) {
    std::vector<float> values(v.size() * 3);
    for (size_t i = 0; i < v.size(); ++i)
      for (int k = 0; k < 3; ++k) values[i * 3 + k] = v[i][k];
    arrays.push_back({section, name, "Float32", 3, bytesOf(values.data(), values.size())});
  };
  if (mesh.normals.size() == n && n > 0) vectors("PointData", "Normals", mesh.normals);
  if (mesh.velocities.size() == n && n > 0) vectors("PointData", "velocity", mesh.velocities);
  vectors("Points", "Points", mesh.positions);
  std::vector<int64_t> connectivity, offsets;
  connectivity.reserve(mesh.triangles.size() * 3);
  for (const auto& t : mesh.triangles) {
    for (uint32_t v : t) connectivity.push_back(v);
    offsets.push_back(int64_t(connectivity.size()));
  }
  addCells(arrays, "Polys", connectivity, offsets);
  writePolyData(vtp, n, 0, mesh.triangles.size(), arrays);
}

// One entry of a .pvd: a time step's file (relative to the .pvd), and its part and name where a time step
// holds several (one a collider).
struct PvdEntry {
  double time;
  int part;
  std::string name;
  fs::path file;
};

void writePvd(const fs::path& path, const std::vector<PvdEntry>& entries) {
  writeFileAtomically(path, [&](std::ostream& out) {
    out << "<?xml version=\"1.0\"?>\n"
        << "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n";
    for (const PvdEntry& e : entries) {
      char time[32];
      *std::to_chars(time, time + sizeof time - 1, e.time).ptr = '\0';  // the shortest text that reads back exactly
      out << "    <DataSet timestep=\"" << time << "\" part=\"" << e.part << "\"";
      if (!e.name.empty()) out << " name=\"" << escapeXml(e.name) << "\"";
      out << " file=\"" << escapeXml(e.file.generic_string()) << "\"/>\n";
    }
    out << "  </Collection>\n</VTKFile>\n";
  });
}

// Converts every (ply, vtp) pair on all cores, a progress step each.
void convertAll(const std::vector<std::pair<fs::path, fs::path>>& jobs, bool mesh, Progress& progress) {
  parallelFor(
      0, jobs.size(),
      [&](size_t begin, size_t end) {
        for (size_t j = begin; j < end; ++j) {
          Progress::checkInterrupt();
          if (mesh)
            writeMeshFrame(jobs[j].first, jobs[j].second);
          else
            writePointsFrame(jobs[j].first, jobs[j].second);
          progress.advance();
        }
      },
      1);
}

}  // namespace

std::vector<fs::path> exportVtk(const ExportRun& run, Progress& progress) {
  const fs::path out = run.dir / "export";
  size_t total = 0;
  for (const FrameSeries& s : run.series) total += s.frames.size();
  for (const SolidFiles& solid : run.solids) total += solid.moving ? run.frames.size() : 1;
  progress.start("export vtk", total);
  std::vector<fs::path> written;
  // Particles, whitewater and surfaces: a .vtp a frame under <kind>/, then <kind>.pvd.
  for (const FrameSeries& series : run.series) {
    std::vector<std::pair<fs::path, fs::path>> jobs;
    std::vector<PvdEntry> entries;
    for (int f : series.frames) {
      const fs::path vtp = framePath(out, series.kind, f, "vtp");
      jobs.push_back({framePath(run.dir, series.kind, f, "ply"), vtp});
      entries.push_back({run.time(f), 0, "", fs::relative(vtp, out)});
      written.push_back(vtp);
    }
    convertAll(jobs, series.mesh, progress);
    written.push_back(out / (series.kind + ".pvd"));
    writePvd(written.back(), entries);
  }
  // Colliders and bodies: a standing solid's .vtp once, a moving one's each frame; a part each in their .pvd.
  for (const std::string folder : {"colliders", "bodies"}) {
    std::vector<std::pair<fs::path, fs::path>> jobs;
    std::vector<PvdEntry> entries;
    int part = 0;
    for (const SolidFiles& solid : run.solids) {
      if (solid.folder != folder) continue;
      const std::string& name = solid.settings.name;
      const fs::path standing = out / folder / (name + ".vtp");
      if (!solid.moving) jobs.push_back({run.solidMesh(solid, 0), standing});
      for (int f : run.frames) {
        const fs::path vtp = solid.moving ? framePath(out / folder, name, f, "vtp") : standing;
        if (solid.moving) jobs.push_back({run.solidMesh(solid, f), vtp});
        entries.push_back({run.time(f), part, name, fs::relative(vtp, out)});
      }
      ++part;
    }
    if (jobs.empty()) continue;
    convertAll(jobs, true, progress);
    for (const auto& job : jobs) written.push_back(job.second);
    std::stable_sort(entries.begin(), entries.end(),
                     [](const PvdEntry& a, const PvdEntry& b) { return a.time < b.time; });
    written.push_back(out / (folder + ".pvd"));
    writePvd(written.back(), entries);
  }
  progress.finish();
  return written;
}

}  // namespace surge
