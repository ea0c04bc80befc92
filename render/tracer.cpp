#include "render/tracer.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <array>
#include <limits>
#include <mutex>
#include <string>
#include <vector>

#include "core/errors.h"
#include "render/shading.h"

namespace surge {

// Embree reports errors through a callback; the first message is kept and turned into a RunError by check().
struct RayDevice::Impl {
  RTCDevice device = nullptr;
  std::mutex mutex;
  std::string error;

  void check(const char* what) {
    std::lock_guard<std::mutex> lock(mutex);
    if (error.empty() && rtcGetDeviceError(device) == RTC_ERROR_NONE) return;
    const std::string message = "Embree failed while " + std::string(what) + ": " + error;
    error.clear();
    throw RunError(message);
  }
};

namespace {

void onEmbreeError(void* user, RTCError code, const char* text) {
  auto* impl = static_cast<RayDevice::Impl*>(user);
  std::lock_guard<std::mutex> lock(impl->mutex);
  if (impl->error.empty())
    impl->error = (text ? text : "") + std::string(" (error ") + std::to_string(code) + ")";
}

// Geometry ids; the water, the tank (render.tank "none") and empty colliders are left out, collider c is
// kFirstColliderId + c.
constexpr unsigned kGroundId = 0;
constexpr unsigned kTankId = 1;
constexpr unsigned kWaterId = 2;
constexpr unsigned kWhitewaterId = 3;
constexpr unsigned kFirstColliderId = 4;

// Ray masks: every object is seen by camera and reflection rays, but the tank's edges, a guide for the eye
// rather than a real frame, cast no shadows (their thin noisy shadow lines would only clutter the picture).
constexpr unsigned kSeen = 1u;
constexpr unsigned kCastsShadow = 2u;

struct Triangles {
  std::vector<Eigen::Vector3f> positions;
  std::vector<std::array<uint32_t, 3>> indices;

  // An axis-aligned box as 12 triangles (outward winding does not matter: shading faces normals forward).
  void addBox(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi) {
    const auto base = static_cast<uint32_t>(positions.size());
    for (int corner = 0; corner < 8; ++corner)
      positions.emplace_back(corner & 1 ? hi.x() : lo.x(), corner & 2 ? hi.y() : lo.y(),
                             corner & 4 ? hi.z() : lo.z());
    // Each face as four corners (bit patterns) around it.
    static const int faces[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1},
                                    {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
    for (const auto& f : faces) {
      indices.push_back({base + f[0], base + f[1], base + f[2]});
      indices.push_back({base + f[0], base + f[2], base + f[3]});
    }
  }
};

void attachTriangles(RTCDevice device, RTCScene scene, unsigned id, unsigned mask,
                     const std::vector<Eigen::Vector3f>& positions,
                     const std::vector<std::array<uint32_t, 3>>& indices) {
  RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(
      geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), positions.size()));
  auto* triangles = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(
      geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), indices.size()));
  if (vertices && triangles) {
    for (size_t i = 0; i < positions.size(); ++i)
      for (int k = 0; k < 3; ++k) vertices[3 * i + k] = positions[i][k];
    for (size_t i = 0; i < indices.size(); ++i)
      for (int k = 0; k < 3; ++k) triangles[3 * i + k] = indices[i][k];
  }
  rtcSetGeometryMask(geometry, mask);
  rtcCommitGeometry(geometry);
  rtcAttachGeometryByID(scene, geometry, id);
  rtcReleaseGeometry(geometry);
}

// Sets hit.normal to the mesh's vertex normals interpolated at (u, v) of `tri`, turned to the ray's side.
void smoothShading(const TriangleMesh& mesh, const std::array<uint32_t, 3>& tri, float u, float v, Hit& hit) {
  const auto& n = mesh.normals;
  const float weights[3] = {1.0f - u - v, u, v};
  const Eigen::Vector3f ns = weights[0] * n[tri[0]] + weights[1] * n[tri[1]] + weights[2] * n[tri[2]];
  const float length = ns.norm();
  if (length <= 1e-12f) return;
  const float side = ns.dot(hit.geometricNormal) < 0 ? -1.0f : 1.0f;
  hit.normal = side * ns / length;
  // Lift the leave point onto the curved surface the vertex normals describe (Hanika, "Hacking the shadow
  // terminator", Ray Tracing Gems II, 2021), so shadow rays of a coarse mesh do not catch the neighbouring
  // facets and draw its triangles as dark steps.
  Eigen::Vector3f lift = Eigen::Vector3f::Zero();
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3f vertexNormal = side * n[tri[k]];
    const float below = std::min(0.0f, (hit.point - mesh.positions[tri[k]]).dot(vertexNormal));
    lift -= weights[k] * below * vertexNormal;
  }
  hit.leavePoint += lift;
}

}  // namespace

RayDevice::RayDevice() : impl_(std::make_unique<Impl>()) {
  impl_->device = rtcNewDevice(nullptr);
  if (!impl_->device)
    throw RunError("Embree could not start (error " + std::to_string(rtcGetDeviceError(nullptr)) + ")");
  rtcSetDeviceErrorFunction(impl_->device, onEmbreeError, impl_.get());
}

RayDevice::~RayDevice() {
  rtcReleaseDevice(impl_->device);
}

struct RayScene::Impl {
  RTCScene scene = nullptr;
  const TriangleMesh* water = nullptr;
  const std::vector<ColliderMesh>* colliders = nullptr;
  const WhitewaterSpheres* whitewater = nullptr;
  std::vector<std::vector<std::array<uint32_t, 3>>> colliderTriangles;  // those drawn (trianglesFacing)
  bool smooth = false;
  SurfaceKind tank = SurfaceKind::TankEdge;
  ~Impl() {
    if (scene) rtcReleaseScene(scene);
  }
};

RayScene::RayScene(const RayDevice& device, const TriangleMesh& water, const Scene& scene)
    : RayScene(device, water, scene, noColliders()) {}

const std::vector<ColliderMesh>& RayScene::noColliders() {
  static const std::vector<ColliderMesh> none;
  return none;
}

RayScene::RayScene(const RayDevice& device, const TriangleMesh& water, const Scene& scene,
                   const std::vector<ColliderMesh>& colliders, const WhitewaterSpheres* whitewater)
    : impl_(std::make_unique<Impl>()) {
  const size_t vertexCount = water.positions.size();
  for (size_t t = 0; t < water.triangles.size(); ++t)
    for (uint32_t v : water.triangles[t])
      if (v >= vertexCount)
        throw InputError("water mesh", "triangle " + std::to_string(t),
                         "names vertex " + std::to_string(v) + " of " + std::to_string(vertexCount));
  impl_->water = &water;
  impl_->smooth = water.normals.size() == vertexCount;

  const Eigen::Vector3f lo = scene.domain.min.cast<float>(), hi = scene.domain.max.cast<float>();
  const float size = std::max((hi - lo).maxCoeff(), 1e-3f);
  offset_ = 1e-4f * size;

  RayDevice::Impl& dev = device.impl();
  impl_->scene = rtcNewScene(dev.device);

  // The ground: a square fifty tank sizes across, a hair below the floor so the water's bottom never fights
  // it.
  const Eigen::Vector3f centre = 0.5f * (lo + hi);
  const float half = 50.0f * size, floorY = lo.y() - 0.5f * offset_;
  attachTriangles(dev.device, impl_->scene, kGroundId, kSeen | kCastsShadow,
                  {{centre.x() - half, floorY, centre.z() - half},
                   {centre.x() + half, floorY, centre.z() - half},
                   {centre.x() + half, floorY, centre.z() + half},
                   {centre.x() - half, floorY, centre.z() + half}},
                  {{{0, 1, 2}}, {{0, 2, 3}}});

  if (scene.render.tank == "glass") {
    // The four side walls as thin glass panes (shading.cpp treats each as a slab of no thickness), a little
    // outside the domain so that the water's surface along a wall never coincides with them; the top is open
    // and the ground is the floor. They filter the sun, so they are in the shadow mask.
    impl_->tank = SurfaceKind::TankGlass;
    const float gap = 0.002f * size;
    const Eigen::Vector3f outerLo(lo.x() - gap, floorY, lo.z() - gap),
        outerHi(hi.x() + gap, hi.y(), hi.z() + gap);
    Triangles glass;
    for (int axis : {0, 2}) {
      const int across = 2 - axis;  // the other horizontal axis
      for (float at : {outerLo[axis], outerHi[axis]}) {
        if (!scene.hasWall(axis, at == outerHi[axis])) continue;  // an open or periodic face has no pane
        const auto base = static_cast<uint32_t>(glass.positions.size());
        for (int corner = 0; corner < 4; ++corner) {
          Eigen::Vector3f p;
          p[axis] = at;
          p[across] = (corner == 1 || corner == 2) ? outerHi[across] : outerLo[across];
          p.y() = corner >= 2 ? outerHi.y() : outerLo.y();
          glass.positions.push_back(p);
        }
        glass.indices.push_back({base, base + 1, base + 2});
        glass.indices.push_back({base, base + 2, base + 3});
      }
    }
    attachTriangles(dev.device, impl_->scene, kTankId, kSeen | kCastsShadow, glass.positions, glass.indices);
  } else if (scene.render.tank != "none") {
    // The tank's twelve edges as square bars of half-width r (corners overlap, which reads as a frame).
    const float r = 0.003f * size;
    Triangles tank;
    for (const auto& [p0, p1] : tankEdges(scene)) tank.addBox(p0.array() - r, p1.array() + r);
    if (!tank.indices.empty()) attachTriangles(dev.device, impl_->scene, kTankId, kSeen, tank.positions, tank.indices);
  }

  if (!water.triangles.empty())
    attachTriangles(dev.device, impl_->scene, kWaterId, kSeen | kCastsShadow, water.positions,
                    water.triangles);
  if (whitewater && !whitewater->empty()) {
    // Spray, foam and bubbles as Embree's sphere points: exact spheres, cheaper than meshes or a density volume
    // (docs/whitewater.md).
    impl_->whitewater = whitewater;
    RTCGeometry geometry = rtcNewGeometry(dev.device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
    auto* points = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0,
                                                               RTC_FORMAT_FLOAT4, 4 * sizeof(float),
                                                               whitewater->spheres.size()));
    if (points)
      for (size_t i = 0; i < whitewater->spheres.size(); ++i)
        for (int k = 0; k < 4; ++k) points[4 * i + k] = whitewater->spheres[i][k];
    rtcSetGeometryMask(geometry, kSeen | kCastsShadow);
    rtcCommitGeometry(geometry);
    rtcAttachGeometryByID(impl_->scene, geometry, kWhitewaterId);
    rtcReleaseGeometry(geometry);
  }
  impl_->colliders = &colliders;
  const Eigen::Vector3f camera = framedCamera(scene).position.cast<float>();
  for (size_t c = 0; c < colliders.size(); ++c) {
    impl_->colliderTriangles.push_back(trianglesFacing(colliders[c], camera));
    if (impl_->colliderTriangles.back().empty()) continue;
    attachTriangles(dev.device, impl_->scene, kFirstColliderId + unsigned(c), kSeen | kCastsShadow,
                    colliders[c].mesh.positions, impl_->colliderTriangles.back());
  }
  rtcCommitScene(impl_->scene);
  dev.check("building the scene");
}

RayScene::~RayScene() = default;

bool RayScene::intersect(const Ray& ray, float maxDistance, Hit& hit, bool shadowRay) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit query;
  query.ray.org_x = ray.origin.x();
  query.ray.org_y = ray.origin.y();
  query.ray.org_z = ray.origin.z();
  query.ray.dir_x = ray.direction.x();
  query.ray.dir_y = ray.direction.y();
  query.ray.dir_z = ray.direction.z();
  query.ray.tnear = 0.0f;
  query.ray.tfar = maxDistance;
  query.ray.time = 0.0f;
  query.ray.mask = shadowRay ? kCastsShadow : kSeen;
  query.ray.id = 0;
  query.ray.flags = 0;
  query.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  query.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(impl_->scene, &context, &query);
  if (query.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;

  const unsigned id = query.hit.geomID;
  const ColliderMesh* collider =
      id >= kFirstColliderId ? &(*impl_->colliders)[id - kFirstColliderId] : nullptr;
  hit.kind = id == kWaterId        ? SurfaceKind::Water
             : id == kTankId       ? impl_->tank
             : id == kWhitewaterId ? SurfaceKind::Whitewater
             : collider            ? SurfaceKind::Collider
                                   : SurfaceKind::Ground;
  if (hit.kind == SurfaceKind::Whitewater) hit.albedo = impl_->whitewater->albedo[query.hit.primID];
  hit.distance = query.ray.tfar;
  hit.point = ray.origin + hit.distance * ray.direction;
  Eigen::Vector3f ng(query.hit.Ng_x, query.hit.Ng_y, query.hit.Ng_z);
  ng.normalize();
  if (ng.dot(ray.direction) > 0) ng = -ng;
  hit.geometricNormal = ng;
  hit.normal = ng;
  hit.leavePoint = hit.point + offset_ * ng;
  hit.passPoint = hit.point - offset_ * ng;
  if (hit.kind == SurfaceKind::Water && !impl_->water->fluid.empty()) hit.fluid = impl_->water->fluid[query.hit.primID];
  if (hit.kind == SurfaceKind::Water && impl_->smooth)
    smoothShading(*impl_->water, impl_->water->triangles[query.hit.primID], query.hit.u, query.hit.v, hit);
  if (collider) {
    hit.albedo = collider->albedo;
    if (collider->mesh.normals.size() == collider->mesh.positions.size())
      smoothShading(collider->mesh, impl_->colliderTriangles[id - kFirstColliderId][query.hit.primID],
                    query.hit.u, query.hit.v, hit);
  }
  return true;
}

bool RayScene::occluded(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction,
                        float maxDistance) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay query;
  query.org_x = origin.x();
  query.org_y = origin.y();
  query.org_z = origin.z();
  query.dir_x = direction.x();
  query.dir_y = direction.y();
  query.dir_z = direction.z();
  query.tnear = 0.0f;
  query.tfar = maxDistance;
  query.time = 0.0f;
  query.mask = kCastsShadow;
  query.id = 0;
  query.flags = 0;
  rtcOccluded1(impl_->scene, &context, &query);
  return query.tfar < 0.0f;  // Embree sets tfar to -inf when something blocks the ray
}

}  // namespace surge
