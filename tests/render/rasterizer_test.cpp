// The OSMesa quick-look renderer (headless: no display is opened) and the contact sheet.
#include "render/rasterizer.h"

#include <gtest/gtest.h>

#include "core/errors.h"
#include "render/camera.h"
#include "render/contact_sheet.h"
#include "render/renderer.h"
#include "render_test_helpers.h"

namespace surge {
namespace {

using testing::boxMesh;
using testing::pixelAt;
using testing::CountingProgress;
using testing::TemporaryFolder;
using testing::unitTankScene;

TEST(RasterizerTest, DrawsTheWaterWhereTheMeshProjects) {
  const Scene scene = unitTankScene();
  Rasterizer rasterizer(scene);  // OSMesa: works without X
  const Image water = rasterizer.drawMesh(boxMesh({0.3f, 0.0f, 0.3f}, {0.7f, 0.5f, 0.7f}));
  const Image empty = rasterizer.drawMesh(TriangleMesh{});
  ASSERT_EQ(water.width, 64);
  ASSERT_EQ(water.height, 48);
  ASSERT_EQ(water.rgb.size(), 64u * 48u * 3u);
  const PinholeCamera camera(framedCamera(scene), 64, 48);
  float px = 0, py = 0;
  ASSERT_TRUE(camera.project({0.5f, 0.5f, 0.5f}, px, py));
  const uint8_t *w = pixelAt(water, int(px), int(py)), *e = pixelAt(empty, int(px), int(py));
  // Water colour (0.15, 0.45, 0.8) as body colour: blue well above red; the bare floor there is grey (red and
  // blue within a few levels). 40 levels is far above the grey's tint and far below the water's.
  EXPECT_GT(int(w[2]) - int(w[0]), 40);
  EXPECT_LT(std::abs(int(e[2]) - int(e[0])), 15);
  // The sky at the top of the image is lighter than the ground at the bottom corner... and not black.
  EXPECT_GT(pixelAt(empty, 32, 0)[2], 100);
}

TEST(RasterizerTest, LeftStaysLeft) {
  const Scene scene =
      unitTankScene(R"("camera": {"position": [0.5, 0.6, 3.0], "look_at": [0.5, 0.3, 0.5], "fov": 40})");
  Rasterizer rasterizer(scene);
  const Image image = rasterizer.drawMesh(boxMesh({0.05f, 0.0f, 0.4f}, {0.25f, 0.15f, 0.6f}));
  const Image empty = rasterizer.drawMesh(TriangleMesh{});
  int leftChanged = 0, rightChanged = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      if (std::abs(pixelAt(image, x, y)[2] - pixelAt(empty, x, y)[2]) > 24)
        ++(x < 32 ? leftChanged : rightChanged);
  EXPECT_GT(leftChanged, 20);
  EXPECT_EQ(rightChanged, 0);
}

TEST(RasterizerTest, ParticlesAndTwoDimensionalScenes) {
  const Scene scene = parseScene(R"({
    "name": "flat", "dimensions": 2,
    "domain": {"min": [0, 0], "max": [2, 1]},
    "particle_spacing": 0.05,
    "fluids": [{"box": {"min": [0, 0], "max": [0.5, 0.5]}}],
    "render": {"width": 80, "height": 40}
  })",
                                 "test");
  ParticleFrame particles;
  particles.dimensions = 2;
  particles.resize(1);
  particles.position[0] = Eigen::Vector3f(0.5f, 0.5f, 0.0f);  // left of the middle, at mid height
  Rasterizer rasterizer(scene);
  const Image image = rasterizer.drawParticles(particles);
  ASSERT_EQ(image.width, 80);
  ASSERT_EQ(image.height, 40);
  // Orthographic, face on: the tank [0, 2] x [0, 1] fills 92 % of the width (margin 4 % a side), so x = 0.5
  // lands at 80 x (0.04 + 0.92 x 0.25) = 21.6 and y = 0.5 at the middle row. A sphere of radius 0.025 spans a
  // pixel there: the pixel is water-blue, the tank beside it a light grey.
  const uint8_t* p = pixelAt(image, 21, 20);
  const uint8_t* beside = pixelAt(image, 40, 20);
  EXPECT_GT(int(p[2]) - int(p[0]), 40);
  EXPECT_LT(std::abs(int(beside[2]) - int(beside[0])), 10);
  // A 2D surface mesh (the surfacer extrudes it into a slab along z) is drawn face on the same way: a slab
  // over x in [0.4, 0.6] covers the column at 80 x (0.04 + 0.92 x 0.25) = 21.6 from the floor to y = 0.5.
  const Image slab = rasterizer.drawMesh(boxMesh({0.4f, 0.0f, -0.1f}, {0.6f, 0.5f, 0.1f}));
  const uint8_t* inSlab = pixelAt(slab, 21, 30);
  EXPECT_GT(int(inSlab[2]) - int(inSlab[0]), 40);
  EXPECT_LT(std::abs(int(pixelAt(slab, 21, 5)[2]) - int(pixelAt(slab, 21, 5)[0])), 10);  // above the water
}

TEST(RasterizerTest, RenderFramesFallsBackToParticlesWithoutSurfaces) {
  TemporaryFolder folder;
  ParticleFrame particles;
  particles.resize(2);
  particles.position[0] = Eigen::Vector3f(0.4f, 0.1f, 0.5f);
  particles.position[1] = Eigen::Vector3f(0.6f, 0.1f, 0.5f);
  for (int frame : {0, 1}) writeParticlePly(framePath(folder.path(), "particles", frame, "ply"), particles);
  CountingProgress progress;
  RenderOptions options;
  options.renderer = "gl";
  renderFrames(folder.path(), unitTankScene(), FrameRange{}, progress, options);
  EXPECT_EQ(listFrames(folder.path(), "frames", "png"), (std::vector<int>{0, 1}));
  EXPECT_EQ(readPng(framePath(folder.path(), "frames", 1, "png")).width, 64);
  options.renderer = "vulkan";
  EXPECT_THROW(renderFrames(folder.path(), unitTankScene(), FrameRange{}, progress, options), InputError);
}

TEST(ContactSheetTest, PicksEvenlySpacedFramesAndLaysThemOut) {
  EXPECT_EQ(contactSheetFrames({0, 1, 2, 3, 4, 5, 6, 7, 8}, 3), (std::vector<int>{0, 4, 8}));
  EXPECT_EQ(contactSheetFrames({3, 4}, 12), (std::vector<int>{3, 4}));
  TemporaryFolder folder;
  for (int frame = 0; frame < 6; ++frame) {
    Image image;
    image.width = 40;
    image.height = 20;
    image.rgb.assign(40 * 20 * 3, uint8_t(40 * frame));
    writePng(framePath(folder.path(), "frames", frame, "png"), image);
  }
  const fs::path path = makeContactSheet(folder.path(), unitTankScene(), 6);
  const Image sheet = readPng(path);
  // Four columns of cells 40 wide (at least 160 asked, at most the frame's width), two rows of 20: plus
  // 4-pixel gutters, 4 x 40 + 5 x 4 by 2 x 20 + 3 x 4.
  EXPECT_EQ(sheet.width, 180);
  EXPECT_EQ(sheet.height, 52);
  EXPECT_EQ(pixelAt(sheet, 4 + 44 + 10, 4 + 10)[0], 40);        // frame 1, first row
  EXPECT_EQ(pixelAt(sheet, 4 + 44 + 10, 4 + 24 + 10)[0], 200);  // frame 5, second row
}

}  // namespace
}  // namespace surge
