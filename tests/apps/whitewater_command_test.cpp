// surge run with whitewater, end to end: the frames' diffuse particles reach the surface VDB as a PointDataGrid
// `whitewater` with their attributes, and the path tracer draws them.
#include <gtest/gtest.h>
#include <stb/stb_image.h>

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/points/PointCount.h>
#include <openvdb/points/PointDataGrid.h>

#include "core/files.h"
#include "core/ply.h"
#include "tests/apps/run_surge.h"

namespace surge {
namespace {

const char* kSplash = R"({
  "name": "splash", "dimensions": 3,
  "domain": {"min": [0, 0, 0], "max": [0.8, 0.5, 0.2]}, "particle_spacing": 0.02,
  "fluids": [{"box": {"min": [0, 0, 0], "max": [0.25, 0.35, 0.2]}}],
  "output": {"fps": 30, "frames": 24}, "whitewater": {"enabled": 1},
  "render": {"width": 192, "height": 108, "samples": 1, "edge_samples": 1, "tank": "none"}
})";

std::vector<unsigned char> pixelsOf(const fs::path& png, int& width, int& height) {
  int channels = 0;
  unsigned char* data = stbi_load(png.c_str(), &width, &height, &channels, 3);
  std::vector<unsigned char> out(data, data + (data ? size_t(width) * height * 3 : 0));
  stbi_image_free(data);
  return out;
}

TEST(WhitewaterCommand, TheFramesReachTheVdbAndThePicture) {
  const fs::path scene = writeTestScene("splash.json", kSplash);
  const fs::path out = freshFolder("surge_whitewater_run");
  const SurgeResult run = runSurge("run '" + scene.string() + "' --quiet --out '" + out.string() + "'");
  ASSERT_EQ(run.status, 0) << run.err;
  ASSERT_TRUE(fs::exists(out / "whitewater" / "counts.csv"));
  // The frame with the most whitewater.
  int busiest = 0;
  size_t most = 0;
  for (int f : listFrames(out, "whitewater", "ply")) {
    const size_t n = readDiffusePly(framePath(out, "whitewater", f, "ply")).size();
    if (n > most) most = n, busiest = f;
  }
  ASSERT_GT(most, 20u) << "the splash made almost no whitewater";
  const DiffuseFrame diffuse = readDiffusePly(framePath(out, "whitewater", busiest, "ply"));

  openvdb::initialize();
  openvdb::io::File file(framePath(out, "surface", busiest, "vdb").string());
  file.open();
  ASSERT_TRUE(file.hasGrid("whitewater"));
  const auto grid = openvdb::gridPtrCast<openvdb::points::PointDataGrid>(file.readGrid("whitewater"));
  ASSERT_TRUE(grid);
  EXPECT_EQ(openvdb::points::pointCount(grid->tree()), diffuse.size());
  const auto leaf = grid->tree().cbeginLeaf();
  ASSERT_TRUE(leaf);
  for (const char* attribute : {"P", "v", "id", "type", "lifetime"})
    EXPECT_NE(leaf->attributeSet().descriptor().find(attribute), openvdb::points::AttributeSet::INVALID_POS)
        << attribute;
  EXPECT_TRUE(file.hasGrid("surface"));
  file.close();

  // The same frame rendered without its whitewater: the pixels that change are the particles, and brighter.
  const fs::path bare = freshFolder("surge_whitewater_bare");
  fs::copy(out, bare, fs::copy_options::recursive);
  fs::remove_all(bare / "whitewater");
  const std::string frames = std::to_string(busiest) + ":" + std::to_string(busiest);
  ASSERT_EQ(runSurge("render '" + bare.string() + "' --quiet --frames " + frames).status, 0);
  int w1 = 0, h1 = 0, w2 = 0, h2 = 0;
  const auto with = pixelsOf(framePath(out, "frames", busiest, "png"), w1, h1);
  const auto without = pixelsOf(framePath(bare, "frames", busiest, "png"), w2, h2);
  ASSERT_EQ(with.size(), without.size());
  ASSERT_FALSE(with.empty());
  int changed = 0;
  double brighter = 0;
  for (size_t p = 0; p + 2 < with.size(); p += 3) {
    const int a = with[p] + with[p + 1] + with[p + 2], b = without[p] + without[p + 1] + without[p + 2];
    if (std::abs(a - b) > 90) ++changed, brighter += a - b;
  }
  EXPECT_GT(changed, 10) << "the whitewater is not in the picture";
  EXPECT_GT(brighter, 0) << "the whitewater darkened the picture";
}

}  // namespace
}  // namespace surge
