#include "render/renderer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/errors.h"
#include "core/parallel.h"
#include "render/camera.h"
#include "render_test_helpers.h"

namespace surge {
namespace {

using testing::boxMesh;
using testing::pixelAt;
using testing::CountingProgress;
using testing::TemporaryFolder;
using testing::unitTankScene;

double luminanceVariance(const Image& image) {
  double sum = 0, sumSquares = 0;
  const size_t n = size_t(image.width) * image.height;
  for (size_t i = 0; i < n; ++i) {
    const double l =
        0.2126 * image.rgb[3 * i] + 0.7152 * image.rgb[3 * i + 1] + 0.0722 * image.rgb[3 * i + 2];
    sum += l;
    sumSquares += l * l;
  }
  const double mean = sum / n;
  return sumSquares / n - mean * mean;
}

// The columns of the pixels that differ (by more than 24 levels in some channel, far above the few levels of
// sampling noise) between two images of the same view: where an added object and its shadow show.
std::vector<int> changedColumns(const Image& with, const Image& without) {
  std::vector<int> columns;
  for (int y = 0; y < with.height; ++y)
    for (int x = 0; x < with.width; ++x) {
      const uint8_t *a = pixelAt(with, x, y), *b = pixelAt(without, x, y);
      if (std::abs(a[0] - b[0]) > 24 || std::abs(a[1] - b[1]) > 24 || std::abs(a[2] - b[2]) > 24)
        columns.push_back(x);
    }
  return columns;
}

TEST(RendererTest, ImageHasTheSceneResolutionAndIsNotBlank) {
  const Scene scene = unitTankScene();
  const Image image = renderMesh(boxMesh({0.3f, 0.0f, 0.3f}, {0.7f, 0.5f, 0.7f}), scene, 0);
  EXPECT_EQ(image.width, 64);
  EXPECT_EQ(image.height, 48);
  ASSERT_EQ(image.rgb.size(), 64u * 48u * 3u);
  // A blank image has variance 0. The empty tank alone (sky, grey ground, thin dark edges) measures about 240
  // (grey levels squared); the blue box in front of the light floor raises it to about 1160. 600 lies
  // between, so this checks that the mesh itself shows, not only the backdrop.
  EXPECT_GT(luminanceVariance(image), 600.0);
  EXPECT_LT(luminanceVariance(renderMesh(TriangleMesh{}, scene, 0)), 600.0);
}

TEST(RendererTest, WaterColouredPixelsWhereTheMeshProjects) {
  const Scene scene = unitTankScene();
  const Image water = renderMesh(boxMesh({0.3f, 0.0f, 0.3f}, {0.7f, 0.5f, 0.7f}), scene, 0);
  const Image empty = renderMesh(TriangleMesh{}, scene, 0);
  const PinholeCamera camera(framedCamera(scene), scene.render.width, scene.render.height);
  // The centre of the box's top face; the default camera looks down on it from above, so the 3x3 pixels
  // around its projection lie inside the top face (which spans about 8x7 pixels around it).
  float px = 0, py = 0;
  ASSERT_TRUE(camera.project({0.5f, 0.5f, 0.5f}, px, py));
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      const int x = int(px) + dx, y = int(py) + dy;
      ASSERT_TRUE(x >= 0 && x < water.width && y >= 0 && y < water.height);
      const uint8_t* w = pixelAt(water, x, y);
      const uint8_t* e = pixelAt(empty, x, y);
      // Water colour (0.15, 0.45, 0.8): blue clearly above red (measured ~110 levels; in the empty tank no
      // pixel has blue more than ~10 above red)...
      EXPECT_GT(int(w[2]) - int(w[0]), 60) << "pixel " << x << "," << y;
      // ...and the box changes what is seen there by far more than sampling noise (a few levels).
      EXPECT_GT(std::abs(int(w[0]) - int(e[0])) + std::abs(int(w[2]) - int(e[2])), 60)
          << "pixel " << x << "," << y;
    }
}

TEST(RendererTest, SmoothNormalsRenderLikeFlatOnAFlatFace) {
  // A box whose every face carries its own normal as vertex normals renders exactly like the flat box: the
  // interpolated normal is the face normal, and light refracts through every face (the water is clear
  // enough to see through), so the whole image must match, not only the top face.
  const Scene scene = unitTankScene();
  const TriangleMesh flat = boxMesh({0.3f, 0.0f, 0.3f}, {0.7f, 0.5f, 0.7f});
  const TriangleMesh smooth = testing::boxMeshWithFaceNormals({0.3f, 0.0f, 0.3f}, {0.7f, 0.5f, 0.7f});
  ASSERT_EQ(smooth.normals.size(), smooth.positions.size());
  const Image a = renderMesh(flat, scene, 3), b = renderMesh(smooth, scene, 3);
  EXPECT_TRUE(a.rgb == b.rgb);
}

TEST(RendererTest, ObjectOnTheLeftAppearsInTheLeftHalf) {
  // Looking down -z from the front, world -x is image left. A box at the left side of the tank, then its
  // mirror image at the right side: every changed pixel (box and shadow; the sun casts it towards +x, but by
  // under 0.1 m for this low box) lies in the matching half. Measured: columns 20-27 and 38-45 of 64, so a
  // margin of 4-5 pixels from the centre line; a mirrored image would put each box wholly in the other half.
  const Scene scene =
      unitTankScene(R"("camera": {"position": [0.5, 0.6, 3.0], "look_at": [0.5, 0.3, 0.5], "fov": 40})");
  const int middle = scene.render.width / 2;
  const Image empty = renderMesh(TriangleMesh{}, scene, 0);
  const std::vector<int> left =
      changedColumns(renderMesh(boxMesh({0.05f, 0.0f, 0.4f}, {0.25f, 0.15f, 0.6f}), scene, 0), empty);
  ASSERT_GT(left.size(), 20u);
  EXPECT_LT(*std::max_element(left.begin(), left.end()), middle);
  const std::vector<int> right =
      changedColumns(renderMesh(boxMesh({0.75f, 0.0f, 0.4f}, {0.95f, 0.15f, 0.6f}), scene, 0), empty);
  ASSERT_GT(right.size(), 20u);
  EXPECT_GE(*std::min_element(right.begin(), right.end()), middle);
}

TEST(RendererTest, SameBytesWithOneAndTwoThreads) {
  // 4x3 tiles, partial ones; the denoiser and the edge samples' second round on.
  const Scene scene =
      unitTankScene(R"("width": 100, "height": 70, "samples": 3, "denoise": 1, "edge_samples": 7)");
  const TriangleMesh mesh = boxMesh({0.2f, 0.0f, 0.3f}, {0.6f, 0.4f, 0.8f});
  Image one, two;
  {
    const ThreadLimit limit(1);
    one = renderMesh(mesh, scene, 7);
  }
  {
    const ThreadLimit limit(2);
    two = renderMesh(mesh, scene, 7);
  }
  EXPECT_TRUE(one.rgb == two.rgb);
}

TEST(RendererTest, FrameNumberSeedsTheNoise) {
  // Jittered samples differ between frames (anti-aliased edges and soft shadows move by a level or two),
  // while the same frame repeats exactly.
  const Scene scene = unitTankScene();
  const TriangleMesh mesh = boxMesh({0.3f, 0.0f, 0.3f}, {0.7f, 0.5f, 0.7f});
  EXPECT_TRUE(renderMesh(mesh, scene, 1).rgb == renderMesh(mesh, scene, 1).rgb);
  EXPECT_FALSE(renderMesh(mesh, scene, 1).rgb == renderMesh(mesh, scene, 2).rgb);
}

TEST(RendererTest, TriangleNamingAMissingVertexIsInputError) {
  TriangleMesh mesh = boxMesh({0.3f, 0.0f, 0.3f}, {0.7f, 0.5f, 0.7f});
  mesh.triangles[5][1] = 8;
  EXPECT_THROW(renderMesh(mesh, unitTankScene(), 0), InputError);
}

TEST(RendererTest, PngDecodesToTheSameImage) {
  TemporaryFolder folder;
  const Scene scene = unitTankScene();
  const Image image = renderMesh(boxMesh({0.3f, 0.0f, 0.3f}, {0.7f, 0.5f, 0.7f}), scene, 0);
  const fs::path path = folder.path() / "deep" / "frame.png";
  writePng(path, image);
  const Image decoded = readPng(path);  // stb_image
  EXPECT_EQ(decoded.width, scene.render.width);
  EXPECT_EQ(decoded.height, scene.render.height);
  EXPECT_TRUE(decoded.rgb == image.rgb);  // PNG is lossless
  EXPECT_EQ(std::distance(fs::directory_iterator(path.parent_path()), fs::directory_iterator()),
            1);  // no temp
}

TEST(RendererTest, PngWriteFailureIsRunError) {
  TemporaryFolder folder;
  Image image;
  image.width = 2;
  image.height = 2;
  image.rgb.assign(12, 128);
  writePng(folder.path() / "file", image);
  EXPECT_THROW(writePng(folder.path() / "file" / "below.png", image), RunError);  // a file is not a folder
  image.rgb.pop_back();
  EXPECT_THROW(writePng(folder.path() / "short.png", image), RunError);
}

TEST(RendererTest, RenderFramesWritesThePngsInRange) {
  TemporaryFolder folder;
  const Scene scene = unitTankScene(R"("samples": 1)");
  const TriangleMesh mesh = boxMesh({0.3f, 0.0f, 0.3f}, {0.7f, 0.5f, 0.7f});
  for (int frame : {0, 1, 2, 5}) writeMeshPly(framePath(folder.path(), "surface", frame, "ply"), mesh);
  CountingProgress progress;
  renderFrames(folder.path(), scene, FrameRange::parse("1:5"), progress);
  EXPECT_EQ(listFrames(folder.path(), "frames", "png"), (std::vector<int>{1, 2, 5}));
  EXPECT_EQ(progress.label, "render");
  EXPECT_EQ(progress.total, 3u);
  EXPECT_EQ(progress.done, 3u);
  EXPECT_TRUE(progress.finished);
  const Image frame5 = readPng(framePath(folder.path(), "frames", 5, "png"));
  EXPECT_TRUE(frame5.rgb == renderMesh(mesh, scene, 5).rgb);
}

TEST(RendererTest, RenderFramesWithoutSurfacesIsInputError) {
  TemporaryFolder folder;
  CountingProgress progress;
  try {
    renderFrames(folder.path(), unitTankScene(), FrameRange{}, progress);
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_EQ(error.exitStatus(), kExitBadInput);
    EXPECT_NE(std::string(error.what()).find(folder.path().string()), std::string::npos) << error.what();
  }
  writeMeshPly(framePath(folder.path(), "surface", 3, "ply"), TriangleMesh{});
  EXPECT_THROW(renderFrames(folder.path(), unitTankScene(), FrameRange::parse("4:"), progress), InputError);
}

TEST(RendererTest, InterruptStopsBeforeWritingAFrame) {
  TemporaryFolder folder;
  writeMeshPly(framePath(folder.path(), "surface", 0, "ply"), TriangleMesh{});
  CountingProgress progress;
  Progress::setInterrupted(true);
  EXPECT_THROW(renderFrames(folder.path(), unitTankScene(), FrameRange{}, progress), Interrupted);
  EXPECT_THROW(renderMesh(TriangleMesh{}, unitTankScene(), 0), Interrupted);
  Progress::setInterrupted(false);
  EXPECT_TRUE(listFrames(folder.path(), "frames", "png").empty());
}

}  // namespace
}  // namespace surge
