// The table of shapes: every kind a collider or body may be, by the name scene files give it, with the parts
// that take it, its builder and its mass properties. A new shape is its ShapeKind, an entry here (with its
// functions in shapes.cpp), its case in ColliderShape::distance (a switch, so a particle's distance costs no
// call through a pointer) and its Bullet shape in sim/rigid_bodies.cpp; the switches have no default and
// -Werror=switch makes a kind left out fail to compile. core/scene_fields.cpp's `shape` choices must list the
// same names (a test checks).
#pragma once

#include <array>
#include <string>

#include "geometry/collider_shape.h"
#include "geometry/mass_properties.h"

namespace surge {

// What a builder reads: the scene, the solid's settings, its key for errors and its size relative to the tank.
struct ShapeInput {
  const Scene& scene;
  const ColliderSettings& settings;
  const std::string& key;    // "colliders[2]", "bodies[0]"
  const std::string& where;  // the scene file
  bool body = false;
  float spacing = 0, support = 0, domainSize = 0;
};

struct ShapeType {
  const char* name;  // as a scene names it (`shape`)
  ShapeKind kind;
  bool collider, body, body2d;  // the parts that take it: a collider (2D or 3D), a body, a body in 2D
  // Fills the shape's parameters, its drawing mesh (outward normals), its bounds, and a mesh's grid.
  void (*build)(ColliderShape& shape, const ShapeInput& input);
  // Volume, centre and inertia at unit density, unscaled; in 2D of the cross-section at z = 0 (only the
  // moment about z). Null for a part that does not take it (no finite mass).
  MassProperties (*mass3d)(const ColliderShape& shape);
  MassProperties (*mass2d)(const ColliderShape& shape);
};

// Every kind, in ShapeKind's order.
const std::array<ShapeType, kShapeKinds>& shapeTypes();
const ShapeType& shapeType(ShapeKind kind);
// The shape a scene names `name`, or null.
const ShapeType* findShapeType(const std::string& name);

}  // namespace surge
