#include "sim/rigid_bodies.h"

#include <btBulletDynamicsCommon.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "core/errors.h"
#include "core/files.h"
#include "geometry/shapes.h"

namespace surge {
namespace {

btVector3 toBullet(const Eigen::Vector3d& v) { return btVector3(v.x(), v.y(), v.z()); }
Eigen::Vector3d fromBullet(const btVector3& v) { return Eigen::Vector3d(v.x(), v.y(), v.z()); }
btQuaternion toBullet(const Eigen::Quaterniond& q) { return btQuaternion(q.x(), q.y(), q.z(), q.w()); }
Eigen::Quaterniond fromBullet(const btQuaternion& q) { return Eigen::Quaterniond(q.w(), q.x(), q.y(), q.z()); }

btTransform toBullet(const Pose& pose) {
  return btTransform(toBullet(pose.rotation), toBullet(pose.translation));
}

constexpr double kLongestBulletStep = 1e-3;  // s

// Bullet's contact margin: a tenth of the particle spacing (Bullet's default of 4 cm is larger than many bodies).
double contactMargin(const Scene& scene) { return 0.1 * scene.particle_spacing; }

// How Bullet holds each kind: a half-space, its own primitive, the triangles of the drawing mesh (static
// only), or the mesh's convex hull (a moving body).
enum class BulletShape { Plane, Primitive, Triangles, Hull };

// A collider of each kind (a container is its triangles, whatever its kind).
BulletShape colliderShape(ShapeKind kind) {
  switch (kind) {
    case ShapeKind::Plane: return BulletShape::Plane;
    case ShapeKind::Box:
    case ShapeKind::Sphere:
    case ShapeKind::Capsule:
    case ShapeKind::Cylinder: return BulletShape::Primitive;
    case ShapeKind::Heightfield:
    case ShapeKind::Mesh: return BulletShape::Triangles;
  }
  return BulletShape::Triangles;
}

// A body of each kind; one that Bullet cannot move (a half-space, a heightfield's open solid) is an InputError
// naming `key`.shape.
BulletShape bodyShape(ShapeKind kind, const std::string& where, const std::string& key) {
  switch (kind) {
    case ShapeKind::Box:
    case ShapeKind::Sphere:
    case ShapeKind::Capsule:
    case ShapeKind::Cylinder: return BulletShape::Primitive;
    case ShapeKind::Mesh: return BulletShape::Hull;
    case ShapeKind::Plane:
    case ShapeKind::Heightfield: break;
  }
  throw InputError(where, key + ".shape", std::string("a ") + shapeType(kind).name + " cannot be a body");
}

}  // namespace

void checkBodyShape(ShapeKind kind, const std::string& where, const std::string& key) {
  bodyShape(kind, where, key);
}

// Bullet's objects. Shapes live as long as RigidBodies; the world and its objects are rebuilt every frame.
struct RigidBodies::World {
  std::vector<std::unique_ptr<btCollisionShape>> shapes;
  std::vector<std::unique_ptr<btTriangleMesh>> triangles;
  std::vector<btCollisionShape*> bodyShapes;  // per body
  std::vector<btCollisionShape*> colliderShapes;  // per collider
  std::vector<btCollisionShape*> tankShapes;  // a slab beyond each wall
  std::vector<btTransform> tankPlaces;

  std::unique_ptr<btDefaultCollisionConfiguration> configuration;
  std::unique_ptr<btCollisionDispatcher> dispatcher;
  std::unique_ptr<btDbvtBroadphase> broadphase;
  std::unique_ptr<btSequentialImpulseConstraintSolver> solver;
  std::unique_ptr<btDiscreteDynamicsWorld> dynamics;
  std::vector<std::unique_ptr<btDefaultMotionState>> motionStates;
  std::vector<std::unique_ptr<btCollisionObject>> statics;
  std::vector<std::unique_ptr<btRigidBody>> bodies;
  std::vector<btRigidBody*> movingColliders;  // kinematic, per moving collider
  std::vector<size_t> movingColliderIndex;

  btCollisionShape* keep(btCollisionShape* shape, double margin) {
    shape->setMargin(margin);
    shapes.emplace_back(shape);
    return shape;
  }
  // A box, sphere, capsule or cylinder (along y) as Bullet's own shape, scaled; null for the other kinds.
  btCollisionShape* primitive(const ColliderShape& shape, double scale, double margin) {
    const double r = scale * shape.radius, h = scale * shape.halfHeight;
    switch (shape.kind) {
      case ShapeKind::Box: return keep(new btBoxShape(toBullet(scale * shape.halfExtents.cast<double>())), margin);
      case ShapeKind::Sphere: return keep(new btSphereShape(r), margin);
      case ShapeKind::Capsule: return keep(new btCapsuleShape(r, 2 * h), margin);
      case ShapeKind::Cylinder: return keep(new btCylinderShape(btVector3(r, h, r)), margin);
      case ShapeKind::Plane:
      case ShapeKind::Heightfield:
      case ShapeKind::Mesh: return nullptr;
    }
    return nullptr;
  }
  btCollisionShape* triangleMesh(const TriangleMesh& mesh, double scale, double margin) {
    auto soup = std::make_unique<btTriangleMesh>();
    for (const auto& t : mesh.triangles)
      soup->addTriangle(toBullet(scale * mesh.positions[t[0]].cast<double>()),
                        toBullet(scale * mesh.positions[t[1]].cast<double>()),
                        toBullet(scale * mesh.positions[t[2]].cast<double>()));
    btCollisionShape* shape = new btBvhTriangleMeshShape(soup.get(), true);
    triangles.push_back(std::move(soup));
    return keep(shape, margin);
  }
  void clear() {
    if (dynamics) {
      for (auto& b : bodies) dynamics->removeRigidBody(b.get());
      for (btRigidBody* b : movingColliders) dynamics->removeRigidBody(b);
      for (auto& s : statics) dynamics->removeCollisionObject(s.get());
    }
    movingColliders.clear();
    movingColliderIndex.clear();
    bodies.clear();
    statics.clear();
    motionStates.clear();
    dynamics.reset();
    solver.reset();
    broadphase.reset();
    dispatcher.reset();
    configuration.reset();
  }
  ~World() { clear(); }
};

RigidBodies::RigidBodies(const Scene& scene, std::shared_ptr<const ColliderShapes> shapes)
    : scene_(scene), shapes_(std::move(shapes)), world_(std::make_unique<World>()) {
  if (scene.bodies.empty()) return;
  if (!shapes_) shapes_ = buildColliderShapes(scene);
  const double margin = contactMargin(scene);
  const std::string where = scene.source.empty() ? "scene" : scene.source;
  World& w = *world_;
  const size_t first = scene.colliders.size();
  // The tank: a slab beyond each wall, as thick as the domain is wide.
  const Eigen::Vector3d lo = scene.domain.min, hi = scene.domain.max;
  Eigen::Vector3d extent = hi - lo;
  if (scene.dimensions == 2) extent.z() = std::max(extent.x(), extent.y());
  const double thick = extent.maxCoeff();
  for (int k = 0; k < scene.dimensions; ++k)
    for (int side = 0; side < 2; ++side) {
      Eigen::Vector3d half = 0.5 * extent + Eigen::Vector3d::Constant(thick);
      half[k] = 0.5 * thick;
      Eigen::Vector3d centre = 0.5 * (lo + hi);
      if (scene.dimensions == 2) centre.z() = 0;
      centre[k] = side == 0 ? lo[k] - 0.5 * thick : hi[k] + 0.5 * thick;
      w.tankShapes.push_back(w.keep(new btBoxShape(toBullet(half)), margin));
      w.tankPlaces.emplace_back(btQuaternion::getIdentity(), toBullet(centre));
    }
  // The colliders: planes as planes, solid primitives as themselves, containers, heightfields and meshes as
  // their triangles.
  for (size_t c = 0; c < scene.colliders.size(); ++c) {
    const ColliderShape& shape = (*shapes_)[c];
    const double scale = scene.colliders[c].scale;
    btCollisionShape* s = nullptr;
    switch (colliderShape(shape.kind)) {
      case BulletShape::Plane:
        s = w.keep(new btStaticPlaneShape(toBullet(shape.planeNormal.cast<double>()), 0), margin);
        break;
      case BulletShape::Primitive:
        s = shape.container ? w.triangleMesh(shape.mesh, scale, margin) : w.primitive(shape, scale, margin);
        break;
      case BulletShape::Triangles:
      case BulletShape::Hull:
        s = w.triangleMesh(shape.mesh, scale, margin);
        break;
    }
    w.colliderShapes.push_back(s);
  }
  // The bodies: their mass properties, their principal frames, their shapes in those frames.
  for (size_t b = 0; b < scene.bodies.size(); ++b) {
    const BodySettings& settings = scene.bodies[b];
    const ColliderShape& shape = (*shapes_)[first + b];
    const bool asHull = bodyShape(shape.kind, where, "bodies[" + std::to_string(b) + "]") == BulletShape::Hull;
    const double scale = settings.solid.scale;
    MassProperties m = surge::massProperties(shape, scale, scene.dimensions, 1.0);
    const double density = settings.density > 0 ? settings.density : settings.mass / m.volume;
    m.mass *= density;  // mass and inertia are linear in the density
    m.inertia *= density;
    Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();
    if (shape.kind == ShapeKind::Mesh) {
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(m.inertia);
      axes = eigen.eigenvectors();
      if (axes.determinant() < 0) axes.col(2) = -axes.col(2);
      m.inertia = eigen.eigenvalues().asDiagonal();
    }
    btCollisionShape* s = nullptr;
    if (!asHull) {
      s = w.primitive(shape, scale, margin);
    } else {
      // A mesh collides as its convex hull, in the principal frame about the centre of mass.
      auto* hull = new btConvexHullShape();
      for (const Eigen::Vector3f& p : shape.mesh.positions)
        hull->addPoint(toBullet(axes.transpose() * (scale * p.cast<double>() - m.centre)), false);
      hull->recalcLocalAabb();
      s = w.keep(hull, margin);
    }
    w.bodyShapes.push_back(s);
    // The largest sphere about the centre inside the body (the hull's nearest face for a mesh).
    double inner = 0;
    if (shape.kind == ShapeKind::Box) inner = scale * shape.halfExtents.head(scene.dimensions).minCoeff();
    else if (shape.kind == ShapeKind::Mesh) inner = 0.5 * scale * shape.bounds.sizes().minCoeff();
    else inner = scale * shape.radius;
    innerRadius_.push_back(inner);
    mass_.push_back(m);
    principal_.push_back(axes);

    BodyState state;
    const Pose start = colliderPose(settings.solid, 0.0);
    state.orientation = start.rotation;
    state.position = start.translation + start.rotation * m.centre;
    state.velocity = settings.velocity;
    state.angularVelocity = settings.angular_velocity;
    states_.push_back(state);
  }
  beginFrame(0.0);
  // Bodies that overlap at the start would be thrown apart by the contact solver: a mistake in the scene.
  w.dynamics->performDiscreteCollisionDetection();
  btDispatcher* dispatcher = w.dynamics->getDispatcher();
  const double overlap = 0.25 * scene.particle_spacing;
  for (int i = 0; i < dispatcher->getNumManifolds(); ++i) {
    btPersistentManifold* manifold = dispatcher->getManifoldByIndexInternal(i);
    const auto* a = btRigidBody::upcast(manifold->getBody0());
    const auto* c = btRigidBody::upcast(manifold->getBody1());
    if (!a || !c || a->getUserIndex() < 0 || c->getUserIndex() < 0) continue;
    for (int p = 0; p < manifold->getNumContacts(); ++p)
      if (manifold->getContactPoint(p).getDistance() < -overlap) {
        const int later = std::max(a->getUserIndex(), c->getUserIndex());
        const int earlier = std::min(a->getUserIndex(), c->getUserIndex());
        throw InputError(scene.source.empty() ? "scene" : scene.source, "bodies[" + std::to_string(later) + "]",
                         "overlaps bodies[" + std::to_string(earlier) + "] at the start");
      }
  }
}

RigidBodies::~RigidBodies() = default;

void RigidBodies::setStates(const std::vector<BodyState>& states) {
  states_ = states;
}

Pose RigidBodies::pose(size_t b) const {
  Pose pose;
  pose.rotation = states_[b].orientation;
  pose.scale = scene_.bodies[b].solid.scale;
  pose.translation = states_[b].position - states_[b].orientation * mass_[b].centre;
  return pose;
}

void RigidBodies::beginFrame(double time) {
  if (empty()) return;
  World& w = *world_;
  w.clear();
  w.configuration = std::make_unique<btDefaultCollisionConfiguration>();
  w.dispatcher = std::make_unique<btCollisionDispatcher>(w.configuration.get());
  w.broadphase = std::make_unique<btDbvtBroadphase>();
  w.solver = std::make_unique<btSequentialImpulseConstraintSolver>();
  w.dynamics = std::make_unique<btDiscreteDynamicsWorld>(w.dispatcher.get(), w.broadphase.get(), w.solver.get(),
                                                         w.configuration.get());
  w.dynamics->setGravity(toBullet(scene_.gravity));

  // The tank's slabs.
  for (size_t k = 0; k < w.tankShapes.size(); ++k) {
    auto object = std::make_unique<btCollisionObject>();
    object->setCollisionShape(w.tankShapes[k]);
    object->setWorldTransform(w.tankPlaces[k]);
    object->setFriction(1);
    object->setRestitution(1);
    object->setUserIndex(-1);
    w.dynamics->addCollisionObject(object.get());
    w.statics.push_back(std::move(object));
  }
  // The colliders, standing or moved by their keyframes (kinematic).
  for (size_t c = 0; c < scene_.colliders.size(); ++c) {
    const ColliderSettings& settings = scene_.colliders[c];
    const btTransform at = toBullet(colliderPose(settings, time));
    if (isMoving(settings)) {
      w.motionStates.push_back(std::make_unique<btDefaultMotionState>(at));
      btRigidBody::btRigidBodyConstructionInfo info(0, w.motionStates.back().get(), w.colliderShapes[c]);
      auto body = std::make_unique<btRigidBody>(info);
      body->setCollisionFlags(body->getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT);
      body->setActivationState(DISABLE_DEACTIVATION);
      body->setFriction(1);
      body->setRestitution(1);
      body->setUserIndex(-1);
      w.dynamics->addRigidBody(body.get());
      w.movingColliders.push_back(body.get());
      w.movingColliderIndex.push_back(c);
      w.statics.emplace_back(body.release());
    } else {
      auto object = std::make_unique<btCollisionObject>();
      object->setCollisionShape(w.colliderShapes[c]);
      object->setWorldTransform(at);
      object->setFriction(1);
      object->setRestitution(1);
      object->setUserIndex(-1);
      w.dynamics->addCollisionObject(object.get());
      w.statics.push_back(std::move(object));
    }
  }
  // The bodies, from their state.
  for (size_t b = 0; b < states_.size(); ++b) {
    const BodyState& s = states_[b];
    const MassProperties& m = mass_[b];
    const Eigen::Vector3d inertia = m.inertia.diagonal();
    btRigidBody::btRigidBodyConstructionInfo info(m.mass, nullptr, w.bodyShapes[b], toBullet(inertia));
    info.m_friction = scene_.bodies[b].solid.friction;
    info.m_restitution = scene_.bodies[b].restitution;
    info.m_linearDamping = info.m_angularDamping = 0;
    auto body = std::make_unique<btRigidBody>(info);
    const Eigen::Quaterniond principal(s.orientation.toRotationMatrix() * principal_[b]);
    body->setWorldTransform(btTransform(toBullet(principal), toBullet(s.position)));
    body->setLinearVelocity(toBullet(s.velocity));
    body->setAngularVelocity(toBullet(s.angularVelocity));
    body->setActivationState(DISABLE_DEACTIVATION);  // a body at rest still feels the water
    body->setUserIndex(int(b));
    // Continuous collision for a fast body: a step that would carry it further than half its smallest extent
    // stops at the first contact instead of sinking deep into a wall and being pushed back out over later steps.
    body->setCcdMotionThreshold(0.5 * innerRadius_[b]);
    body->setCcdSweptSphereRadius(0.8 * innerRadius_[b]);
    if (scene_.dimensions == 2) {
      body->setLinearFactor(btVector3(1, 1, 0));
      body->setAngularFactor(btVector3(0, 0, 1));
      // In 2D only the moment about z counts; Bullet gets it on every axis, which the factors then ignore.
      body->setMassProps(m.mass, btVector3(inertia.z(), inertia.z(), inertia.z()));
    }
    w.dynamics->addRigidBody(body.get());
    w.bodies.push_back(std::move(body));
  }
}

long RigidBodies::step(double time, double dt) {
  World& w = *world_;
  for (size_t k = 0; k < w.movingColliders.size(); ++k)
    w.movingColliders[k]->getMotionState()->setWorldTransform(
        toBullet(colliderPose(scene_.colliders[w.movingColliderIndex[k]], time + dt)));
  // Bullet steps of at most a millisecond: a body meeting a wall at speed sinks into it by about its speed times
  // the step before the contact pushes it out, and the water caught between would end inside it. Each is one
  // step of its own (no time carried over between calls, so a world rebuilt at a frame steps the same).
  const int pieces = std::max(1, int(std::ceil(dt / kLongestBulletStep - 1e-9)));
  for (int piece = 0; piece < pieces; ++piece) {
    for (size_t b = 0; b < states_.size(); ++b) {
      w.bodies[b]->applyCentralForce(toBullet(states_[b].fluid.force));
      w.bodies[b]->applyTorque(toBullet(states_[b].fluid.torque));
    }
    w.dynamics->stepSimulation(dt / pieces, 0);
  }
  long bad = -1;
  for (size_t b = 0; b < states_.size(); ++b) {
    const btRigidBody& body = *w.bodies[b];
    BodyState& s = states_[b];
    const btTransform& t = body.getWorldTransform();
    s.position = fromBullet(t.getOrigin());
    s.orientation = Eigen::Quaterniond(fromBullet(t.getRotation()).toRotationMatrix() * principal_[b].transpose());
    s.orientation.normalize();
    s.velocity = fromBullet(body.getLinearVelocity());
    s.angularVelocity = fromBullet(body.getAngularVelocity());
    if (bad < 0 && !(s.position.allFinite() && s.velocity.allFinite() && s.angularVelocity.allFinite() &&
                     s.orientation.coeffs().allFinite()))
      bad = long(b);
  }
  return bad;
}

void RigidBodies::setFluidWrenches(const std::vector<Wrench>& solids, size_t firstBody) {
  for (size_t b = 0; b < states_.size(); ++b) states_[b].fluid = solids[firstBody + b];
}

void writeBodyStates(const fs::path& path, const Scene& scene, const std::vector<BodyState>& states) {
  writeFileAtomically(path, [&](std::ostream& out) {
    for (size_t b = 0; b < states.size(); ++b) {
      const BodyState& s = states[b];
      const Eigen::Quaterniond& q = s.orientation;
      const double values[] = {s.position.x(), s.position.y(), s.position.z(), q.w(), q.x(), q.y(), q.z(),
                               s.velocity.x(), s.velocity.y(), s.velocity.z(), s.angularVelocity.x(),
                               s.angularVelocity.y(), s.angularVelocity.z(), s.fluid.force.x(),
                               s.fluid.force.y(), s.fluid.force.z(), s.fluid.torque.x(), s.fluid.torque.y(),
                               s.fluid.torque.z()};
      out << scene.bodies[b].solid.name;
      char number[64];
      for (double v : values) {
        std::snprintf(number, sizeof number, " %a", v);
        out << number;
      }
      out << "\n";
    }
  });
}

std::vector<BodyState> readBodyStates(const fs::path& path, const Scene& scene) {
  std::istringstream in(readTextFile(path));
  std::vector<BodyState> states;
  std::string line;
  for (size_t b = 0; b < scene.bodies.size(); ++b) {
    if (!std::getline(in, line)) throw InputError(path.string(), "bodies", "has fewer bodies than the scene");
    std::istringstream fields(line);
    std::string name;
    fields >> name;
    if (name != scene.bodies[b].solid.name)
      throw InputError(path.string(), "bodies", "line " + std::to_string(b + 1) + " is not body '" +
                                                    scene.bodies[b].solid.name + "'");
    double v[19];
    for (double& value : v) {
      std::string token;
      fields >> token;
      char* end = nullptr;
      value = std::strtod(token.c_str(), &end);
      if (token.empty() || *end != '\0')
        throw InputError(path.string(), "bodies", "line " + std::to_string(b + 1) + " is cut short");
    }
    BodyState s;
    s.position = Eigen::Vector3d(v[0], v[1], v[2]);
    s.orientation = Eigen::Quaterniond(v[3], v[4], v[5], v[6]);
    s.velocity = Eigen::Vector3d(v[7], v[8], v[9]);
    s.angularVelocity = Eigen::Vector3d(v[10], v[11], v[12]);
    s.fluid.force = Eigen::Vector3d(v[13], v[14], v[15]);
    s.fluid.torque = Eigen::Vector3d(v[16], v[17], v[18]);
    states.push_back(s);
  }
  return states;
}

}  // namespace surge
