// The tank's drawn edges leave its open faces out (domain.open): the path tracer's bars, the preview's lines.
#include <gtest/gtest.h>

#include "render/shading.h"

namespace surge {
namespace {

Scene tank(int dimensions, std::vector<std::string> open) {
  Scene scene;
  scene.dimensions = dimensions;
  scene.domain.max = Eigen::Vector3d(2, 1, dimensions == 3 ? 0.5 : 0);
  scene.open = std::move(open);
  return scene;
}

TEST(TankEdges, AnOpenFaceTakesItsEdgesAway) {
  EXPECT_EQ(tankEdges(tank(3, {})).size(), 12u);
  // Open at +x: the four edges around that face go; the other eight stay.
  const auto open = tankEdges(tank(3, {"+x"}));
  ASSERT_EQ(open.size(), 8u);
  for (const auto& [a, b] : open) EXPECT_FALSE(a.x() == 2 && b.x() == 2) << a.transpose() << " - " << b.transpose();
  // A channel open at both ends keeps only the four edges along it.
  EXPECT_EQ(tankEdges(tank(3, {"-x", "+x"})).size(), 4u);
  // 2D: the floor and the two walls, less the open ones.
  EXPECT_EQ(tankEdges(tank(2, {})).size(), 3u);
  const auto flat = tankEdges(tank(2, {"-x", "-y"}));
  ASSERT_EQ(flat.size(), 1u);
  EXPECT_EQ(flat[0][0].x(), 2);
  EXPECT_EQ(flat[0][1].x(), 2);
}

}  // namespace
}  // namespace surge
