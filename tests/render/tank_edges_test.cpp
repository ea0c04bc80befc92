// The tank's drawn edges leave its open faces (domain.open) and the faces of its periodic axes (domain.periodic)
// out: the path tracer's bars and glass panes, the preview's lines.
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

TEST(TankEdges, APeriodicAxisHasNoWalls) {
  Scene channel = tank(3, {});
  channel.periodic = {"x"};
  EXPECT_EQ(tankEdges(channel).size(), 4u);  // the fluid runs on through both x faces: the edges along x stay
  for (const auto& [a, b] : tankEdges(channel)) EXPECT_NE(a.x(), b.x());
  channel.periodic = {"x", "z"};
  EXPECT_EQ(tankEdges(channel).size(), 0u);
  Scene couette = tank(2, {});
  couette.periodic = {"x"};
  ASSERT_EQ(tankEdges(couette).size(), 1u);  // the floor only
  EXPECT_EQ(tankEdges(couette)[0][0].y(), 0);
  EXPECT_EQ(tankEdges(couette)[0][1].y(), 0);
}

}  // namespace
}  // namespace surge
