// The surfacer on a frame of several fluids (issue 34): one level set a fluid, `surface` for the first and
// `surface_<name>` for the others, in the frame's VDB, and each fluid's mesh (surface_<name>/ beside surface/).
#include <gtest/gtest.h>
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

#include <algorithm>

#include "core/files.h"
#include "core/ply.h"
#include "core/progress.h"
#include "core/scene.h"
#include "surface/surfacer.h"

namespace surge {
namespace {

// The x extent of a mesh's vertices.
std::pair<float, float> xExtent(const TriangleMesh& mesh) {
  float lo = INFINITY, hi = -INFINITY;
  for (const auto& p : mesh.positions) {
    lo = std::min(lo, p.x());
    hi = std::max(hi, p.x());
  }
  return {lo, hi};
}

// Water in x [0, 0.2] and oil in x [0.4, 0.6]: each mesh covers its own block (within the surface's reach of a
// spacing beyond the particles' centres) and not the other's.
TEST(SeveralFluidsSurface, EachFluidHasItsLevelSetAndMesh) {
  const Scene scene = parseScene(R"({"name": "two", "dimensions": 3,
    "domain": {"min": [0, 0, 0], "max": [0.6, 0.4, 0.2]}, "particle_spacing": 0.02,
    "fluids": [{"box": {"min": [0, 0, 0], "max": [0.2, 0.2, 0.2]}},
               {"name": "oil", "rest_density": 900, "box": {"min": [0.4, 0, 0], "max": [0.6, 0.2, 0.2]}}]})",
                                 "test");
  ParticleFrame frame;
  for (int block = 0; block < 2; ++block)
    for (int k = 0; k < 10; ++k)
      for (int j = 0; j < 10; ++j)
        for (int i = 0; i < 10; ++i) {
          frame.position.emplace_back(0.4f * block + 0.02f * (i + 0.5f), 0.02f * (j + 0.5f), 0.02f * (k + 0.5f));
          frame.velocity.emplace_back(0, 0, 0);
          frame.id.push_back(uint32_t(frame.id.size()));
          frame.fluid.push_back(uint8_t(block));
        }
  const fs::path dir = fs::path(testing::TempDir()) / "several_fluids_surface";
  fs::remove_all(dir);
  writeParticlePly(framePath(dir, "particles", 0, "ply"), frame);
  Progress silent;
  surfaceFrames(dir, scene, FrameRange{}, silent);

  openvdb::initialize();
  openvdb::io::File file(framePath(dir, "surface", 0, "vdb").string());
  file.open();
  std::vector<std::string> names;
  for (auto name = file.beginName(); name != file.endName(); ++name) names.push_back(name.gridName());
  file.close();
  EXPECT_EQ(names, (std::vector<std::string>{"surface", "surface_oil"}));

  const TriangleMesh water = readMeshPly(framePath(dir, "surface", 0, "ply"));
  const TriangleMesh oil = readMeshPly(fluidMeshPath(framePath(dir, "surface", 0, "ply"), "oil"));
  ASSERT_FALSE(water.triangles.empty());
  ASSERT_FALSE(oil.triangles.empty());
  const auto [waterLo, waterHi] = xExtent(water);
  const auto [oilLo, oilHi] = xExtent(oil);
  EXPECT_GT(waterLo, -0.02f);
  EXPECT_LT(waterHi, 0.2f + 0.02f);
  EXPECT_GT(oilLo, 0.4f - 0.02f);
  EXPECT_LT(oilHi, 0.6f + 0.02f);
}

}  // namespace
}  // namespace surge
