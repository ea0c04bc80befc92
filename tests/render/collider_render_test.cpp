// The colliders in both renderers, read from an output folder written here by hand as `surge sim` leaves it:
// scene.json, surface/frame_NNNNN.ply and colliders/<name>.ply (plus colliders/<name>/frame_NNNNN.ply for a
// moving one).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "core/errors.h"
#include "core/parallel.h"
#include "render/camera.h"
#include "render/colliders.h"
#include "render/rasterizer.h"
#include "render/renderer.h"
#include "render_test_helpers.h"

namespace surge {
namespace {

using Eigen::Vector3f;
using testing::boxMeshWithFaceNormals;
using testing::CountingProgress;
using testing::pixelAt;
using testing::TemporaryFolder;

// The unit tank of the other render tests with `colliders` (a JSON array) and 64x48 images.
std::string tankJson(const std::string& colliders, const std::string& renderExtra = "") {
  return R"({"name": "colliders", "dimensions": 3, "domain": {"min": [0, 0, 0], "max": [1, 1, 1]},
    "particle_spacing": 0.05, "fluids": [{"box": {"min": [0, 0, 0], "max": [0.5, 0.5, 0.5]}}],
    "colliders": )" +
         colliders + R"(, "render": {"width": 64, "height": 48)" +
         (renderExtra.empty() ? "" : ", " + renderExtra) + "}}";
}

// An output folder as the simulation and the surfacer leave it: scene.json (resolved, through sceneToJson)
// and the water mesh as surface/frame_NNNNN.ply for each of `frames`. Returns the scene read back from
// scene.json, as `surge render` reads it.
Scene writeOutputFolder(const fs::path& dir, const std::string& json, const std::vector<int>& frames,
                        const TriangleMesh& water = {}) {
  const Scene scene = parseScene(json, "test");
  writeFileAtomically(dir / "scene.json", [&](std::ostream& out) { out << sceneToJson(scene); });
  for (int frame : frames) writeMeshPly(framePath(dir, "surface", frame, "ply"), water);
  return loadScene(dir / "scene.json");
}

void writeCollider(const fs::path& dir, const std::string& name, const TriangleMesh& mesh) {
  writeMeshPly(dir / "colliders" / (name + ".ply"), mesh);
}

// A box as the simulation writes a collider: each face with its own vertices and its outward normal.
TriangleMesh solidBox(const Vector3f& lo, const Vector3f& hi) {
  TriangleMesh mesh = boxMeshWithFaceNormals(lo, hi);
  const Vector3f centre = 0.5f * (lo + hi);
  for (const auto& t : mesh.triangles) {
    const Vector3f faceCentre = (mesh.positions[t[0]] + mesh.positions[t[1]] + mesh.positions[t[2]]) / 3.0f;
    for (uint32_t v : t)
      if (mesh.normals[v].dot(faceCentre - centre) < 0) mesh.normals[v] = -mesh.normals[v];
  }
  return mesh;
}

// A container's mesh as the simulation writes it: the shape's triangles with the normals turned inwards.
TriangleMesh insideOut(TriangleMesh mesh) {
  for (Vector3f& n : mesh.normals) n = -n;
  return mesh;
}

Image renderFrame(const fs::path& dir, const std::string& renderer, int frame) {
  CountingProgress progress;
  RenderOptions options;
  options.renderer = renderer;
  renderFrames(dir, loadScene(dir / "scene.json"), FrameRange{frame, frame}, progress, options);
  return readPng(framePath(dir, "frames", frame, "png"));
}

// The pixel where a world point lands in an image of the scene's camera.
const uint8_t* pixelOf(const Image& image, const Scene& scene, const Vector3f& point) {
  const PinholeCamera camera(framedCamera(scene), image.width, image.height);
  float x = 0, y = 0;
  EXPECT_TRUE(camera.project(point, x, y));
  EXPECT_TRUE(x >= 0 && x < image.width && y >= 0 && y < image.height) << x << "," << y;
  return pixelAt(image, int(x), int(y));
}

// Red clearly above green and blue: a collider of albedo (0.8, 0.1, 0.1) seen lit. Under the sun and the sky
// its red channel carries about 1.2 of linear light (tone-mapped to ~235), green and blue about 0.15 (~125):
// a gap of ~110 levels. The grey floor, the sky and the water (blue above red) never reach 60.
bool looksRed(const uint8_t* p) {
  return int(p[0]) - int(p[1]) > 60 && int(p[0]) - int(p[2]) > 60;
}

double luminance(const uint8_t* p) {
  return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
}

const char* const kRedBlock =
    R"([{"name": "block", "shape": "box", "position": [0.5, 0.2, 0.5], "size": [0.3, 0.4, 0.3],
         "color": [0.8, 0.1, 0.1]}])";

TEST(ColliderRenderTest, BoxShowsInItsColourInBothRenderersAndCastsAShadow) {
  TemporaryFolder folder;
  const Scene scene = writeOutputFolder(folder.path(), tankJson(kRedBlock), {0});
  writeCollider(folder.path(), "block", solidBox({0.35f, 0, 0.35f}, {0.65f, 0.4f, 0.65f}));
  for (const char* renderer : {"embree", "gl"}) {
    const Image image = renderFrame(folder.path(), renderer, 0);
    // The centre of the top face, which spans some 8x6 pixels around it.
    const uint8_t* top = pixelOf(image, scene, {0.5f, 0.4f, 0.5f});
    EXPECT_TRUE(looksRed(top)) << renderer << ": " << int(top[0]) << " " << int(top[1]) << " " << int(top[2]);
  }
  // The shadow: the sun (towards -0.41, 0.87, -0.26) casts the block's shadow towards +x. The floor at
  // (0.73, 0, 0.5), three pixels clear of the block's foot in the image, sees the sun through the block (its
  // ray enters the face x = 0.65 at height 0.17), so at most the sky lights it: under 0.37 of linear light
  // against 0.9 in the sun, at most 186 against 228 once tone-mapped (measured 165 and 230, the block hiding
  // some sky too). 20 levels is half the smallest gap.
  const Image with = renderFrame(folder.path(), "embree", 0);
  const Image without = renderMesh(TriangleMesh{}, scene, 0);
  const Vector3f shaded(0.73f, 0.0f, 0.5f);
  EXPECT_LT(luminance(pixelOf(with, scene, shaded)) + 20, luminance(pixelOf(without, scene, shaded)));
}

TEST(ColliderRenderTest, InvisibleColliderIsNeitherDrawnNorRead) {
  // `visible: 0`: the image is the same bytes as with no collider at all, and its mesh file is never opened
  // (there is none here).
  TemporaryFolder folder;
  const std::string hidden =
      R"([{"name": "block", "shape": "box", "position": [0.5, 0.2, 0.5], "size": [0.3, 0.4, 0.3],
           "color": [0.8, 0.1, 0.1], "visible": 0}])";
  const TriangleMesh water = testing::boxMesh({0.1f, 0.0f, 0.1f}, {0.3f, 0.2f, 0.3f});
  const Scene scene = writeOutputFolder(folder.path(), tankJson(hidden), {0}, water);
  EXPECT_TRUE(renderFrame(folder.path(), "embree", 0).rgb == renderMesh(water, scene, 0).rgb);
  Rasterizer rasterizer(scene);
  EXPECT_TRUE(renderFrame(folder.path(), "gl", 0).rgb == rasterizer.drawMesh(water).rgb);
}

TEST(ColliderRenderTest, MissingColliderMeshIsInputErrorNamingTheFile) {
  TemporaryFolder folder;
  writeOutputFolder(folder.path(), tankJson(kRedBlock), {0});
  for (const char* renderer : {"embree", "gl"}) {
    try {
      renderFrame(folder.path(), renderer, 0);
      FAIL() << "expected InputError";
    } catch (const InputError& error) {
      EXPECT_NE(std::string(error.what()).find("block.ply"), std::string::npos) << error.what();
    }
  }
}

TEST(ColliderRenderTest, MovingColliderIsDrawnWhereItsFrameMeshPutsIt) {
  // Two keyframes make the block a moving collider. Frame 0 has no frame file, so <name>.ply (the block on
  // the left) stands in; frame 1's file puts it on the right.
  TemporaryFolder folder;
  const std::string moving =
      R"([{"name": "block", "shape": "box", "position": [0.2, 0.15, 0.5], "size": [0.2, 0.3, 0.2],
           "color": [0.8, 0.1, 0.1], "motion": [{"time": 0, "position": [0.2, 0.15, 0.5]},
                                               {"time": 1, "position": [0.8, 0.15, 0.5]}]}])";
  const Scene scene = writeOutputFolder(folder.path(), tankJson(moving), {0, 1});
  writeCollider(folder.path(), "block", solidBox({0.1f, 0, 0.4f}, {0.3f, 0.3f, 0.6f}));
  writeMeshPly(framePath(folder.path() / "colliders", "block", 1, "ply"),
               solidBox({0.7f, 0, 0.4f}, {0.9f, 0.3f, 0.6f}));
  const Vector3f leftTop(0.2f, 0.3f, 0.5f), rightTop(0.8f, 0.3f, 0.5f);
  for (const char* renderer : {"embree", "gl"}) {
    const Image first = renderFrame(folder.path(), renderer, 0),
                second = renderFrame(folder.path(), renderer, 1);
    EXPECT_TRUE(looksRed(pixelOf(first, scene, leftTop))) << renderer;
    EXPECT_FALSE(looksRed(pixelOf(first, scene, rightTop))) << renderer;
    EXPECT_FALSE(looksRed(pixelOf(second, scene, leftTop))) << renderer;
    EXPECT_TRUE(looksRed(pixelOf(second, scene, rightTop))) << renderer;
  }
}

TEST(ColliderRenderTest, ContainerAndPlaneDoNotHideWhatIsInside) {
  // A green container all around a red block, and a blue plane between the camera and the block whose fluid
  // side faces away from the camera. Both keep only the faces turned towards the camera, so the block stays
  // in view (and lit: the sun comes in through the opening), and the container's far wall shows green beyond
  // it. Control: the same green box as an ordinary (closed, opaque) collider hides the block.
  const std::string json = R"([
      {"name": "block", "shape": "box", "position": [0.5, 0.1, 0.5], "size": [0.2, 0.2, 0.2],
       "color": [0.8, 0.1, 0.1]},
      {"name": "vessel", "shape": "box", "container": 1, "position": [0.5, 0.5, 0.5], "size": [0.9, 0.9, 0.9],
       "color": [0.1, 0.7, 0.1]},
      {"name": "screen", "shape": "plane", "position": [0.5, 0.5, 0.97], "normal": [0, 0, -1],
       "color": [0.1, 0.1, 0.8]}])";
  TriangleMesh screen;  // a square 4 across in the plane z = 0.97, its normal -z
  screen.positions = {{-1.5f, -1.5f, 0.97f}, {2.5f, -1.5f, 0.97f}, {2.5f, 2.5f, 0.97f}, {-1.5f, 2.5f, 0.97f}};
  screen.normals.assign(4, Vector3f(0, 0, -1));
  screen.triangles = {{0, 1, 2}, {0, 2, 3}};
  const TriangleMesh vessel = solidBox({0.05f, 0.05f, 0.05f}, {0.95f, 0.95f, 0.95f});
  const Vector3f blockTop(0.5f, 0.2f, 0.5f), farWall(0.3f, 0.45f, 0.05f);
  for (const char* renderer : {"embree", "gl"}) {
    TemporaryFolder folder;
    const Scene scene = writeOutputFolder(folder.path(), tankJson(json), {0});
    writeCollider(folder.path(), "block", solidBox({0.4f, 0, 0.4f}, {0.6f, 0.2f, 0.6f}));
    writeCollider(folder.path(), "vessel", insideOut(vessel));
    writeCollider(folder.path(), "screen", screen);
    const Image image = renderFrame(folder.path(), renderer, 0);
    const uint8_t* block = pixelOf(image, scene, blockTop);
    EXPECT_TRUE(looksRed(block)) << renderer << ": " << int(block[0]) << " " << int(block[1]) << " "
                                 << int(block[2]);
    // The far wall's inside faces +z, away from the sun: sky light only (in the preview 0.6 of the sky's mean
    // (0.55, 0.67, 0.86)), on albedo (0.1, 0.7, 0.1) about 0.28 of linear light in green against 0.03-0.05 in
    // red and blue: 173 against 42-61 once tone-mapped; the path tracer adds light bounced off the green
    // floor (measured 178 against 29-43). 60 levels is half the smaller gap.
    const uint8_t* wall = pixelOf(image, scene, farWall);
    EXPECT_GT(int(wall[1]) - int(wall[0]), 60) << renderer;
    EXPECT_GT(int(wall[1]) - int(wall[2]), 60) << renderer;

    // The control: an ordinary collider's near faces are drawn, and hide the block.
    std::string closed = json;
    closed.replace(closed.find(R"("container": 1)"), 14, R"("container": 0)");
    const Scene closedScene = writeOutputFolder(folder.path(), tankJson(closed), {0});
    writeCollider(folder.path(), "vessel", vessel);
    EXPECT_FALSE(looksRed(pixelOf(renderFrame(folder.path(), renderer, 0), closedScene, blockTop)))
        << renderer;
  }
}

TEST(ColliderRenderTest, TwoDimensionalViewShowsCrossSectionsInTheColliderColour) {
  // 2D: the tank [0, 2] x [0, 1] seen face on (80x40 pixels, as in RasterizerTest): x lands at pixel
  // 80 x (0.04 + 0.46 x) and y at row 40 x (1.04 - y) / 1.08. Colliders are flat in their albedo as sRGB:
  // 0.8 -> 231, 0.1 -> 89, 0.7 -> 219.
  const auto pixel2d = [](const Image& image, float x, float y) {
    return pixelAt(image, int(80 * (0.04f + 0.46f * x)), int(40 * (1.04f - y) / 1.08f));
  };
  const auto flatJson = [](const std::string& second) {
    return R"({"name": "flat", "dimensions": 2, "domain": {"min": [0, 0], "max": [2, 1]},
      "particle_spacing": 0.05, "fluids": [{"box": {"min": [0, 0], "max": [0.5, 0.5]}}],
      "colliders": [
        {"name": "prism", "shape": "box", "position": [0.5, 0.3], "size": [0.4, 0.4],
         "color": [0.8, 0.1, 0.1]}, )" +
           second + R"(], "render": {"width": 80, "height": 40}})";
  };
  TemporaryFolder folder;
  writeOutputFolder(folder.path(),
                    flatJson(R"({"name": "ball", "shape": "sphere", "position": [1.4, 0.5], "radius": 0.3,
                                 "color": [0.1, 0.7, 0.1]})"),
                    {0});
  writeCollider(folder.path(), "prism", solidBox({0.3f, 0.1f, -0.2f}, {0.7f, 0.5f, 0.2f}));
  // The ball's centre lies 0.2 in front of the plane z = 0: its cross-section there is a disc of radius
  // sqrt(0.3^2 - 0.2^2) = 0.22, while seen straight on it would cover 0.3.
  writeCollider(folder.path(), "ball", testing::sphereMesh({1.4f, 0.5f, 0.2f}, 0.3f, 48));
  const Image image = renderFrame(folder.path(), "gl", 0);
  const uint8_t* prism = pixel2d(image, 0.5f, 0.3f);
  EXPECT_NEAR(prism[0], 231, 1);
  EXPECT_NEAR(prism[1], 89, 1);
  EXPECT_NEAR(prism[2], 89, 1);
  const uint8_t* ball = pixel2d(image, 1.4f, 0.5f);
  EXPECT_NEAR(ball[0], 89, 1);
  EXPECT_NEAR(ball[1], 219, 1);
  // 0.26 from the ball's centre: outside its cross-section, inside its outline; the light grey tank there.
  const uint8_t* rim = pixel2d(image, 1.66f, 0.5f);
  EXPECT_LT(std::abs(int(rim[1]) - int(rim[0])), 10) << int(rim[0]) << " " << int(rim[1]);

  // A container's solid is its outside: the cup [1.2, 1.8] x [0.1, 0.9] fills the tank around it, not inside
  // it, and nothing beyond the tank.
  writeOutputFolder(folder.path(),
                    flatJson(R"({"name": "cup", "shape": "box", "container": 1, "position": [1.5, 0.5],
                                 "size": [0.6, 0.8], "color": [0.1, 0.7, 0.1]})"),
                    {0});
  writeCollider(folder.path(), "cup", insideOut(solidBox({1.2f, 0.1f, -0.3f}, {1.8f, 0.9f, 0.3f})));
  const Image cupImage = renderFrame(folder.path(), "gl", 0);
  const uint8_t* wall = pixel2d(cupImage, 1.0f, 0.5f);
  EXPECT_NEAR(wall[0], 89, 1);
  EXPECT_NEAR(wall[1], 219, 1);
  const uint8_t* inside = pixel2d(cupImage, 1.5f, 0.5f);
  EXPECT_LT(std::abs(int(inside[1]) - int(inside[0])), 10);
  const uint8_t* beyond = pixelAt(cupImage, 79, 20);  // right of the tank, in the margin
  EXPECT_LT(std::abs(int(beyond[1]) - int(beyond[0])), 10);
  EXPECT_TRUE(prism[0] == pixel2d(cupImage, 0.5f, 0.3f)[0]);  // the prism is still there, on top
}

TEST(ColliderRenderTest, GlassTankReplacesTheEdgesAndNoneDrawsNeither) {
  // The same empty tank with render.tank edges, glass and none. Where the edges show (pixels at least 24
  // levels darker than without any tank: the dark bars, albedo 0.04, against the floor and sky), the glass
  // image has no dark bar: there it is lighter than the edges image. Clear glass changes the rest of the view
  // a little (a few per cent of reflection), so it is not the same image as none either.
  TemporaryFolder folder;
  Image images[3];
  const char* modes[3] = {"edges", "glass", "none"};
  for (int m = 0; m < 3; ++m) {
    writeOutputFolder(
        folder.path(),
        tankJson("[]", std::string(R"("width": 160, "height": 120, "tank": ")") + modes[m] + "\""), {0});
    images[m] = renderFrame(folder.path(), "embree", 0);
  }
  const Image &edges = images[0], &glass = images[1], &none = images[2];
  int bars = 0, glassLighter = 0;
  for (int y = 0; y < edges.height; ++y)
    for (int x = 0; x < edges.width; ++x)
      if (luminance(pixelAt(edges, x, y)) + 24 < luminance(pixelAt(none, x, y))) {
        ++bars;
        if (luminance(pixelAt(glass, x, y)) > luminance(pixelAt(edges, x, y)) + 24) ++glassLighter;
      }
  EXPECT_GT(bars, 100);  // twelve edges, most of a pixel wide at this size
  EXPECT_GT(glassLighter, 0.9 * bars);
  EXPECT_FALSE(glass.rgb == none.rgb);
  EXPECT_FALSE(glass.rgb == edges.rgb);
}

TEST(ColliderRenderTest, SameBytesWithOneAndTwoThreadsWithCollidersAndGlass) {
  const Scene scene =
      parseScene(tankJson(kRedBlock, R"("width": 100, "height": 70, "samples": 3, "tank": "glass")"), "test");
  const std::vector<ColliderMesh> colliders = {
      makeColliderMesh(scene.colliders[0], solidBox({0.35f, 0, 0.35f}, {0.65f, 0.4f, 0.65f}))};
  const TriangleMesh water = testing::boxMesh({0.0f, 0.0f, 0.0f}, {0.3f, 0.3f, 1.0f});
  Image one, two;
  {
    const ThreadLimit limit(1);
    one = renderMesh(water, colliders, scene, 7);
  }
  {
    const ThreadLimit limit(2);
    two = renderMesh(water, colliders, scene, 7);
  }
  EXPECT_TRUE(one.rgb == two.rgb);
}

}  // namespace
}  // namespace surge
