#include "core/ply.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

#include "core/errors.h"
#include "core/scene.h"

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

// Stores v as a value of `type` at p (little-endian, as readScalar reads it); false if the type cannot hold it
// (an integer type given a fraction, or a number out of its range).
bool storeScalar(char* p, const std::string& type, double v) {
  auto store = [p](auto value) {
    std::memcpy(p, &value, sizeof value);
    return true;
  };
  auto integer = [&](auto zero, double lo, double hi) {
    if (!(v >= lo && v <= hi) || v != std::floor(v)) return false;
    return store(static_cast<decltype(zero)>(v));
  };
  if (type == "float" || type == "float32") return std::isfinite(v) && std::abs(v) <= 3.4e38 && store(float(v));
  if (type == "double" || type == "float64") return std::isfinite(v) && store(v);
  if (type == "int" || type == "int32") return integer(int32_t{}, -2147483648.0, 2147483647.0);
  if (type == "uint" || type == "uint32") return integer(uint32_t{}, 0, 4294967295.0);
  if (type == "short" || type == "int16") return integer(int16_t{}, -32768, 32767);
  if (type == "ushort" || type == "uint16") return integer(uint16_t{}, 0, 65535);
  if (type == "char" || type == "int8") return integer(int8_t{}, -128, 127);
  return integer(uint8_t{}, 0, 255);
}

enum class PlyFormat { BinaryLittleEndian, BinaryBigEndian, Ascii };

// A parsed PLY: the header and, per element, the bytes of its records as binary little-endian holds them (an
// ASCII or big-endian body is converted as it is read, so that one reader serves all three formats).
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
  PlyFormat format = PlyFormat::BinaryLittleEndian;
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
      std::string name;
      words >> name;
      if (name == "binary_little_endian") format = PlyFormat::BinaryLittleEndian;
      else if (name == "binary_big_endian") format = PlyFormat::BinaryBigEndian;
      else if (name == "ascii") format = PlyFormat::Ascii;
      else fail("format '" + name + "' is not one of ascii, binary_little_endian, binary_big_endian");
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
  // One value of `type` from the body into buffer, as little-endian bytes; false at the end of the file or, in
  // ASCII, at a word that is not a number the type holds.
  auto readValue = [&](const std::string& type, char* buffer) {
    const int size = typeSize(type);
    if (format == PlyFormat::Ascii) {
      std::string token;
      if (!(in >> token)) return false;
      char* end = nullptr;
      const double v = std::strtod(token.c_str(), &end);
      return end == token.c_str() + token.size() && storeScalar(buffer, type, v);
    }
    in.read(buffer, size);
    if (format == PlyFormat::BinaryBigEndian) std::reverse(buffer, buffer + size);
    return static_cast<bool>(in);
  };
  for (const PlyElement& element : file.elements) {
    std::string bytes;
    bool hasList = false;
    size_t recordSize = 0;
    for (const PlyProperty& p : element.properties) {
      hasList |= !p.countType.empty();
      recordSize += typeSize(p.type);
    }
    if (!hasList && format == PlyFormat::BinaryLittleEndian) {
      if (recordSize > 0 && element.count > bodySize / recordSize)
        throw InputError(where, "element " + element.name,
                         "file ends before its " + std::to_string(element.count) + " records");
      bytes.resize(recordSize * element.count);
      in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
      if (static_cast<size_t>(in.gcount()) != bytes.size())
        throw InputError(where, "element " + element.name,
                         "file ends before its " + std::to_string(element.count) + " records");
    } else {
      // Record by record (lists, or a body to convert), keeping little-endian bytes. A record takes at least a
      // byte of the body, a list item its size (a byte in ASCII), which bounds what a file can claim before
      // anything is allocated for it.
      if (element.count > bodySize)
        throw InputError(where, "element " + element.name,
                         "file ends before its " + std::to_string(element.count) + " records");
      auto ended = [&](size_t r) {
        return InputError(where, "element " + element.name,
                          format == PlyFormat::Ascii && in
                              ? "record " + std::to_string(r) + " holds a word that is not a number of its type"
                              : "file ends inside record " + std::to_string(r));
      };
      for (size_t r = 0; r < element.count; ++r) {
        for (const PlyProperty& p : element.properties) {
          char buffer[8];
          if (p.countType.empty()) {
            if (!readValue(p.type, buffer)) throw ended(r);
            bytes.append(buffer, typeSize(p.type));
            continue;
          }
          if (!readValue(p.countType, buffer)) throw ended(r);
          const double count = readScalar(buffer, p.countType);
          // A list's length: a whole number the rest of the file can hold (PLY readers elsewhere trust it).
          const int leastItemBytes = format == PlyFormat::Ascii ? 1 : typeSize(p.type);
          if (!(count >= 0) || count != std::floor(count) || count * leastItemBytes > double(bodySize))
            throw InputError(where, "element " + element.name,
                             "record " + std::to_string(r) + " has a list length that is not a count the file holds");
          const size_t items = static_cast<size_t>(count);
          bytes.append(buffer, typeSize(p.countType));
          if (format == PlyFormat::BinaryLittleEndian) {  // the items as they stand, in one read
            const size_t at = bytes.size();
            bytes.resize(at + items * typeSize(p.type));
            in.read(bytes.data() + at, static_cast<std::streamsize>(items * typeSize(p.type)));
            if (!in) throw ended(r);
            continue;
          }
          for (size_t k = 0; k < items; ++k) {
            if (!readValue(p.type, buffer)) throw ended(r);
            bytes.append(buffer, typeSize(p.type));
          }
        }
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
        << "property uint id\n" << (frame.fluid.empty() ? "" : "property uchar fluid\n") << "end_header\n";
    const size_t record = frame.fluid.empty() ? 28 : 29;
    std::string buffer;
    buffer.resize(frame.size() * record);
    char* p = buffer.data();
    for (size_t i = 0; i < frame.size(); ++i) {
      const float values[6] = {frame.position[i].x(), frame.position[i].y(), frame.position[i].z(),
                               frame.velocity[i].x(), frame.velocity[i].y(), frame.velocity[i].z()};
      std::memcpy(p, values, sizeof values);
      std::memcpy(p + 24, &frame.id[i], 4);
      if (record == 29) p[28] = static_cast<char>(frame.fluid[i]);
      p += record;
    }
    out.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
  });
}

ParticleFrame readParticlePly(const fs::path& path) {
  const std::string where = path.string();
  const PlyFile file = parsePly(path);
  size_t index = 0;
  if (!findElement(file, "vertex", &index)) throw InputError(where, "element vertex", "missing");
  const auto columns = readColumns(file, index, {"x", "y", "z", "vx", "vy", "vz", "id", "fluid"},
                                   {false, false, false, false, false, false, true, true}, where);
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
  if (!columns[7].empty()) {
    frame.fluid.resize(n);
    for (size_t i = 0; i < n; ++i) {
      if (!(columns[7][i] >= 0 && columns[7][i] < 256))
        throw InputError(where, "vertex " + std::to_string(i) + " fluid", "not a fluid index 0-255");
      frame.fluid[i] = static_cast<uint8_t>(columns[7][i]);
    }
  }
  return frame;
}

void writeDiffusePly(const fs::path& path, const DiffuseFrame& frame) {
  writeFileAtomically(path, [&](std::ostream& out) {
    out << "ply\nformat binary_little_endian 1.0\ncomment surge whitewater frame\n"
        << "comment dimensions " << frame.dimensions << "\n"
        << "comment next_id " << frame.nextId << "\n"
        << "element vertex " << frame.size() << "\n"
        << "property float x\nproperty float y\nproperty float z\n"
        << "property float vx\nproperty float vy\nproperty float vz\n"
        << "property uint id\nproperty uchar type\nproperty float lifetime\nend_header\n";
    constexpr size_t kRecord = 24 + 4 + 1 + 4;
    std::string buffer(frame.size() * kRecord, '\0');
    char* p = buffer.data();
    for (size_t i = 0; i < frame.size(); ++i, p += kRecord) {
      const float values[6] = {frame.position[i].x(), frame.position[i].y(), frame.position[i].z(),
                               frame.velocity[i].x(), frame.velocity[i].y(), frame.velocity[i].z()};
      std::memcpy(p, values, sizeof values);
      std::memcpy(p + 24, &frame.id[i], 4);
      std::memcpy(p + 28, &frame.type[i], 1);
      std::memcpy(p + 29, &frame.lifetime[i], 4);
    }
    out.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
  });
}

DiffuseFrame readDiffusePly(const fs::path& path) {
  const std::string where = path.string();
  const PlyFile file = parsePly(path);
  size_t index = 0;
  if (!findElement(file, "vertex", &index)) throw InputError(where, "element vertex", "missing");
  const auto columns =
      readColumns(file, index, {"x", "y", "z", "vx", "vy", "vz", "id", "type", "lifetime"},
                  std::vector<bool>(9, false), where);
  DiffuseFrame frame;
  for (const std::string& comment : file.comments) {
    if (comment.rfind("dimensions ", 0) == 0) frame.dimensions = comment.substr(11) == "2" ? 2 : 3;
    if (comment.rfind("next_id ", 0) == 0) frame.nextId = uint32_t(std::strtoul(comment.c_str() + 8, nullptr, 10));
  }
  const size_t n = file.elements[index].count;
  frame.resize(n);
  const char* names[9] = {"x", "y", "z", "vx", "vy", "vz", "id", "type", "lifetime"};
  for (size_t i = 0; i < n; ++i) {
    for (int k = 0; k < 9; ++k)
      if (!std::isfinite(float(columns[size_t(k)][i])))
        throw InputError(where, "vertex " + std::to_string(i) + " " + names[k], "not a finite number");
    if (columns[7][i] > kBubble)
      throw InputError(where, "vertex " + std::to_string(i) + " type", "must be 0 (spray), 1 (foam) or 2 (bubble)");
    frame.position[i] = Eigen::Vector3f(float(columns[0][i]), float(columns[1][i]), float(columns[2][i]));
    frame.velocity[i] = Eigen::Vector3f(float(columns[3][i]), float(columns[4][i]), float(columns[5][i]));
    frame.id[i] = uint32_t(columns[6][i]);
    frame.type[i] = uint8_t(columns[7][i]);
    frame.lifetime[i] = float(columns[8][i]);
    frame.nextId = std::max(frame.nextId, frame.id[i] + 1);
  }
  return frame;
}

bool readDiffusePlyIfPresent(const fs::path& path, DiffuseFrame& frame) {
  std::error_code error;
  if (!fs::exists(path, error)) return false;
  frame = readDiffusePly(path);
  return true;
}

std::vector<PlyColumn> readVertexColumns(const fs::path& path) {
  const std::string where = path.string();
  const PlyFile file = parsePly(path);
  size_t index = 0;
  if (!findElement(file, "vertex", &index)) throw InputError(where, "element vertex", "missing");
  std::vector<std::string> names;
  for (const PlyProperty& p : file.elements[index].properties) names.push_back(p.name);
  auto values = readColumns(file, index, names, std::vector<bool>(names.size(), false), where);
  std::vector<PlyColumn> columns(names.size());
  for (size_t n = 0; n < names.size(); ++n)
    columns[n] = {names[n], file.elements[index].properties[n].type, std::move(values[n])};
  return columns;
}

void writeMeshPly(const fs::path& path, const TriangleMesh& mesh) {
  const bool normals = mesh.normals.size() == mesh.positions.size() && !mesh.positions.empty();
  const bool velocities = mesh.velocities.size() == mesh.positions.size() && !mesh.positions.empty();
  writeFileAtomically(path, [&](std::ostream& out) {
    out << "ply\nformat binary_little_endian 1.0\ncomment surge surface mesh\n"
        << "element vertex " << mesh.positions.size() << "\n"
        << "property float x\nproperty float y\nproperty float z\n";
    if (normals) out << "property float nx\nproperty float ny\nproperty float nz\n";
    if (velocities) out << "property float vx\nproperty float vy\nproperty float vz\n";
    out << "element face " << mesh.triangles.size() << "\n"
        << "property list uchar uint vertex_indices\nend_header\n";
    for (size_t i = 0; i < mesh.positions.size(); ++i) {
      for (int k = 0; k < 3; ++k) put(out, mesh.positions[i][k]);
      if (normals)
        for (int k = 0; k < 3; ++k) put(out, mesh.normals[i][k]);
      if (velocities)
        for (int k = 0; k < 3; ++k) put(out, mesh.velocities[i][k]);
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
  const auto columns = readColumns(file, vertexIndex, {"x", "y", "z", "nx", "ny", "nz", "vx", "vy", "vz"},
                                   {false, false, false, true, true, true, true, true, true}, where);
  const size_t n = file.elements[vertexIndex].count;
  mesh.positions.resize(n);
  for (size_t i = 0; i < n; ++i)
    mesh.positions[i] = Eigen::Vector3f(float(columns[0][i]), float(columns[1][i]), float(columns[2][i]));
  if (!columns[3].empty() && !columns[4].empty() && !columns[5].empty()) {
    mesh.normals.resize(n);
    for (size_t i = 0; i < n; ++i)
      mesh.normals[i] = Eigen::Vector3f(float(columns[3][i]), float(columns[4][i]), float(columns[5][i]));
  }
  if (!columns[6].empty() && !columns[7].empty() && !columns[8].empty()) {
    mesh.velocities.resize(n);
    for (size_t i = 0; i < n; ++i)
      mesh.velocities[i] = Eigen::Vector3f(float(columns[6][i]), float(columns[7][i]), float(columns[8][i]));
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

// domain.periodic: the frame with the particles within `reach` of a periodic face copied a period over (both
// faces of an axis, and on from the first axis's copies to the second's, so a corner gets its diagonal image).
ParticleFrame withPeriodicImages(const ParticleFrame& frame, const Scene& scene, double reach) {
  ParticleFrame out = frame;
  for (int k = 0; k < scene.dimensions; ++k) {
    if (!scene.isPeriodic(k)) continue;
    const double lo = scene.domain.min[k], hi = scene.domain.max[k], period = hi - lo;
    const size_t n = out.size();
    for (size_t i = 0; i < n; ++i)
      for (const double shift : {period, -period}) {
        const double x = out.position[i][k];
        if (shift > 0 ? x >= lo + reach : x <= hi - reach) continue;
        out.position.push_back(out.position[i]);
        out.position.back()[k] = float(x + shift);
        out.velocity.push_back(out.velocity[i]);
        out.id.push_back(out.id[i]);
        if (!out.fluid.empty()) out.fluid.push_back(out.fluid[i]);
      }
  }
  return out;
}

}  // namespace surge
