// The surfacer on a periodic domain (issue 35): the surface runs through the seam as the fluid does. A drop six
// layers thick along x straddles the seam, one layer on the x = 0 side and five on the x = L side; its two pieces
// of mesh must end on the domain's faces with the same cross-section there, as one drop cut in two would.
#include <gtest/gtest.h>

#include <algorithm>

#include "core/files.h"
#include "core/ply.h"
#include "core/progress.h"
#include "core/scene.h"
#include "surface/surfacer.h"

namespace surge {
namespace {

// The y and z extents of the mesh's vertices within `band` of the plane x = at.
struct Section {
  float yLo = INFINITY, yHi = -INFINITY, zLo = INFINITY, zHi = -INFINITY;
  int vertices = 0;
};
Section sectionAt(const TriangleMesh& mesh, float at, float band) {
  Section s;
  for (const auto& p : mesh.positions) {
    if (std::abs(p.x() - at) > band) continue;
    s.yLo = std::min(s.yLo, p.y());
    s.yHi = std::max(s.yHi, p.y());
    s.zLo = std::min(s.zLo, p.z());
    s.zHi = std::max(s.zHi, p.z());
    ++s.vertices;
  }
  return s;
}

// Both pieces end on the faces (every vertex in [0, L] along x: the level set is cut there; without the cut the
// drop's images reach 0.1 beyond each face) and their sections on the two faces, the vertices on each face's
// plane, are the same to a thousandth of a voxel. Measured: both sections y and z 0.155 to 0.245, a voxel inside
// the drop's flat sides at 0.140 (the mesher's chamfer where a side meets the cut, the same on both faces). The
// images themselves move this box-shaped drop's mesh by under a voxel (without them the sections are the same),
// so what this test holds is the cut and the match, not the images.
TEST(PeriodicSurface, ADropAcrossTheSeamMeetsItselfThere) {
  const double L = 0.4, s = 0.02;
  const Scene scene = parseScene(R"({"name": "seam", "dimensions": 3,
    "domain": {"min": [0, 0, 0], "max": [0.4, 0.4, 0.4], "periodic": ["x"]}, "particle_spacing": 0.02,
    "fluids": [{"box": {"min": [0, 0, 0], "max": [0.02, 0.02, 0.02]}}], "gravity": [0, 0, 0]})",
                                 "test");
  ParticleFrame frame;
  for (int i = -5; i <= 0; ++i)
    for (int j = 0; j < 6; ++j)
      for (int k = 0; k < 6; ++k) {
        const double x = std::fmod((i + 0.5) * s + L, L);
        frame.position.emplace_back(float(x), float(0.14 + (j + 0.5) * s), float(0.14 + (k + 0.5) * s));
        frame.velocity.emplace_back(0, 0, 0);
        frame.id.push_back(uint32_t(frame.id.size()));
      }
  const fs::path dir = fs::path(testing::TempDir()) / "periodic_surface";
  fs::remove_all(dir);
  writeParticlePly(framePath(dir, "particles", 0, "ply"), frame);
  Progress silent;
  surfaceFrames(dir, scene, FrameRange{}, silent);
  const TriangleMesh mesh = readMeshPly(framePath(dir, "surface", 0, "ply"));
  ASSERT_FALSE(mesh.triangles.empty());

  const float voxel = float(scene.surface.voxel_size);
  float lo = INFINITY, hi = -INFINITY;
  for (const auto& p : mesh.positions) {
    lo = std::min(lo, p.x());
    hi = std::max(hi, p.x());
  }
  EXPECT_GE(lo, -1e-3f * voxel);
  EXPECT_LE(hi, float(L) + 1e-3f * voxel);
  const float onFace = 1e-3f * voxel;
  const Section low = sectionAt(mesh, 0, onFace), high = sectionAt(mesh, float(L), onFace);
  std::printf("voxel %.4f; section at x = 0: y %.4f to %.4f, z %.4f to %.4f (%d vertices); at x = L: y %.4f to "
              "%.4f, z %.4f to %.4f (%d vertices)\n",
              voxel, low.yLo, low.yHi, low.zLo, low.zHi, low.vertices, high.yLo, high.yHi, high.zLo, high.zHi,
              high.vertices);
  ASSERT_GT(low.vertices, 0);
  ASSERT_GT(high.vertices, 0);
  EXPECT_EQ(low.vertices, high.vertices);
  EXPECT_NEAR(low.yLo, high.yLo, onFace);
  EXPECT_NEAR(low.yHi, high.yHi, onFace);
  EXPECT_NEAR(low.zLo, high.zLo, onFace);
  EXPECT_NEAR(low.zHi, high.zHi, onFace);
}

}  // namespace
}  // namespace surge
