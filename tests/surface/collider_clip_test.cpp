// Tests of the water meeting colliders in the surface stage (surface/collider_clip.h, through surfaceFrames,
// as `surge surface` runs it): a block of water resting against a box, in a box container, on a floor plane;
// the colliders' level sets in the VDB; a moving collider's frame mesh; and a scene without colliders giving
// the same bytes as before colliders existed.
//
// Only openvdb/io/File.h is included here (to read the VDB back as other tools will), never OpenVDB's tools.
#include <gtest/gtest.h>
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>

#include "core/files.h"
#include "core/ply.h"
#include "geometry/collider_shape.h"
#include "core/progress.h"
#include "surface/surfacer.h"

namespace surge {
namespace {

constexpr double kH = 0.02, kVoxel = kH / 2;

Scene sceneWithSpacing(double h, const char* method = "spheres") {
  Scene scene;
  scene.name = "collider_clip_test";
  scene.dimensions = 3;
  scene.particle_spacing = h;
  scene.surface.method = method;
  scene.surface.particle_radius = h;  // the loader's defaults
  scene.surface.voxel_size = h / 2;
  return scene;
}

ColliderSettings collider(const std::string& name, const std::string& shape, int container = 0) {
  ColliderSettings c;
  c.name = name;
  c.shape = shape;
  c.container = container;
  return c;
}

struct Box {
  Eigen::Vector3d lo, hi;
  // Signed distance to the box (negative inside).
  double distance(const Eigen::Vector3d& x) const {
    const Eigen::Vector3d q = (lo - x).cwiseMax(x - hi);
    return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
  }
};

// A box's closed mesh as `surge sim` writes it: four vertices a face, normals out of the solid (or, for a
// container, turned in: into the fluid, the winding left as it is).
TriangleMesh boxColliderMesh(const Box& box, bool container = false) {
  TriangleMesh mesh = boxMesh((0.5 * (box.hi - box.lo)).cast<float>());  // geometry/: outward normals
  const Eigen::Vector3f centre = (0.5 * (box.hi + box.lo)).cast<float>();
  for (Eigen::Vector3f& p : mesh.positions) p += centre;
  if (container)
    for (Eigen::Vector3f& n : mesh.normals) n = -n;
  return mesh;
}

// The square a plane collider is drawn as, normals into the fluid.
TriangleMesh planeMesh(double y) {
  TriangleMesh mesh;
  mesh.positions = {{-5, float(y), -5}, {-5, float(y), 5}, {5, float(y), 5}, {5, float(y), -5}};
  mesh.normals.assign(4, Eigen::Vector3f::UnitY());
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  return mesh;
}

// A block of water filling `fluid`: a lattice of spacing h, the outer layers h/2 inside its faces, jittered
// by up to `jitter` spacings (a fixed hash) and kept h/2 inside the faces the colliders hold (as the
// simulator keeps particle centres a radius away from a collider).
ParticleFrame waterBlock(const Box& fluid, double h, double jitter) {
  ParticleFrame frame;
  const Eigen::Vector3i n = ((fluid.hi - fluid.lo) / h).array().round().cast<int>();
  for (int i = 0; i < n.x(); ++i)
    for (int j = 0; j < n.y(); ++j)
      for (int k = 0; k < n.z(); ++k) {
        Eigen::Vector3d x = fluid.lo + h * (Eigen::Vector3d(i, j, k) + Eigen::Vector3d::Constant(0.5));
        const size_t id = frame.position.size();
        for (int a = 0; a < 3; ++a) {
          const uint32_t bits = uint32_t(id * 2654435761u) ^ uint32_t((a + 1) * 40503u * (id + 7));
          x[a] += jitter * h * (double(bits % 2001) / 1000.0 - 1.0);
        }
        x = x.cwiseMax(fluid.lo + Eigen::Vector3d::Constant(h / 2))
                .cwiseMin(fluid.hi - Eigen::Vector3d::Constant(h / 2));
        frame.position.push_back(x.cast<float>());
        frame.velocity.push_back(Eigen::Vector3f::Zero());
        frame.id.push_back(uint32_t(id));
      }
  return frame;
}

fs::path uniqueTempDir(const std::string& suffix = "") {
  const auto* info = testing::UnitTest::GetInstance()->current_test_info();
  const fs::path dir = fs::path(testing::TempDir()) /
                       ("surge_colliders_" + std::to_string(::getpid()) + "_" + info->name() + suffix);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// An output folder as `surge sim` leaves it: frame 0 and each collider's mesh; then `surge surface` on it.
struct Surfaced {
  fs::path dir;
  TriangleMesh mesh;
  openvdb::FloatGrid::Ptr surface;
};

Surfaced surfaceFolder(const fs::path& dir, const Scene& scene, const ParticleFrame& frame,
                       const std::vector<std::pair<std::string, TriangleMesh>>& meshes) {
  writeParticlePly(framePath(dir, "particles", 0, "ply"), frame);
  for (const auto& [name, mesh] : meshes) writeMeshPly(dir / "colliders" / (name + ".ply"), mesh);
  Progress silent;
  surfaceFrames(dir, scene, FrameRange{}, silent);
  Surfaced run;
  run.dir = dir;
  run.mesh = readMeshPly(framePath(dir, "surface", 0, "ply"));
  openvdb::initialize();
  openvdb::io::File file(framePath(dir, "surface", 0, "vdb").string());
  file.open();
  run.surface = openvdb::gridPtrCast<openvdb::FloatGrid>(file.readGrid("surface"));
  file.close();
  return run;
}

// Trilinear, as the mesher and a renderer read the level set.
double sample(const openvdb::FloatGrid& grid, const Eigen::Vector3d& x) {
  const Eigen::Vector3d p = x / grid.voxelSize()[0];
  const Eigen::Vector3d f = p.array().floor(), t = p - f;
  const auto accessor = grid.getConstAccessor();
  double sum = 0;
  for (int c = 0; c < 8; ++c) {
    const Eigen::Vector3i o((c & 1), (c >> 1) & 1, c >> 2);
    double w = 1;
    for (int a = 0; a < 3; ++a) w *= o[a] ? t[a] : 1 - t[a];
    sum +=
        w *
        double(accessor.getValue(openvdb::Coord(int(f.x()) + o.x(), int(f.y()) + o.y(), int(f.z()) + o.z())));
  }
  return sum;
}

// Where the level set crosses zero on the segment a -> b (the first sign change in steps of a tenth of a
// voxel, then bisection); b if it never does.
Eigen::Vector3d crossing(const openvdb::FloatGrid& grid, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const int steps = int(std::ceil((b - a).norm() / (0.1 * kVoxel)));
  Eigen::Vector3d previous = a;
  const bool inside = sample(grid, a) < 0;
  for (int s = 1; s <= steps; ++s) {
    Eigen::Vector3d x = a + (b - a) * (double(s) / steps);
    if ((sample(grid, x) < 0) != inside) {
      for (int i = 0; i < 30; ++i) {
        const Eigen::Vector3d m = (previous + x) / 2;
        ((sample(grid, m) < 0) == inside ? previous : x) = m;
      }
      return (previous + x) / 2;
    }
    previous = x;
  }
  return b;
}

// The figures of water against the face x = wall of a collider, over the water's face there: the rectangle
// R of the water's own top, bottom and side faces (found 6 spacings from the wall, where the wall does not
// act).
//  - penetration: how deep the mesh's vertices lie in the collider (its exact distance), at most;
//  - levelSetInside: the level set's lowest value at points 0.1 to 3 voxels inside the collider over R
//    (negative: the level set holds water inside the collider);
//  - gap: the level set on the collider's face (there, the distance from the face to the water) over R, at
//    most, but for R's corners: squares 3 voxels a side where the water's own edges (top and side faces
//    meeting, rounded by the smoothing wherever they are) meet the wall;
//  - cornerGap: the same in those corners;
//  - retreat: how far the contact line (where the water comes within a tenth of a voxel of the wall) falls
//    short of R's edges, at most (R's corners left out likewise).
struct Contact {
  double penetration = 0, levelSetInside = 1e9, gap = 0, cornerGap = 0, retreat = 0;
};

Contact measureContact(const Surfaced& run, const Box& solid, const Box& fluid) {
  Contact m;
  for (const Eigen::Vector3f& x : run.mesh.positions)
    m.penetration = std::max(m.penetration, -solid.distance(x.cast<double>()));
  const double wall = solid.lo.x(), far = wall - 6 * kH;
  const auto& grid = *run.surface;
  const double mid = (fluid.lo.y() + fluid.hi.y()) / 2, midZ = (fluid.lo.z() + fluid.hi.z()) / 2;
  const double margin = 3 * kVoxel, step = 0.25 * kVoxel;
  const double top = crossing(grid, {far, mid, midZ}, {far, fluid.hi.y() + margin, midZ}).y();
  const double bottom = crossing(grid, {far, mid, midZ}, {far, fluid.lo.y() - margin, midZ}).y();
  const double front = crossing(grid, {far, mid, midZ}, {far, mid, fluid.lo.z() - margin}).z();
  const double back = crossing(grid, {far, mid, midZ}, {far, mid, fluid.hi.z() + margin}).z();
  const auto corner = [&](double y, double z) {
    return (y < bottom + margin || y > top - margin) && (z < front + margin || z > back - margin);
  };
  for (double y = bottom; y <= top; y += step)
    for (double z = front; z <= back; z += step) {
      double& gap = corner(y, z) ? m.cornerGap : m.gap;
      gap = std::max(gap, sample(grid, {wall, y, z}));
      for (double depth = 0.1; depth <= 3; depth += 0.3)
        m.levelSetInside = std::min(m.levelSetInside, sample(grid, {wall + depth * kVoxel, y, z}));
    }
  // The contact line: from beyond R's edge towards its middle, the first point of the wall the water reaches.
  const auto reach = [&](Eigen::Vector3d x, const Eigen::Vector3d& inward) {
    for (int s = 0; s < 200 && sample(grid, x) > 0.1 * kVoxel; ++s) x += inward * (0.05 * kVoxel);
    return x;
  };
  for (double z = front + margin; z <= back - margin; z += step) {
    m.retreat = std::max(m.retreat, top - reach({wall, top + margin, z}, -Eigen::Vector3d::UnitY()).y());
    m.retreat = std::max(m.retreat, reach({wall, bottom - margin, z}, Eigen::Vector3d::UnitY()).y() - bottom);
  }
  for (double y = bottom + margin; y <= top - margin; y += step) {
    m.retreat = std::max(m.retreat, reach({wall, y, front - margin}, Eigen::Vector3d::UnitZ()).z() - front);
    m.retreat = std::max(m.retreat, back - reach({wall, y, back + margin}, -Eigen::Vector3d::UnitZ()).z());
  }
  return m;
}

void print(const char* what, const Contact& m) {
  std::printf("%s: penetration %.3f, level set inside %.3f, gap %.3f (corners %.3f), retreat %.3f voxels\n",
              what, m.penetration / kVoxel, m.levelSetInside / kVoxel, m.gap / kVoxel, m.cornerGap / kVoxel,
              m.retreat / kVoxel);
}

// The water (12 x 10 x 10 particles, off the voxel lattice) resting against the face x = 0.3037 of a box
// that stands beyond it on every side.
const Box kFluid{{0.3037 - 12 * kH, 0.0013, 0.0021}, {0.3037, 0.0013 + 10 * kH, 0.0021 + 10 * kH}};
const Box kWall{{0.3037, -0.1, -0.1}, {0.5037, 0.4, 0.3}};

TEST(ColliderClip, WaterMeetsABoxWithoutGapOrOverlap) {
  for (const char* method : {"spheres", "smooth_spheres", "anisotropic"}) {
    SCOPED_TRACE(method);
    Scene scene = sceneWithSpacing(kH, method);
    const ParticleFrame water = waterBlock(kFluid, kH, 0.1);
    const Surfaced before = surfaceFolder(uniqueTempDir(std::string("_before_") + method), scene, water, {});
    scene.colliders = {collider("wall", "box")};
    const Surfaced after =
        surfaceFolder(uniqueTempDir(std::string("_") + method), scene, water, {{"wall", boxColliderMesh(kWall)}});
    const Contact without = measureContact(before, kWall, kFluid),
                  with = measureContact(after, kWall, kFluid);
    std::printf("%s\n", method);
    print("  without the collider", without);
    print("  with the collider   ", with);
    EXPECT_LE(with.penetration, 0.1 * kVoxel);
    EXPECT_GE(with.levelSetInside, -0.1 * kVoxel);
    EXPECT_LE(with.gap, kVoxel);
    EXPECT_LE(with.retreat, kVoxel);
    // The rest of the water is as it was: its faces away from the wall, and its volume to a few percent.
    EXPECT_GT(after.mesh.triangles.size(), 1000u);
  }
}

// A rigid body is met as a moving collider whose meshes are in bodies/ (core/scene.h's solidFiles): the same
// wall as a body, its mesh only in bodies/<name>/frame_00000.ply (bodies/<name>.ply stands elsewhere, so reading
// the wrong one shows), is met with the same figures as the collider above.
TEST(ColliderClip, WaterMeetsABodyAsItStandsAtTheFrame) {
  Scene scene = sceneWithSpacing(kH);
  BodySettings raft;
  raft.solid = collider("raft", "box");
  raft.density = 500;
  scene.bodies = {raft};
  const fs::path dir = uniqueTempDir();
  const Box elsewhere{{2, 2, 2}, {2.1, 2.1, 2.1}};
  writeMeshPly(dir / "bodies" / "raft.ply", boxColliderMesh(elsewhere));
  writeMeshPly(framePath(dir / "bodies", "raft", 0, "ply"), boxColliderMesh(kWall));
  const Surfaced run = surfaceFolder(dir, scene, waterBlock(kFluid, kH, 0.1), {});
  const Contact with = measureContact(run, kWall, kFluid);
  print("body", with);
  EXPECT_LE(with.penetration, 0.1 * kVoxel);
  EXPECT_GE(with.levelSetInside, -0.1 * kVoxel);
  EXPECT_LE(with.gap, kVoxel);
  EXPECT_LE(with.retreat, kVoxel);
}

TEST(ColliderClip, ContainerAndFloorPlaneHoldTheWater) {
  // The same water in a box container whose floor and three walls are the water's faces, and on a floor
  // plane: no vertex in the solid (outside the container, under the plane) deeper than a tenth of a voxel.
  const ParticleFrame water = waterBlock(kFluid, kH, 0.1);
  const Box container{{kFluid.lo.x(), kFluid.lo.y(), kFluid.lo.z()}, {kFluid.hi.x(), 0.4, 0.3}};
  Scene scene = sceneWithSpacing(kH);
  scene.colliders = {collider("tank", "box", 1)};
  const Surfaced held =
      surfaceFolder(uniqueTempDir("_container"), scene, water, {{"tank", boxColliderMesh(container, true)}});
  double outside = 0;
  for (const Eigen::Vector3f& x : held.mesh.positions)
    outside = std::max(outside, container.distance(x.cast<double>()));
  std::printf("container: deepest vertex in the solid %.3f voxels\n", outside / kVoxel);
  EXPECT_LE(outside, 0.1 * kVoxel);
  // The water reaches the container's floor and walls: the level set is <= 0 on them over the water's faces.
  EXPECT_LE(sample(*held.surface, {kFluid.lo.x() + 0.1, kFluid.lo.y(), 0.1}), 1e-4);
  EXPECT_LE(sample(*held.surface, {kFluid.lo.x(), 0.1, 0.1}), 1e-4);
  EXPECT_LE(sample(*held.surface, {kFluid.hi.x(), 0.1, 0.1}), 1e-4);

  scene.colliders = {collider("floor", "plane")};
  const Surfaced floor =
      surfaceFolder(uniqueTempDir("_plane"), scene, water, {{"floor", planeMesh(kFluid.lo.y())}});
  double below = 0;
  for (const Eigen::Vector3f& x : floor.mesh.positions)
    below = std::max(below, kFluid.lo.y() - double(x.y()));
  std::printf("plane: deepest vertex under it %.3f voxels\n", below / kVoxel);
  EXPECT_LE(below, 0.1 * kVoxel);
  EXPECT_LE(sample(*floor.surface, {0.2, kFluid.lo.y(), 0.1}), 1e-4);
}

std::string bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// Equal but for the 36 characters of the UUID that OpenVDB writes into every file's header.
void expectSameVdb(const fs::path& a, const fs::path& b) {
  const std::string x = bytes(a), y = bytes(b);
  ASSERT_EQ(x.size(), y.size());
  size_t first = x.size(), last = 0;
  for (size_t i = 0; i < x.size(); ++i)
    if (x[i] != y[i]) first = std::min(first, i), last = i;
  if (first < x.size()) {
    EXPECT_LT(last - first, 36u) << "first difference at byte " << first;
  }
}

TEST(ColliderClip, WithoutCollidersTheBytesAreTheSame) {
  // A scene without colliders takes the surfacer's path of before: a colliders/ folder it does not name is
  // never read, and the files are those of surfaceFrame (the function the stage called before colliders).
  const ParticleFrame water = waterBlock(kFluid, kH, 0.1);
  const Scene scene = sceneWithSpacing(kH);
  const Surfaced plain = surfaceFolder(uniqueTempDir("_plain"), scene, water, {});
  const Surfaced stray = surfaceFolder(uniqueTempDir("_stray"), scene, water, {{"wall", boxColliderMesh(kWall)}});
  const fs::path direct = uniqueTempDir("_direct");
  surfaceFrame(water, scene, direct / "frame.vdb", direct / "frame.ply");
  for (const Surfaced* run : {&plain, &stray}) {
    EXPECT_EQ(bytes(framePath(run->dir, "surface", 0, "ply")), bytes(direct / "frame.ply"));
    expectSameVdb(framePath(run->dir, "surface", 0, "vdb"), direct / "frame.vdb");
  }
  // A collider that the water does not reach leaves the mesh as it was (only the VDB gains its grid).
  Scene far = scene;
  far.colliders = {collider("far", "box")};
  const Box away{{2, 2, 2}, {2.2, 2.2, 2.2}};
  const Surfaced distant = surfaceFolder(uniqueTempDir("_far"), far, water, {{"far", boxColliderMesh(away)}});
  EXPECT_EQ(bytes(framePath(distant.dir, "surface", 0, "ply")), bytes(direct / "frame.ply"));
}

TEST(ColliderClip, VdbHoldsEachCollidersLevelSetAndAMovingOneIsReadAtItsFrame) {
  const ParticleFrame water = waterBlock(kFluid, kH, 0.1);
  Scene scene = sceneWithSpacing(kH);
  scene.colliders = {collider("wall", "box"), collider("floor", "plane"), collider("paddle", "box")};
  scene.colliders[2].motion.resize(2);  // moving: its frame files are read
  const Box paddleAtZero{{-0.5, 0, 0}, {-0.4, 0.2, 0.2}}, paddleAtFrame{{-0.3, 0, 0}, {-0.2, 0.2, 0.2}};
  const fs::path dir = uniqueTempDir();
  writeMeshPly(framePath(dir / "colliders", "paddle", 0, "ply"), boxColliderMesh(paddleAtFrame));
  const Surfaced run =
      surfaceFolder(dir, scene, water,
                    {{"wall", boxColliderMesh(kWall)}, {"floor", planeMesh(-1)}, {"paddle", boxColliderMesh(paddleAtZero)}});
  openvdb::io::File file(framePath(dir, "surface", 0, "vdb").string());
  file.open();
  std::vector<std::string> names;
  for (auto name = file.beginName(); name != file.endName(); ++name) names.push_back(name.gridName());
  // The water and a grid for every collider but the plane (a half-space has no narrow band).
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"collider_paddle", "collider_wall", "surface"}));
  const auto wall = openvdb::gridPtrCast<openvdb::FloatGrid>(file.readGrid("collider_wall"));
  const auto paddle = openvdb::gridPtrCast<openvdb::FloatGrid>(file.readGrid("collider_paddle"));
  file.close();
  ASSERT_TRUE(wall && paddle);
  EXPECT_EQ(wall->getGridClass(), openvdb::GRID_LEVEL_SET);
  EXPECT_NEAR(wall->voxelSize()[0], kVoxel, 1e-12);
  EXPECT_FALSE(wall->metaValue<bool>("container"));
  // A signed distance to the box: exact on the voxels near its face, negative inside, deep inside too.
  EXPECT_NEAR(sample(*wall, {kWall.lo.x() - 0.013, 0.1, 0.1}), 0.013, 1e-4);
  EXPECT_NEAR(sample(*wall, {kWall.lo.x() + 0.017, 0.1, 0.1}), -0.017, 1e-4);
  EXPECT_LT(sample(*wall, {0.4, 0.15, 0.1}), 0);
  // The paddle stands where its frame file puts it, not where <name>.ply does.
  EXPECT_NEAR(sample(*paddle, {paddleAtFrame.lo.x() - 0.012, 0.1, 0.1}), 0.012, 1e-4);
  EXPECT_GT(sample(*paddle, {-0.45, 0.1, 0.1}), 0);
}

TEST(ColliderClip, ResumeRedoesOnlyTheFramesWhoseMovingColliderChanged) {
  const fs::path dir = uniqueTempDir();
  Scene scene = sceneWithSpacing(kH);
  scene.colliders = {collider("wall", "box"), collider("paddle", "box")};
  scene.colliders[1].motion.resize(2);
  const Box paddle{{-0.3, 0, 0}, {-0.2, 0.2, 0.2}};
  for (int f = 0; f < 2; ++f) {
    writeParticlePly(framePath(dir, "particles", f, "ply"), waterBlock(kFluid, kH, 0.1));
    writeMeshPly(framePath(dir / "colliders", "paddle", f, "ply"), boxColliderMesh(paddle));
  }
  writeMeshPly(dir / "colliders" / "wall.ply", boxColliderMesh(kWall));
  writeMeshPly(dir / "colliders" / "paddle.ply", boxColliderMesh(paddle));
  std::ofstream(dir / "scene.json") << "{}\n";  // an input of every frame; its contents are not read here
  struct Counting : Progress {
    size_t total = 0;
    void start(const std::string&, size_t n) override { total = n; }
  } progress;
  surfaceFrames(dir, scene, FrameRange{}, progress, /*resume=*/true);
  EXPECT_EQ(progress.total, 2u);
  // `surge sim --resume` rewrites a standing collider's mesh (the same bytes): nothing to redo.
  const auto later = fs::last_write_time(framePath(dir, "surface", 1, "vdb")) + std::chrono::seconds(5);
  fs::last_write_time(dir / "colliders" / "wall.ply", later);
  surfaceFrames(dir, scene, FrameRange{}, progress, true);
  EXPECT_EQ(progress.total, 0u);
  // A moving collider's frame file newer than the frame's surface: that frame again.
  fs::last_write_time(framePath(dir / "colliders", "paddle", 1, "ply"), later);
  surfaceFrames(dir, scene, FrameRange{}, progress, true);
  EXPECT_EQ(progress.total, 1u);
}

}  // namespace
}  // namespace surge
