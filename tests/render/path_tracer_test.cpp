// The path tracer's physics: energy conservation in a white furnace, a water sphere acting as a lens, Fresnel
// reflection off water and off a glass tank's panes.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "render/camera.h"
#include "render/renderer.h"
#include "render/shading.h"
#include "render/tracer.h"
#include "render_test_helpers.h"

namespace surge {
namespace {

using testing::sphereMesh;
using testing::unitTankScene;

// A white furnace: the sky is 1 in every direction, there is no sun, every diffuse surface has albedo 1 and
// the water absorbs nothing. Whatever a path meets, the light it brings back is then exactly 1 in
// expectation; more would mean energy created, less energy lost (within max_depth, made large here).
Shading whiteFurnace(const Scene& scene) {
  Shading s = testing::furnaceLight(scene);
  s.waterAbsorption = Eigen::Vector3f::Zero();
  s.maxDepth = 256;
  return s;
}

// The mean radiance (channel 0; all three are equal here) over `samples` paths through image point (x, y).
double meanRadiance(const RayScene& world, const Shading& shading, const PinholeCamera& camera, float x,
                    float y, int samples) {
  double sum = 0;
  for (int s = 0; s < samples; ++s) {
    SampleRandom random(1, uint32_t(y * 1000 + x), uint32_t(s));
    sum += traceRadiance(world, shading, camera.rayThrough(x, y), random)[0];
  }
  return sum / samples;
}

// In a white furnace every path returns 1, or after Russian roulette (survival 0.95 at throughput 1) 0 or
// 1/0.95^k: its standard deviation is at most sqrt(0.05 k) ~ 0.5 for the few roulette steps a path here takes,
// so the mean of 4096 paths is within 0.5 / 64 ~ 0.008 of its expectation; 0.03 is almost four of those. An
// error in the Fresnel weights or the Lambertian sampling shifts the mean by far more (dropping the 1 - F
// factor of a refraction alone: ~0.04 per crossing).
template <size_t N>
void expectFurnaceBalance(const RayScene& world, const Shading& shading, const PinholeCamera& camera,
                          const float (&points)[N][2]) {
  for (const auto& p : points) {
    const double mean = meanRadiance(world, shading, camera, p[0], p[1], 4096);
    EXPECT_NEAR(mean, 1.0, 0.03) << "image point " << p[0] << "," << p[1];
  }
}

TEST(PathTracerTest, WhiteFurnaceConservesEnergy) {
  const Scene scene = unitTankScene();
  const Shading shading = whiteFurnace(scene);
  const RayDevice device;
  const TriangleMesh ball = sphereMesh({0.5f, 0.4f, 0.5f}, 0.25f, 24);
  const RayScene world(device, ball, scene);
  const PinholeCamera camera(framedCamera(scene), 64, 48);
  float cx = 0, cy = 0;
  ASSERT_TRUE(camera.project({0.5f, 0.4f, 0.5f}, cx, cy));
  // Rays onto the ground beside the tank (one Lambertian bounce into the sky), through the water ball
  // (Fresnel splits, refractions, total internal reflections, bounces off the floor under it) and past its
  // rim.
  const float points[][2] = {{4, 44}, {60, 44}, {cx, cy}, {cx + 3, cy - 2}, {cx - 4, cy + 1}};
  expectFurnaceBalance(world, shading, camera, points);
}

TEST(PathTracerTest, GlassWallsAndCollidersConserveEnergyInTheWhiteFurnace) {
  // The furnace again, in a glass tank, with a white collider (albedo 1) beside the water ball: rays through
  // the panes (split, reflected or passed) and off the collider must still bring back exactly 1 on average.
  const Scene scene = unitTankScene(R"("tank": "glass")");
  const Shading shading = whiteFurnace(scene);
  const RayDevice device;
  const TriangleMesh ball = sphereMesh({0.5f, 0.4f, 0.5f}, 0.25f, 24);
  ColliderSettings white;
  white.color = Eigen::Vector3d::Ones();
  const std::vector<ColliderMesh> colliders = {
      makeColliderMesh(white, testing::boxMeshWithFaceNormals({0.8f, 0.0f, 0.2f}, {0.95f, 0.3f, 0.8f}))};
  const RayScene world(device, ball, scene, colliders);
  const PinholeCamera camera(framedCamera(scene), 64, 48);
  float cx = 0, cy = 0, bx = 0, by = 0;
  ASSERT_TRUE(camera.project({0.5f, 0.4f, 0.5f}, cx, cy));
  ASSERT_TRUE(camera.project({0.875f, 0.3f, 0.5f}, bx, by));
  // Through the front pane onto the floor, into the ball, onto the collider's top, and over the tank's rim.
  const float points[][2] = {{cx - 8, cy + 8}, {cx, cy}, {cx + 3, cy - 2}, {bx, by}, {32, 8}};
  expectFurnaceBalance(world, shading, camera, points);
}

TEST(PathTracerTest, GlassPaneReflectsAsAThinSlab) {
  // A ray meets the front pane of a glass tank; behind the pane a black collider swallows all that passes,
  // and the reflection goes to a sky of radiance 1. The first pane splits deterministically, so the radiance
  // is the slab's reflectance exactly: per polarisation 2R / (1 + R) of the single-surface Fresnel R, at
  // index 1.5. Head on R = 0.04 for both: 0.0769. At 60 degrees Rs = 0.1766, Rp = 0.0018: 0.1519 (a single
  // surface would give 0.089, the unpolarised R put through 2R / (1 + R) 0.164).
  const Scene scene = unitTankScene(R"("tank": "glass")");
  const Shading shading = whiteFurnace(scene);
  const RayDevice device;
  const TriangleMesh noWater;
  ColliderSettings black;
  black.color = Eigen::Vector3d::Zero();
  const std::vector<ColliderMesh> blackBox = {
      makeColliderMesh(black, testing::boxMeshWithFaceNormals({0.05f, 0.05f, 0.05f}, {0.95f, 0.95f, 0.95f}))};
  const RayScene world(device, noWater, scene, blackBox);
  const auto reflectance = [&](float degrees) {
    const float a = float(degrees * M_PI / 180);
    Ray ray;
    ray.direction = Eigen::Vector3f(-std::sin(a), 0, -std::cos(a));
    ray.origin = Eigen::Vector3f(0.5f, 0.5f, 1.0f) - 2.0f * ray.direction;  // meets the pane near (0.5, 0.5)
    SampleRandom random(0, 0, 0);
    return traceRadiance(world, shading, ray, random)[0];
  };
  EXPECT_NEAR(reflectance(0), 0.0769, 0.001);
  EXPECT_NEAR(reflectance(60), 0.1519, 0.001);
}

// Looking straight down on a clear water ball hanging above a ground whose left half (x < 1) is dark and
// right half bright. A ball lens of index n focuses n R / (2 (n - 1)) = 2 R from its centre; the ground
// lies 3.7 R below it, beyond the focus, so the ball shows the ground upside down: bright on its left, dark
// on its right.
TEST(PathTracerTest, WaterBallOverTheCheckerboardActsAsALens) {
  const Scene scene = parseScene(R"({
    "name": "lens", "dimensions": 3,
    "domain": {"min": [0, 0, 0], "max": [2, 1, 1]},
    "particle_spacing": 0.05,
    "fluids": [{"box": {"min": [0, 0, 0], "max": [0.5, 0.5, 0.5]}}],
    "render": {"width": 96, "height": 96, "samples": 16,
               "camera": {"position": [1.0, 4.0, 0.5], "look_at": [1.0, 0.0, 0.5], "fov": 14}}
  })",
                                 "test");
  Shading shading = whiteFurnace(scene);  // uniform sky light: the ground shows its albedo, no shadows
  shading.checkerSize = 1;                // squares [0,1) and [1,2) in x over the whole view
  shading.floorAlbedo = shading.groundAlbedo = 0.5f;
  shading.checkerContrast = 0.4f;  // albedo 0.1 for x < 1 (z in [0, 1)), 0.9 for x >= 1
  shading.maxDepth = 16;
  const float radius = 0.15f;
  const Eigen::Vector3f centre(1.0f, 0.55f, 0.5f);
  const Image image = renderMeshWith(sphereMesh(centre, radius, 32), scene, 0, shading);
  const PinholeCamera camera(framedCamera(scene), image.width, image.height);
  float cx = 0, cy = 0;
  ASSERT_TRUE(camera.project(centre, cx, cy));
  float rimX = 0, rimY = 0;
  ASSERT_TRUE(camera.project(centre + Eigen::Vector3f(radius, 0, 0), rimX, rimY));
  const float r = rimX - cx;  // the ball's radius in the image: about 18 pixels
  ASSERT_GT(r, 10.0f);
  const auto level = [&](float x, float y) {
    return int(image.rgb[3 * (size_t(y) * image.width + size_t(x)) + 1]);
  };
  // Outside the ball: the ground as it is (world +x is image right when looking down with -z as image up).
  const int outsideLeft = level(cx - 1.6f * r, cy), outsideRight = level(cx + 1.6f * r, cy);
  // Through the ball, half way out from its centre.
  const int throughLeft = level(cx - 0.5f * r, cy), throughRight = level(cx + 0.5f * r, cy);
  // Albedos 0.1 and 0.9 under a sky of 1 tone-map to about 60 and 225 of 255; through the ball, two Fresnel
  // transmissions (~0.96 each) and a ~4 % sky reflection move that by a few levels. Sampling noise is a level
  // or two (the ground under a uniform sky has none; only paths through the ball vary). 80 levels is half the
  // contrast: a clear margin both ways.
  EXPECT_GT(outsideRight - outsideLeft, 80) << outsideLeft << " " << outsideRight;
  EXPECT_GT(throughLeft - throughRight, 80) << throughLeft << " " << throughRight;  // flipped
  // The image through the ball differs from the ground around it on each side.
  EXPECT_GT(throughLeft - outsideLeft, 80);
  EXPECT_GT(outsideRight - throughRight, 80);
}

TEST(PathTracerTest, FresnelMakesWaterReflectMoreAtGrazingAngles) {
  // Water in a furnace whose sky is bright above and black below: a ray hitting a flat water surface from
  // above sees F x sky + (1 - F) x (black floor below), so the brightness is the Fresnel reflectance: 2 %
  // head on, far more at grazing incidence (about 60 % at 85 degrees; Schlick's formula gives 0.62).
  const Scene scene = unitTankScene();
  Shading shading = whiteFurnace(scene);
  shading.belowHorizon = Eigen::Vector3f::Zero();
  shading.floorAlbedo = shading.groundAlbedo = shading.tankAlbedo = 0;
  const RayDevice device;
  // Deeper than the ground: refracted light meets the black ground inside the water and never returns.
  const TriangleMesh pool = testing::boxMesh({-50, -1, -50}, {50, 0.5f, 50});
  const RayScene world(device, pool, scene);
  const auto reflectance = [&](float degrees) {
    const float a = float(degrees * M_PI / 180);
    Ray ray;
    ray.origin = Eigen::Vector3f(0.5f, 2, 0.5f);  // above the tank's middle, clear of its edges
    ray.direction = Eigen::Vector3f(std::sin(a), -std::cos(a), 0);
    double sum = 0;
    for (int s = 0; s < 256; ++s) {
      SampleRandom random(0, 0, uint32_t(s));
      sum += traceRadiance(world, shading, ray, random)[0];
    }
    return sum / 256;
  };
  // The first hit splits deterministically into F (to the sky: exactly F) and 1 - F (into black water), so
  // there is no noise: the reflectance matches the exact Fresnel equations to float precision.
  EXPECT_NEAR(reflectance(0), 0.0204, 0.001);  // ((1.333 - 1) / (1.333 + 1))^2
  EXPECT_GT(reflectance(85), 0.5);
}

TEST(PathTracerTest, QualityPresetsSetResolutionAndSamples) {
  RenderSettings settings;  // 960 x 540
  settings.samples = 8;
  settings.quality = "preview";
  EXPECT_EQ(resolvedRenderSettings(settings).width, 480);
  EXPECT_EQ(resolvedRenderSettings(settings).height, 270);
  EXPECT_EQ(resolvedRenderSettings(settings).samples, 4);
  settings.quality = "final";
  EXPECT_EQ(resolvedRenderSettings(settings).width, 1280);
  EXPECT_EQ(resolvedRenderSettings(settings).height, 720);
  EXPECT_EQ(resolvedRenderSettings(settings).samples, 64);
  settings.quality = "standard";
  EXPECT_EQ(resolvedRenderSettings(settings).width, 960);
  // A preset image has the preset's size.
  const Scene scene = unitTankScene(R"("quality": "preview", "width": 100, "height": 60)");
  const Image image = renderMesh(TriangleMesh{}, scene, 0);
  EXPECT_EQ(image.width, 50);
  EXPECT_EQ(image.height, 30);
}

// A scene that sets no camera is framed by the renderer: the whole tank in view, its centre near the image's,
// at any quality (the presets keep the aspect ratio); a camera the scene sets is kept as it is.
TEST(PathTracerTest, ASceneWithoutACameraIsFramedWholeInView) {
  const Scene scene = unitTankScene();
  ASSERT_EQ(scene.render.camera.position, scene.render.camera.look_at);  // the scene leaves it to the renderer
  for (const char* quality : {"standard", "preview", "final"}) {
    SCOPED_TRACE(quality);
    Scene preset = scene;
    preset.render.quality = quality;
    const RenderSettings settings = resolvedRenderSettings(preset);
    EXPECT_EQ(settings.camera.position, framedCamera(scene).position);
    const PinholeCamera camera(settings.camera, settings.width, settings.height);
    for (int corner = 0; corner < 8; ++corner) {
      Eigen::Vector3d p;
      for (int k = 0; k < 3; ++k) p[k] = (corner >> k & 1) ? scene.domain.max[k] : scene.domain.min[k];
      float x = -1, y = -1;
      ASSERT_TRUE(camera.project(p.cast<float>(), x, y));
      EXPECT_GT(x, 0);
      EXPECT_LT(x, settings.width);
      EXPECT_GT(y, 0);
      EXPECT_LT(y, settings.height);
    }
  }
  Scene placed = scene;
  placed.render.camera.position = Eigen::Vector3d(3, 2, 5);
  EXPECT_EQ(framedCamera(placed).position, Eigen::Vector3d(3, 2, 5));
  EXPECT_EQ(framedCamera(placed).look_at, scene.render.camera.look_at);
}

}  // namespace
}  // namespace surge
