// The path tracer with several fluids (issue 34): each liquid absorbs in its own colour (fluids[i].color), and two
// liquids that meet pass the light between them.
#include <gtest/gtest.h>

#include "render/camera.h"
#include "render/shading.h"
#include "render/tracer.h"
#include "render_test_helpers.h"

namespace surge {
namespace {

// A unit tank with water (the default colour) and an orange oil; neither fluid's boxes matter here, only their
// colours: the meshes are the test's own.
Scene waterAndOil(const std::vector<std::string>& overrides = {}) {
  return parseScene(R"({"name": "two_liquids", "dimensions": 3, "domain": {"min": [0, 0, 0], "max": [1, 1, 1]},
    "particle_spacing": 0.05,
    "fluids": [{"box": {"min": [0, 0, 0], "max": [0.5, 0.5, 0.5]}},
               {"name": "oil", "rest_density": 900, "color": [0.9, 0.45, 0.1], "box": {"min": [0.5, 0, 0], "max": [1, 0.5, 0.5]}}],
    "render": {"width": 64, "height": 48, "water_color": [0.3, 0.65, 0.9], "absorption_distance": 0.3}})",
                    "test", overrides);
}

// Light in a white furnace (sky 1 everywhere, no sun, every diffuse surface white) with the scene's liquids: what
// comes back through a liquid is white light less what that liquid absorbed, so its hue is the liquid's.
Shading furnaceWithLiquids(const Scene& scene) {
  Shading s = testing::furnaceLight(scene);
  s.maxDepth = 64;
  return s;
}

Eigen::Vector3f meanLight(const RayScene& world, const Shading& shading, const PinholeCamera& camera,
                          const Eigen::Vector3f& at) {
  float x = 0, y = 0;
  EXPECT_TRUE(camera.project(at, x, y));
  Eigen::Vector3f sum = Eigen::Vector3f::Zero();
  constexpr int kSamples = 1024;
  for (int s = 0; s < kSamples; ++s) {
    SampleRandom random(3, uint32_t(y * 1000 + x), uint32_t(s));
    sum += traceRadiance(world, shading, camera.rayThrough(x, y), random);
  }
  return sum / kSamples;
}

// Two meshes joined as the renderer joins them (TriangleMesh::fluid): `first` fluid 0, `second` fluid 1.
TriangleMesh joined(const TriangleMesh& first, const TriangleMesh& second) {
  TriangleMesh mesh = first;
  const uint32_t base = uint32_t(mesh.positions.size());
  mesh.positions.insert(mesh.positions.end(), second.positions.begin(), second.positions.end());
  for (const auto& t : second.triangles) mesh.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  mesh.fluid.assign(first.triangles.size(), 0);
  mesh.fluid.resize(mesh.triangles.size(), 1);
  return mesh;
}

// A block of water (fluid 0) beside a block of oil (fluid 1), each 0.4 m on a side, the oil at larger x; seen at
// kThroughWater and kThroughOil.
TriangleMesh waterBesideOil() {
  return joined(testing::boxMesh({0.05f, 0.0f, 0.3f}, {0.45f, 0.4f, 0.7f}),
                testing::boxMesh({0.55f, 0.0f, 0.3f}, {0.95f, 0.4f, 0.7f}));
}
const Eigen::Vector3f kThroughWater(0.25f, 0.2f, 0.7f), kThroughOil(0.75f, 0.2f, 0.7f);

// A block of water and a block of oil side by side: seen through the water the light is blue (blue over red above
// 1.5: the water's colour is 3 to 1), through the oil orange (red over blue above 3; 9 to 1). With one absorption for
// both, as before, both would be blue.
TEST(SeveralFluidsRender, EachLiquidAbsorbsInItsOwnColour) {
  const Scene scene = waterAndOil();
  const Shading shading = furnaceWithLiquids(scene);
  ASSERT_EQ(shading.fluidAbsorption.size(), 2u);
  const TriangleMesh mesh = waterBesideOil();
  const RayDevice device;
  const RayScene world(device, mesh, scene);
  const PinholeCamera camera(framedCamera(scene), 64, 48);
  const Eigen::Vector3f water = meanLight(world, shading, camera, kThroughWater);
  const Eigen::Vector3f oil = meanLight(world, shading, camera, kThroughOil);
  std::printf("through water %.3f %.3f %.3f, through oil %.3f %.3f %.3f\n", water[0], water[1], water[2], oil[0],
              oil[1], oil[2]);
  EXPECT_GT(water[2], 1.5f * water[0]);
  EXPECT_GT(oil[0], 3.0f * oil[2]);
}

// fluids[i].absorption_distance: the oil takes its colour over its own 0.1 m where the water keeps the render's
// 0.3. Beer-Lambert makes colour c over a third of the distance the same liquid as c cubed over the whole:
// -ln(c) / (d / 3) = -ln(c^3) / d. So the oil at 0.1 m has the coefficients of its colour cubed at the render's
// distance, and the light through it is the same on every path (within the float rounding of the coefficients),
// while the water's is left as it was.
TEST(SeveralFluidsRender, EachLiquidTakesItsColourOverItsOwnDistance) {
  const Scene scene = waterAndOil(), nearer = waterAndOil({"fluids[1].absorption_distance=0.1"}),
              cubed = waterAndOil({"fluids[1].color=[0.729, 0.091125, 0.001]"});
  const Shading shading = furnaceWithLiquids(scene), nearerShading = furnaceWithLiquids(nearer),
                cubedShading = furnaceWithLiquids(cubed);
  ASSERT_EQ(nearerShading.fluidAbsorption.size(), 2u);
  const Eigen::Vector3f sigma = nearerShading.fluidAbsorption[1], cubedSigma = cubedShading.fluidAbsorption[1];
  EXPECT_LT((sigma - cubedSigma).norm(), 1e-5f * cubedSigma.norm())
      << sigma.transpose() << " / " << cubedSigma.transpose();
  EXPECT_EQ(nearerShading.fluidAbsorption[0], shading.fluidAbsorption[0]);
  EXPECT_EQ(nearerShading.waterAbsorption, shading.waterAbsorption);
  const TriangleMesh mesh = waterBesideOil();
  const RayDevice device;
  const RayScene world(device, mesh, scene);
  const PinholeCamera camera(framedCamera(scene), 64, 48);
  const Eigen::Vector3f through = meanLight(world, shading, camera, kThroughOil);
  const Eigen::Vector3f nearerThrough = meanLight(world, nearerShading, camera, kThroughOil);
  const Eigen::Vector3f cubedThrough = meanLight(world, cubedShading, camera, kThroughOil);
  std::printf("through the oil: %.4f %.4f %.4f at 0.3 m, %.4f %.4f %.4f at 0.1 m, %.4f %.4f %.4f cubed at 0.3 m\n",
              through[0], through[1], through[2], nearerThrough[0], nearerThrough[1], nearerThrough[2], cubedThrough[0],
              cubedThrough[1], cubedThrough[2]);
  EXPECT_LT((nearerThrough - cubedThrough).cwiseAbs().maxCoeff(), 1e-3f);
  EXPECT_GT(through[0] - nearerThrough[0], 0.1f) << "the oil's own distance made no difference";
}

// Oil lying on water, their surfaces overlapping a little at the interface (as two fluids' level sets do): a ray
// down through both is tinted by both (less red than through the oil alone, less blue than through the water
// alone), and in the white furnace with no absorption the light is conserved through the interface (1 within
// the furnace test's 0.03).
TEST(SeveralFluidsRender, LightPassesFromOneLiquidIntoTheOther) {
  const Scene scene = waterAndOil();
  Shading shading = furnaceWithLiquids(scene);
  const TriangleMesh stacked = joined(testing::boxMesh({0.2f, 0.0f, 0.2f}, {0.8f, 0.3f, 0.8f}),
                                      testing::boxMesh({0.2f, 0.29f, 0.2f}, {0.8f, 0.5f, 0.8f}));
  const TriangleMesh oilAlone = joined(TriangleMesh{}, testing::boxMesh({0.2f, 0.29f, 0.2f}, {0.8f, 0.5f, 0.8f}));
  const TriangleMesh waterAlone = testing::boxMesh({0.2f, 0.0f, 0.2f}, {0.8f, 0.3f, 0.8f});
  const RayDevice device;
  const RayScene both(device, stacked, scene), oil(device, oilAlone, scene), water(device, waterAlone, scene);
  // Down through the middle, from above.
  Scene above = scene;
  above.render.camera.position = Eigen::Vector3d(0.5, 2.0, 0.9);
  above.render.camera.look_at = Eigen::Vector3d(0.5, 0.0, 0.5);
  const PinholeCamera camera(above.render.camera, 64, 48);
  const Eigen::Vector3f centre(0.5f, 0.0f, 0.5f);
  const Eigen::Vector3f throughBoth = meanLight(both, shading, camera, centre);
  const Eigen::Vector3f throughOil = meanLight(oil, shading, camera, centre);
  const Eigen::Vector3f throughWater = meanLight(water, shading, camera, centre);
  std::printf("down through both %.3f %.3f %.3f, oil %.3f %.3f %.3f, water %.3f %.3f %.3f\n", throughBoth[0],
              throughBoth[1], throughBoth[2], throughOil[0], throughOil[1], throughOil[2], throughWater[0],
              throughWater[1], throughWater[2]);
  EXPECT_LT(throughBoth[0], 0.9f * throughOil[0]);
  EXPECT_LT(throughBoth[2], 0.9f * throughWater[2]);
  shading.waterAbsorption = Eigen::Vector3f::Zero();
  for (Eigen::Vector3f& sigma : shading.fluidAbsorption) sigma.setZero();
  EXPECT_NEAR(meanLight(both, shading, camera, centre)[0], 1.0f, 0.03f);
}

}  // namespace
}  // namespace surge
