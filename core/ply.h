// PLY files, the format of Surge's particle frames and meshes: written binary little-endian, read in ASCII or
// binary of either byte order.
// Particle frames (DESIGN.md): one `vertex` element with float x y z vx vy vz and uint id; a frame holds
// everything needed to continue a simulation from it. Meshes: vertex x y z nx ny nz and a `face` element with a
// `vertex_indices` list, as Blender and Houdini read them. Writes are atomic (see writeFileAtomically).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/files.h"
#include "core/mesh.h"

namespace surge {

struct ParticleFrame {
  int dimensions = 3;
  std::vector<Eigen::Vector3f> position;
  std::vector<Eigen::Vector3f> velocity;
  std::vector<uint32_t> id;  // stable particle identity, kept across reordering
  // Each particle's fluid (Scene::fluidOf) in a scene of several fluids; empty in a scene of one.
  std::vector<uint8_t> fluid;

  size_t size() const { return position.size(); }
  void resize(size_t n) {
    position.resize(n);
    velocity.resize(n);
    id.resize(n);
    if (!fluid.empty()) fluid.resize(n);
  }
};

void writeParticlePly(const fs::path& path, const ParticleFrame& frame);
// Throws InputError naming the file and the header line or property at fault.
ParticleFrame readParticlePly(const fs::path& path);

struct Scene;
// domain.periodic: the frame with the particles within `reach` of a periodic face copied a period over, after
// its own (the surfacer's level set and the whitewater's neighbours run on across the seam with them).
ParticleFrame withPeriodicImages(const ParticleFrame& frame, const Scene& scene, double reach);

// A whitewater frame (whitewater/frame_NNNNN.ply): the diffuse particles as x y z vx vy vz id type lifetime,
// and the next id to give in a comment, so that the stage continues from a frame as from memory.
enum DiffuseType : uint8_t { kSpray = 0, kFoam = 1, kBubble = 2 };
struct DiffuseFrame {
  int dimensions = 3;
  uint32_t nextId = 0;
  std::vector<Eigen::Vector3f> position;
  std::vector<Eigen::Vector3f> velocity;
  std::vector<uint32_t> id;
  std::vector<uint8_t> type;   // DiffuseType
  std::vector<float> lifetime;  // seconds left

  size_t size() const { return position.size(); }
  void resize(size_t n) {
    position.resize(n);
    velocity.resize(n);
    id.resize(n);
    type.resize(n);
    lifetime.resize(n);
  }
};

void writeDiffusePly(const fs::path& path, const DiffuseFrame& frame);
DiffuseFrame readDiffusePly(const fs::path& path);
// The later stages draw whatever whitewater/ holds: false, and `frame` untouched, where the file is absent.
bool readDiffusePlyIfPresent(const fs::path& path, DiffuseFrame& frame);

// Every scalar property of a PLY's `vertex` element in the file's order, its PLY type and its values, whatever
// their names: for the exporters (surge export), which pass on every channel a frame holds.
struct PlyColumn {
  std::string name, type;  // type as the header spells it: float, uint, uchar...
  std::vector<double> values;
};
std::vector<PlyColumn> readVertexColumns(const fs::path& path);

void writeMeshPly(const fs::path& path, const TriangleMesh& mesh);
TriangleMesh readMeshPly(const fs::path& path);

}  // namespace surge
