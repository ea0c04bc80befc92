#include "core/ply.h"

#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

#include "core/errors.h"

namespace surge {
namespace {

static_assert(sizeof(float) == 4, "PLY float is 32 bits");

// One scalar property or list property of a PLY element.
struct PlyProperty {
  std::string name;
  std::string type;       // scalar type, or the item type of a list
  std::string countType;  // empty unless a list
};

struct PlyElement {
  std::string name;
  size_t count = 0;
  std::vector<PlyProperty> properties;
};

int typeSize(const std::string& type) {
  static const std::map<std::string, int> sizes = {
      {"char", 1},  {"uchar", 1},   {"int8", 1},   {"uint8", 1},  {"short", 2}, {"ushort", 2},
      {"int16", 2}, {"uint16", 2},  {"int", 4},    {"uint", 4},   {"int32", 4}, {"uint32", 4},
      {"float", 4}, {"float32", 4}, {"double", 8}, {"float64", 8}};
  auto it = sizes.find(type);
  return it == sizes.end() ? 0 : it->second;
}

double readScalar(const char* p, const std::string& type) {
  auto load = [p](auto value) {
    std::memcpy(&value, p, sizeof value);
    return static_cast<double>(value);
  };
  if (type == "float" || type == "float32") return load(float{});
  if (type == "double" || type == "float64") return load(double{});
  if (type == "int" || type == "int32") return load(int32_t{});
  if (type == "uint" || type == "uint32") return load(uint32_t{});
  if (type == "short" || type == "int16") return load(int16_t{});
  if (type == "ushort" || type == "uint16") return load(uint16_t{});
  if (type == "char" || type == "int8") return load(int8_t{});
  return load(uint8_t{});
}

// A parsed binary PLY: the header and, per element, the raw bytes of its records.
struct PlyFile {
  std::vector<PlyElement> elements;
  std::vector<std::string> comments;
  std::vector<std::string> data;  // per element
};

PlyFile parsePly(const fs::path& path) {
  const std::string where = path.string();
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(where, "cannot be read");
  PlyFile file;
  std::string line;
  int lineNumber = 0;
  auto fail = [&](const std::string& message) {
    throw InputError(where, "line " + std::to_string(lineNumber), message);
  };
  bool sawFormat = false;
  while (true) {
    if (!std::getline(in, line)) fail("header ends before end_header");
    ++lineNumber;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream words(line);
    std::string word;
    words >> word;
    if (lineNumber == 1) {
      if (word != "ply") fail("not a PLY file (the first line is not 'ply')");
      continue;
    }
    if (word == "format") {
      std::string format;
      words >> format;
      if (format != "binary_little_endian")
        fail("format '" + format + "' is not supported (binary_little_endian)");
      sawFormat = true;
    } else if (word == "comment" || word == "obj_info") {
      file.comments.push_back(line.size() > 8 ? line.substr(8) : "");
    } else if (word == "element") {
      PlyElement element;
      long long count = -1;
      words >> element.name >> count;
      if (element.name.empty() || count < 0) fail("malformed element line");
      element.count = static_cast<size_t>(count);
      file.elements.push_back(element);
    } else if (word == "property") {
      if (file.elements.empty()) fail("property before any element");
      PlyProperty property;
      std::string type;
      words >> type;
      if (type == "list") {
        words >> property.countType >> property.type >> property.name;
        if (!typeSize(property.countType) || !typeSize(property.type)) fail("unknown list type");
      } else {
        property.type = type;
        words >> property.name;
        if (!typeSize(type)) fail("unknown property type '" + type + "'");
      }
      file.elements.back().properties.push_back(property);
    } else if (word == "end_header") {
      break;
    } else if (!word.empty()) {
      fail("unexpected header keyword '" + word + "'");
    }
  }
  if (!sawFormat) fail("no format line");
  // What is left after the header bounds every count below: no allocation larger than the file.
  const std::streampos bodyStart = in.tellg();
  in.seekg(0, std::ios::end);
  const size_t bodySize = size_t(in.tellg() - bodyStart);
  in.seekg(bodyStart);
  for (const PlyElement& element : file.elements) {
    std::string bytes;
    bool hasList = false;
    size_t recordSize = 0;
    for (const PlyProperty& p : element.properties) {
      hasList |= !p.countType.empty();
      recordSize += typeSize(p.type);
    }
    if (!hasList) {
      if (recordSize > 0 && element.count > bodySize / recordSize)
        throw InputError(where, "element " + element.name,
                         "file ends before its " + std::to_string(element.count) + " records");
      bytes.resize(recordSize * element.count);
      in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
      if (static_cast<size_t>(in.gcount()) != bytes.size())
        throw InputError(where, "element " + element.name,
                         "file ends before its " + std::to_string(element.count) + " records");
    } else {
      // Lists: read record by record, keeping the raw bytes.
      for (size_t r = 0; r < element.count; ++r) {
        for (const PlyProperty& p : element.properties) {
          char buffer[8];
          if (p.countType.empty()) {
            in.read(buffer, typeSize(p.type));
            bytes.append(buffer, typeSize(p.type));
            continue;
          }
          in.read(buffer, typeSize(p.countType));
          const double count = readScalar(buffer, p.countType);
          // A list's length: a whole number the rest of the file can hold (PLY readers elsewhere trust it).
          if (!in || !(count >= 0) || count != std::floor(count) || count * typeSize(p.type) > double(bodySize))
            throw InputError(where, "element " + element.name,
                             "record " + std::to_string(r) + " has a list length that is not a count the file holds");
          const size_t items = static_cast<size_t>(count);
          bytes.append(buffer, typeSize(p.countType));
          std::string items_bytes(items * typeSize(p.type), '\0');
          in.read(items_bytes.data(), static_cast<std::streamsize>(items_bytes.size()));
          bytes += items_bytes;
        }
        if (!in)
          throw InputError(where, "element " + element.name, "file ends inside record " + std::to_string(r));
      }
    }
    file.data.push_back(std::move(bytes));
  }
  return file;
}

const PlyElement* findElement(const PlyFile& file, const std::string& name, size_t* index) {
  for (size_t i = 0; i < file.elements.size(); ++i)
    if (file.elements[i].name == name) {
      *index = i;
      return &file.elements[i];
    }
  return nullptr;
}

// Reads the named scalar properties of a list-free element into columns of doubles; a missing name throws
// unless optional, in which case its column stays empty.
std::vector<std::vector<double>> readColumns(const PlyFile& file, size_t elementIndex,
                                             const std::vector<std::string>& names,
                                             const std::vector<bool>& optional, const std::string& where) {
  const PlyElement& element = file.elements[elementIndex];
  std::vector<int> offsets(names.size(), -1);
  std::vector<std::string> types(names.size());
  int recordSize = 0;
  for (const PlyProperty& p : element.properties) {
    if (!p.countType.empty())
      throw InputError(where, "element " + element.name,
                       "list property '" + p.name + "' is not expected here");
    for (size_t n = 0; n < names.size(); ++n)
      if (p.name == names[n]) {
        offsets[n] = recordSize;
        types[n] = p.type;
      }
    recordSize += typeSize(p.type);
  }
  std::vector<std::vector<double>> columns(names.size());
  for (size_t n = 0; n < names.size(); ++n) {
    if (offsets[n] < 0) {
      if (optional[n]) continue;
      throw InputError(where, "property " + names[n], "missing from element " + element.name);
    }
    columns[n].resize(element.count);
    const char* base = file.data[elementIndex].data();
    for (size_t r = 0; r < element.count; ++r)
      columns[n][r] = readScalar(base + r * recordSize + offsets[n], types[n]);
  }
  return columns;
}

template <typename T>
void put(std::ostream& out, T value) {
  out.write(reinterpret_cast<const char*>(&value), sizeof value);
}

}  // namespace

void writeParticlePly(const fs::path& path, const ParticleFrame& frame) {
  writeFileAtomically(path, [&](std::ostream& out) {
    out << "ply\nformat binary_little_endian 1.0\ncomment surge particle frame\n"
        << "comment dimensions " << frame.dimensions << "\n"
        << "element vertex " << frame.size() << "\n"
        << "property float x\nproperty float y\nproperty float z\n"
        << "property float vx\nproperty float vy\nproperty float vz\n"
        << "property uint id\nend_header\n";
    std::string buffer;
    buffer.resize(frame.size() * 28);
    char* p = buffer.data();
    for (size_t i = 0; i < frame.size(); ++i) {
      const float values[6] = {frame.position[i].x(), frame.position[i].y(), frame.position[i].z(),
                               frame.velocity[i].x(), frame.velocity[i].y(), frame.velocity[i].z()};
      std::memcpy(p, values, sizeof values);
      std::memcpy(p + 24, &frame.id[i], 4);
      p += 28;
    }
    out.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
  });
}

ParticleFrame readParticlePly(const fs::path& path) {
  const std::string where = path.string();
  const PlyFile file = parsePly(path);
  size_t index = 0;
  if (!findElement(file, "vertex", &index)) throw InputError(where, "element vertex", "missing");
  const auto columns = readColumns(file, index, {"x", "y", "z", "vx", "vy", "vz", "id"},
                                   {false, false, false, false, false, false, true}, where);
  ParticleFrame frame;
  for (const std::string& comment : file.comments)
    if (comment.rfind("dimensions ", 0) == 0) {
      const std::string value = comment.substr(11);
      if (value != "2" && value != "3")
        throw InputError(where, "comment dimensions", "must be 2 or 3, not '" + value + "'");
      frame.dimensions = value[0] - '0';
    }
  const size_t n = file.elements[index].count;
  frame.resize(n);
  const char* names[6] = {"x", "y", "z", "vx", "vy", "vz"};
  for (size_t i = 0; i < n; ++i) {
    for (int k = 0; k < 6; ++k)
      if (!std::isfinite(float(columns[size_t(k)][i])))
        throw InputError(where, "vertex " + std::to_string(i) + " " + names[k], "not a finite number");
    frame.position[i] = Eigen::Vector3f(float(columns[0][i]), float(columns[1][i]), float(columns[2][i]));
    frame.velocity[i] = Eigen::Vector3f(float(columns[3][i]), float(columns[4][i]), float(columns[5][i]));
    frame.id[i] = columns[6].empty() ? static_cast<uint32_t>(i) : static_cast<uint32_t>(columns[6][i]);
  }
  return frame;
}

void writeMeshPly(const fs::path& path, const TriangleMesh& mesh) {
  const bool normals = mesh.normals.size() == mesh.positions.size() && !mesh.positions.empty();
  writeFileAtomically(path, [&](std::ostream& out) {
    out << "ply\nformat binary_little_endian 1.0\ncomment surge surface mesh\n"
        << "element vertex " << mesh.positions.size() << "\n"
        << "property float x\nproperty float y\nproperty float z\n";
    if (normals) out << "property float nx\nproperty float ny\nproperty float nz\n";
    out << "element face " << mesh.triangles.size() << "\n"
        << "property list uchar uint vertex_indices\nend_header\n";
    for (size_t i = 0; i < mesh.positions.size(); ++i) {
      for (int k = 0; k < 3; ++k) put(out, mesh.positions[i][k]);
      if (normals)
        for (int k = 0; k < 3; ++k) put(out, mesh.normals[i][k]);
    }
    for (const auto& t : mesh.triangles) {
      put<uint8_t>(out, 3);
      for (uint32_t v : t) put(out, v);
    }
  });
}

TriangleMesh readMeshPly(const fs::path& path) {
  const std::string where = path.string();
  const PlyFile file = parsePly(path);
  TriangleMesh mesh;
  size_t vertexIndex = 0, faceIndex = 0;
  if (!findElement(file, "vertex", &vertexIndex)) throw InputError(where, "element vertex", "missing");
  const auto columns = readColumns(file, vertexIndex, {"x", "y", "z", "nx", "ny", "nz"},
                                   {false, false, false, true, true, true}, where);
  const size_t n = file.elements[vertexIndex].count;
  mesh.positions.resize(n);
  for (size_t i = 0; i < n; ++i)
    mesh.positions[i] = Eigen::Vector3f(float(columns[0][i]), float(columns[1][i]), float(columns[2][i]));
  if (!columns[3].empty() && !columns[4].empty() && !columns[5].empty()) {
    mesh.normals.resize(n);
    for (size_t i = 0; i < n; ++i)
      mesh.normals[i] = Eigen::Vector3f(float(columns[3][i]), float(columns[4][i]), float(columns[5][i]));
  }
  const PlyElement* faces = findElement(file, "face", &faceIndex);
  if (!faces) return mesh;
  if (faces->properties.size() != 1 || faces->properties[0].countType.empty())
    throw InputError(where, "element face", "expected a single vertex_indices list");
  const PlyProperty& list = faces->properties[0];
  const char* p = file.data[faceIndex].data();
  const char* end = p + file.data[faceIndex].size();
  const int countSize = typeSize(list.countType), itemSize = typeSize(list.type);
  for (size_t f = 0; f < faces->count; ++f) {
    if (end - p < countSize) throw InputError(where, "face " + std::to_string(f), "the file ends inside the faces");
    const double count = readScalar(p, list.countType);
    p += countSize;
    if (!(count >= 0 && count <= double(end - p) / itemSize))
      throw InputError(where, "face " + std::to_string(f), "vertex count out of range");
    const size_t items = static_cast<size_t>(count);
    std::vector<uint32_t> polygon(items);
    for (size_t k = 0; k < items; ++k, p += itemSize) {
      const double index = readScalar(p, list.type);  // checked before the cast: a float may hold anything
      if (!(index >= 0 && index < double(n)))
        throw InputError(where, "face " + std::to_string(f), "vertex index out of range");
      polygon[k] = static_cast<uint32_t>(index);
    }
    for (size_t k = 1; k + 1 < items; ++k) mesh.triangles.push_back({polygon[0], polygon[k], polygon[k + 1]});
  }
  return mesh;
}

}  // namespace surge
