#include "core/ply.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <fstream>
#include <limits>

#include "core/errors.h"

namespace surge {
namespace {

// A folder of the running test's own: ctest runs the tests of this file side by side, and one lists its folder.
fs::path tempPath(const std::string& name) {
  const fs::path dir = fs::path(testing::TempDir()) /
                       ("surge_ply_test_" + std::string(testing::UnitTest::GetInstance()->current_test_info()->name()));
  fs::create_directories(dir);
  return dir / name;
}

TEST(Ply, ParticleFrameRoundTripsBitForBit) {
  ParticleFrame frame;
  frame.dimensions = 2;
  frame.resize(3);
  for (int i = 0; i < 3; ++i) {
    frame.position[i] = Eigen::Vector3f(0.1f * i + 1e-7f, -2.5f / (i + 1), 0);
    frame.velocity[i] = Eigen::Vector3f(3.0f / 7.0f, float(i), 0);
    frame.id[i] = 100 + i;
  }
  const fs::path path = tempPath("particles.ply");
  for (const auto& entry : fs::directory_iterator(path.parent_path())) fs::remove_all(entry.path());
  writeParticlePly(path, frame);
  const ParticleFrame back = readParticlePly(path);
  EXPECT_EQ(back.dimensions, 2);
  ASSERT_EQ(back.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(back.position[i], frame.position[i]);  // exact: resume depends on it
    EXPECT_EQ(back.velocity[i], frame.velocity[i]);
    EXPECT_EQ(back.id[i], frame.id[i]);
  }
  // Header, then 28 bytes a particle (six floats and an id).
  const std::string header = "ply\nformat binary_little_endian 1.0\n";
  std::ifstream in(path, std::ios::binary);
  std::string start(header.size(), '\0');
  in.read(start.data(), static_cast<std::streamsize>(start.size()));
  EXPECT_EQ(start, header);
  const std::string bytes = readTextFile(path);
  const size_t body = bytes.find("end_header\n");
  ASSERT_NE(body, std::string::npos);
  EXPECT_EQ(bytes.size() - (body + std::string("end_header\n").size()), 3u * 28u);
  // The temporary file the write went through (its name carries the process id) is gone: the folder holds the
  // frame alone.
  for (const auto& entry : fs::directory_iterator(path.parent_path()))
    EXPECT_EQ(entry.path().filename().string().rfind("particles.ply.tmp", 0), std::string::npos) << entry.path();
}

// The exporters pass on every property of a frame: each column in the file's order, with its type.
TEST(Ply, VertexColumnsAreEveryPropertyInOrder) {
  ParticleFrame frame;
  frame.resize(2);
  frame.fluid = {0, 3};
  frame.position = {Eigen::Vector3f(0.25f, 1e-7f, -3), Eigen::Vector3f(1, 2, 3)};
  frame.velocity = {Eigen::Vector3f(0.5f, 0, 0), Eigen::Vector3f(0, -9.81f, 0)};
  frame.id = {7, 4000000000u};
  const fs::path path = tempPath("columns.ply");
  writeParticlePly(path, frame);
  const std::vector<PlyColumn> columns = readVertexColumns(path);
  ASSERT_EQ(columns.size(), 8u);
  const char* names[8] = {"x", "y", "z", "vx", "vy", "vz", "id", "fluid"};
  for (size_t c = 0; c < 8; ++c) EXPECT_EQ(columns[c].name, names[c]);
  EXPECT_EQ(columns[0].type, "float");
  EXPECT_EQ(columns[6].type, "uint");
  EXPECT_EQ(columns[7].type, "uchar");
  EXPECT_EQ(float(columns[1].values[0]), 1e-7f);
  EXPECT_EQ(float(columns[4].values[1]), -9.81f);
  EXPECT_EQ(columns[6].values[1], 4000000000.0);
  EXPECT_EQ(columns[7].values[1], 3.0);
}

TEST(Ply, MeshRoundTrips) {
  TriangleMesh mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  mesh.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {1, 0, 0}};
  mesh.triangles = {{0, 1, 2}, {0, 3, 1}};
  const fs::path path = tempPath("mesh.ply");
  writeMeshPly(path, mesh);
  const TriangleMesh back = readMeshPly(path);
  EXPECT_EQ(back.positions, mesh.positions);
  EXPECT_EQ(back.normals, mesh.normals);
  EXPECT_EQ(back.triangles, mesh.triangles);
}

TEST(Ply, EmptyFramesAndMeshesAreValid) {
  const fs::path path = tempPath("empty.ply");
  writeParticlePly(path, ParticleFrame{});
  EXPECT_EQ(readParticlePly(path).size(), 0u);
  writeMeshPly(path, TriangleMesh{});
  EXPECT_TRUE(readMeshPly(path).triangles.empty());
}

TEST(Ply, BadFilesNameFileAndPlace) {
  const fs::path path = tempPath("bad.ply");
  { std::ofstream(path) << "not a ply\n"; }
  try {
    readParticlePly(path);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.ply: line 1: not a PLY file"), std::string::npos) << e.what();
  }
  ParticleFrame frame;
  frame.resize(10);
  writeParticlePly(path, frame);
  fs::resize_file(path, fs::file_size(path) - 5);  // cut the last record
  try {
    readParticlePly(path);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("element vertex: file ends before its 10 records"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(readParticlePly(tempPath("missing.ply")), InputError);

  // A diverged or hand-made frame with a non-finite value names the particle and the field.
  for (size_t i = 0; i < frame.size(); ++i) frame.position[i] = frame.velocity[i] = Eigen::Vector3f::Zero();
  frame.velocity[7].y() = std::numeric_limits<float>::infinity();
  writeParticlePly(path, frame);
  try {
    readParticlePly(path);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.ply: vertex 7 vy: not a finite number"), std::string::npos)
        << e.what();
  }
}

// A mesh as ASCII and as big-endian PLY (as users bring them: Blender and MeshLab write either, the Stanford
// models are ASCII) reads as the same mesh as the little-endian file Surge writes: positions to the digits
// written, faces as quads and triangles alike, extra properties passed over. A word that is not a number of its
// property's type is refused, naming the record.
TEST(Ply, AsciiAndBigEndianMeshesReadAsTheSameMesh) {
  const fs::path path = tempPath("formats.ply");
  const std::string header = "element vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                             "property uchar red\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n";
  { std::ofstream(path) << "ply\nformat ascii 1.0\ncomment by hand\n" << header
                         << "0 0 0 255\n1 0 0 255\n1 1 0 255\n0.5 1.5 -2.25 7\n4 0 1 2 3\n3 2 3 0\n"; }
  const TriangleMesh ascii = readMeshPly(path);
  const std::vector<Eigen::Vector3f> positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0.5f, 1.5f, -2.25f}};
  const std::vector<std::array<uint32_t, 3>> triangles = {{0, 1, 2}, {0, 2, 3}, {2, 3, 0}};
  EXPECT_EQ(ascii.positions, positions);
  EXPECT_EQ(ascii.triangles, triangles);
  {
    std::ofstream out(path, std::ios::binary);
    out << "ply\nformat binary_big_endian 1.0\n" << header;
    auto big = [&](auto value) {
      char bytes[sizeof value];
      std::memcpy(bytes, &value, sizeof value);
      std::reverse(bytes, bytes + sizeof value);
      out.write(bytes, sizeof value);
    };
    for (const Eigen::Vector3f& p : positions) {
      for (int k = 0; k < 3; ++k) big(p[k]);
      big(uint8_t(255));
    }
    big(uint8_t(4));
    for (int32_t i : {0, 1, 2, 3}) big(i);
    big(uint8_t(3));
    for (int32_t i : {2, 3, 0}) big(i);
  }
  const TriangleMesh bigEndian = readMeshPly(path);
  EXPECT_EQ(bigEndian.positions, positions);
  EXPECT_EQ(bigEndian.triangles, triangles);
  for (const char* body : {"0 0 0 255\n1 0 0 255\n1 1 zero 255\n", "0 0 0 255\n1 0 0 256\n"}) {
    { std::ofstream(path) << "ply\nformat ascii 1.0\n" << header << body; }
    try {
      readMeshPly(path);
      ADD_FAILURE() << "accepted " << body;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("holds a word that is not a number of its type"), std::string::npos)
          << e.what();
    }
  }
}

// Counts the file cannot hold are refused before anything is allocated for them (found by fuzz/fuzz_mesh_ply:
// a float list length of -9.5e8 was converted to an index, undefined behaviour).
TEST(Ply, CountsTheFileCannotHoldAreRefused) {
  const fs::path path = tempPath("counts.ply");
  const std::string header = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
                             "property float y\nproperty float z\nelement face 1\n";
  const std::string vertices(36, '\0');
  auto expectRefused = [&](const std::string& bytes, const std::string& words) {
    { std::ofstream(path, std::ios::binary) << bytes; }
    try {
      readMeshPly(path);
      ADD_FAILURE() << "accepted: " << words;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  const float negative = -9.5e8f, half = 2.5f;
  std::string list(reinterpret_cast<const char*>(&negative), 4);
  expectRefused(header + "property list float int vertex_indices\nend_header\n" + vertices + list,
                "record 0 has a list length that is not a count the file holds");
  list.assign(reinterpret_cast<const char*>(&half), 4);
  expectRefused(header + "property list float int vertex_indices\nend_header\n" + vertices + list,
                "record 0 has a list length");
  const int huge = 1 << 30;
  list.assign(reinterpret_cast<const char*>(&huge), 4);
  expectRefused(header + "property list int int vertex_indices\nend_header\n" + vertices + list,
                "record 0 has a list length");
  // A trillion vertices claimed by a file of a hundred bytes: refused, not a bad_alloc.
  expectRefused("ply\nformat binary_little_endian 1.0\nelement vertex 1000000000000\nproperty float x\n"
                "end_header\n" + vertices,
                "element vertex: file ends before its 1000000000000 records");
}

}  // namespace
}  // namespace surge
