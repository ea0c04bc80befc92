// The table of shapes (geometry/shapes.h) against the scene's declaration and the parts that use it.
#include "geometry/shapes.h"

#include <gtest/gtest.h>

#include "core/errors.h"
#include "tests/core/scene_choices.h"

namespace surge {
namespace {

std::vector<std::string> namesWhere(bool ShapeType::*part) {
  std::vector<std::string> names;
  for (const ShapeType& t : shapeTypes())
    if (t.*part) names.emplace_back(t.name);
  return names;
}

TEST(Shapes, TheScenesShapeChoicesAreTheTablesNames) {
  EXPECT_EQ(sceneChoices("colliders[i].shape"), namesWhere(&ShapeType::collider));
  EXPECT_EQ(sceneChoices("bodies[i].shape"), namesWhere(&ShapeType::body));
}

TEST(Shapes, EveryEntryIsFoundByItsNameAndKind) {
  for (const ShapeType& t : shapeTypes()) {
    SCOPED_TRACE(t.name);
    EXPECT_EQ(findShapeType(t.name), &t);
    EXPECT_EQ(&shapeType(t.kind), &t);
    // A part that takes the shape has its mass: a body its 3D mass, a body in 2D its cross-section's.
    EXPECT_EQ(t.body, t.mass3d != nullptr);
    EXPECT_EQ(t.body2d, t.mass2d != nullptr);
    EXPECT_TRUE(!t.body2d || t.body);
  }
  EXPECT_EQ(findShapeType("torus"), nullptr);
}

Scene oneBodyScene(int dimensions) {
  const std::string v = dimensions == 3 ? "[1, 1, 1]" : "[1, 1]", zero = dimensions == 3 ? "[0, 0, 0]" : "[0, 0]";
  const std::string mid = dimensions == 3 ? "[0.5, 0.5, 0.5]" : "[0.5, 0.5]";
  const std::string size = dimensions == 3 ? "[0.1, 0.1, 0.1]" : "[0.1, 0.1]";
  Scene scene = parseScene(
      R"({"name": "t", "dimensions": )" + std::to_string(dimensions) + R"(, "domain": {"min": )" + zero +
          R"(, "max": )" + v + R"(}, "particle_spacing": 0.02, "fluids": [{"box": {"min": )" + zero + R"(, "max": )" +
          (dimensions == 3 ? "[0.2, 0.2, 0.2]" : "[0.2, 0.2]") + R"(}}], "bodies": [{"shape": "box", "size": )" + size +
          R"(, "position": )" + mid + R"(, "density": 500}]})",
      "test.json");
  scene.source = "test.json";
  return scene;
}

// A scene file cannot name these (its choices refuse them); a scene made in code meets the table.
TEST(Shapes, AShapeAPartDoesNotTakeIsAnErrorNamingTheKey) {
  Scene scene = oneBodyScene(3);
  ColliderSettings settings = scene.bodies[0].solid;
  const auto message = [&](const std::string& shape, const std::string& key, bool body) {
    settings.shape = shape;
    try {
      buildSolidShape(scene, settings, key, body);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("plane", "bodies[1]", true).find("bodies[1].shape"), std::string::npos);
  EXPECT_NE(message("heightfield", "bodies[1]", true).find("bodies[1].shape"), std::string::npos);
  EXPECT_NE(message("torus", "colliders[2]", false).find("colliders[2].shape"), std::string::npos);
  EXPECT_EQ(message("box", "bodies[1]", true), "no error");
  scene.dimensions = 2;
  settings.size = {0.1, 0.1};
  EXPECT_NE(message("mesh", "bodies[0]", true).find("bodies[0].shape"), std::string::npos);
}

// Each body shape's mass at a density of 2 and a scale of 2, against its closed form.
TEST(Shapes, MassPropertiesComeFromTheTable) {
  Scene scene = oneBodyScene(3);
  const ColliderShape box = buildBodyShape(scene, 0);
  const MassProperties m = massProperties(box, 2.0, 3, 2.0);
  EXPECT_NEAR(m.volume, 0.008, 1e-9);
  EXPECT_NEAR(m.mass, 0.016, 1e-9);
  EXPECT_NEAR(m.inertia(0, 0), 0.016 * (0.04 + 0.04) / 12, 1e-9);
  ColliderShape plane = box;
  plane.kind = ShapeKind::Plane;
  EXPECT_THROW(massProperties(plane, 1.0, 3, 1.0), std::invalid_argument);
}

}  // namespace
}  // namespace surge
