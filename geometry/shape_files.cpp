#include "geometry/shape_files.h"

#include <stb/stb_image.h>
#include <tiny_obj_loader.h>

#include <algorithm>
#include <cmath>
#include <fstream>

#include "core/errors.h"
#include "geometry/triangle_mesh.h"

namespace surge {
namespace {

using Vec3 = Eigen::Vector3f;

void checkReadable(const std::string& file, const std::string& where, const std::string& key) {
  std::error_code error;
  if (!fs::exists(file, error)) throw InputError(where, key, "'" + file + "' does not exist");
  if (fs::is_directory(file, error)) throw InputError(where, key, "'" + file + "' is a directory");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(where, key, "'" + file + "' cannot be read");
}

}  // namespace

Heightfield readHeightfieldPng(const std::string& file, float sizeX, float sizeZ, float height,
                               const std::string& where, const std::string& key) {
  checkReadable(file, where, key);
  int width = 0, depth = 0, channels = 0;
  Heightfield h;
  const bool sixteen = stbi_is_16_bit(file.c_str());
  void* pixels = sixteen ? static_cast<void*>(stbi_load_16(file.c_str(), &width, &depth, &channels, 1))
                         : static_cast<void*>(stbi_load(file.c_str(), &width, &depth, &channels, 1));
  if (!pixels) {
    const char* reason = stbi_failure_reason();
    throw InputError(where, key, "'" + file + "' is not a readable PNG (" + (reason ? reason : "unknown") + ")");
  }
  if (width < 2 || depth < 2) {
    stbi_image_free(pixels);
    throw InputError(where, key, "'" + file + "' needs at least 2 x 2 pixels");
  }
  h.width = width;
  h.depth = depth;
  h.sizeX = sizeX;
  h.sizeZ = sizeZ;
  h.heights.resize(size_t(width) * depth);
  const float white = sixteen ? 65535.0f : 255.0f;
  for (size_t i = 0; i < h.heights.size(); ++i) {
    const float grey = sixteen ? static_cast<const uint16_t*>(pixels)[i] : static_cast<const uint8_t*>(pixels)[i];
    h.heights[i] = height * grey / white;
  }
  stbi_image_free(pixels);
  return h;
}

TriangleMesh heightfieldMesh(const Heightfield& h, float bottom, float spacing) {
  const int nx = std::max(2, std::min(h.width, int(std::ceil(h.sizeX / spacing)) + 1));
  const int nz = std::max(2, std::min(h.depth, int(std::ceil(h.sizeZ / spacing)) + 1));
  TriangleMesh mesh;
  auto vertex = [&](float x, float y, float z) {
    mesh.positions.emplace_back(x, y, z);
    return uint32_t(mesh.positions.size() - 1);
  };
  std::vector<uint32_t> top(size_t(nx) * nz);
  for (int j = 0; j < nz; ++j)
    for (int i = 0; i < nx; ++i) {
      const float x = -0.5f * h.sizeX + h.sizeX * i / (nx - 1), z = -0.5f * h.sizeZ + h.sizeZ * j / (nz - 1);
      float sx, sz;
      top[size_t(j) * nx + i] = vertex(x, h.heightAt(x, z, sx, sz), z);
    }
  for (int j = 0; j + 1 < nz; ++j)
    for (int i = 0; i + 1 < nx; ++i) {
      const uint32_t a = top[size_t(j) * nx + i], b = top[size_t(j) * nx + i + 1];
      const uint32_t c = top[size_t(j + 1) * nx + i], d = top[size_t(j + 1) * nx + i + 1];
      mesh.triangles.push_back({a, c, b});  // counter-clockwise seen from above (+y)
      mesh.triangles.push_back({b, c, d});
    }
  // The rim walked counter-clockwise seen from above, its skirt down to the bottom, and the floor.
  std::vector<uint32_t> rim;
  for (int i = 0; i < nx - 1; ++i) rim.push_back(top[i]);
  for (int j = 0; j < nz - 1; ++j) rim.push_back(top[size_t(j) * nx + nx - 1]);
  for (int i = nx - 1; i > 0; --i) rim.push_back(top[size_t(nz - 1) * nx + i]);
  for (int j = nz - 1; j > 0; --j) rim.push_back(top[size_t(j) * nx]);
  std::vector<uint32_t> low;
  for (uint32_t r : rim) low.push_back(vertex(mesh.positions[r].x(), bottom, mesh.positions[r].z()));
  for (size_t k = 0; k < rim.size(); ++k) {
    const size_t next = (k + 1) % rim.size();
    mesh.triangles.push_back({rim[k], low[k], rim[next]});
    mesh.triangles.push_back({rim[next], low[k], low[next]});
  }
  const uint32_t centre = vertex(0, bottom, 0);
  for (size_t k = 0; k < low.size(); ++k) mesh.triangles.push_back({centre, low[k], low[(k + 1) % low.size()]});
  computeVertexNormals(mesh);
  return mesh;
}

TriangleMesh readMeshFile(const std::string& file, const std::string& where, const std::string& key) {
  checkReadable(file, where, key);
  std::string extension = fs::path(file).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(), ::tolower);
  TriangleMesh mesh;
  if (extension == ".ply") {
    try {
      mesh = readMeshPly(file);
    } catch (const InputError& e) {
      throw InputError(where, key, e.what());
    }
  } else if (extension == ".obj") {
    tinyobj::ObjReader reader;
    tinyobj::ObjReaderConfig config;
    config.triangulate = true;
    config.vertex_color = false;
    if (!reader.ParseFromFile(file, config)) {
      std::string message = reader.Error();
      std::replace(message.begin(), message.end(), '\n', ' ');
      throw InputError(where, key, "'" + file + "' is not a readable OBJ (" + message + ")");
    }
    const auto& vertices = reader.GetAttrib().vertices;
    for (size_t i = 0; i + 2 < vertices.size(); i += 3)
      mesh.positions.emplace_back(vertices[i], vertices[i + 1], vertices[i + 2]);
    for (const tinyobj::shape_t& shape : reader.GetShapes()) {
      const auto& indices = shape.mesh.indices;
      for (size_t f = 0; f + 2 < indices.size(); f += 3) {
        std::array<uint32_t, 3> t;
        for (int k = 0; k < 3; ++k) {
          const int index = indices[f + k].vertex_index;
          if (index < 0 || size_t(index) >= mesh.positions.size())
            throw InputError(where, key, "'" + file + "' names a vertex it does not have");
          t[k] = uint32_t(index);
        }
        mesh.triangles.push_back(t);
      }
    }
  } else {
    throw InputError(where, key, "'" + file + "' is neither .obj nor .ply");
  }
  computeVertexNormals(mesh);
  return mesh;
}

}  // namespace surge
