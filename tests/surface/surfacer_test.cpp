// Tests of surface/surfacer.h: the level set and mesh of known particle shapes (a ball, a block, a slab),
// closedness and orientation of the mesh, the VDB file's grid, and the edge cases of 0 and 1 particles.
//
// Only openvdb/io/File.h is included here (to read the VDB back as other tools will), never OpenVDB's tools.
// The program links OpenVDB through surge_surface, a static library whose private link dependencies CMake
// carries onto the link line of its users; OpenVDB's headers sit in /usr/include.
#include "surface/surfacer.h"

#include <gtest/gtest.h>
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <utility>

#include "core/errors.h"
#include "core/parallel.h"
#include "tests/core/scene_choices.h"

namespace surge {
namespace {

constexpr double kPi = 3.14159265358979323846;

Scene sceneWithSpacing(double h, int dimensions = 3, const char* method = "spheres") {
  Scene scene;
  scene.surface.method = method;
  scene.name = "surfacer_test";
  scene.dimensions = dimensions;
  scene.particle_spacing = h;
  scene.surface.particle_radius = h;  // the loader's default
  scene.surface.voxel_size = h / 2;   // the loader's default
  scene.surface.adaptivity = 0;
  return scene;
}

void add(ParticleFrame& frame, const Eigen::Vector3f& x) {
  frame.position.push_back(x);
  frame.velocity.push_back(Eigen::Vector3f::Zero());
  frame.id.push_back(uint32_t(frame.id.size()));
}

// Lattice points of spacing h within radius R of `centre`.
ParticleFrame ball(const Eigen::Vector3d& centre, double R, double h) {
  ParticleFrame frame;
  const int n = int(std::ceil(R / h));
  for (int i = -n; i <= n; ++i)
    for (int j = -n; j <= n; ++j)
      for (int k = -n; k <= n; ++k) {
        const Eigen::Vector3d d = h * Eigen::Vector3d(i, j, k);
        if (d.norm() <= R) add(frame, (centre + d).cast<float>());
      }
  return frame;
}

// An nx x ny x nz lattice of spacing h whose first particle sits at `origin`; nz = 1 and dimensions 2 for 2D.
ParticleFrame block(int nx, int ny, int nz, double h, const Eigen::Vector3d& origin, int dimensions = 3) {
  ParticleFrame frame;
  frame.dimensions = dimensions;
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      for (int k = 0; k < nz; ++k) add(frame, (origin + h * Eigen::Vector3d(i, j, k)).cast<float>());
  return frame;
}

// Signed volume by the divergence theorem: positive for a closed mesh wound counter-clockwise from outside.
double signedVolume(const TriangleMesh& mesh) {
  double volume = 0;
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.positions[t[0]].cast<double>(), b = mesh.positions[t[1]].cast<double>(),
                          c = mesh.positions[t[2]].cast<double>();
    volume += a.dot(b.cross(c)) / 6;
  }
  return volume;
}

// Closed and consistently oriented: every directed edge occurs once and its reverse once, so each edge is
// shared by exactly two triangles that traverse it in opposite directions.
void expectClosedAndOriented(const TriangleMesh& mesh) {
  std::map<std::pair<uint32_t, uint32_t>, int> directed;
  for (const auto& t : mesh.triangles)
    for (int e = 0; e < 3; ++e) ++directed[{t[e], t[(e + 1) % 3]}];
  size_t bad = 0;
  for (const auto& [edge, count] : directed) {
    const auto reverse = directed.find({edge.second, edge.first});
    if (count != 1 || reverse == directed.end() || reverse->second != 1) ++bad;
  }
  EXPECT_EQ(bad, 0u) << "of " << directed.size() << " directed edges";
  for (const auto& t : mesh.triangles)
    for (uint32_t v : t) ASSERT_LT(v, mesh.positions.size());
}

void expectUnitNormals(const TriangleMesh& mesh) {
  ASSERT_EQ(mesh.normals.size(), mesh.positions.size());
  for (const auto& n : mesh.normals) ASSERT_NEAR(n.norm(), 1.0, 1e-4);
}

fs::path uniqueTempDir() {
  const auto* info = testing::UnitTest::GetInstance()->current_test_info();
  const fs::path dir =
      fs::path(testing::TempDir()) / ("surge_surface_" + std::to_string(::getpid()) + "_" + info->name());
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// The checks of a ball of particles, for any surface.method (see BallOfParticlesGivesASphereOfTheFluidsVolume
// and EveryMethodGivesABallOfTheFluidsVolume).
void expectBallOfTheFluidsVolume(const char* method) {
  SCOPED_TRACE(method);
  const double h = 0.02, R = 0.2, voxel = h / 2;
  const Eigen::Vector3d centre(0.013, 0.5, -0.21);  // off the voxel lattice on purpose
  const ParticleFrame frame = ball(centre, R, h);
  const Scene scene = sceneWithSpacing(h, 3, method);
  // Each particle stands for h^3 of fluid: the ball of the same volume has radius (3N / 4 pi)^(1/3) h
  // (0.19968 for the 4169 particles here, within 0.2% of R).
  const double expected = std::cbrt(3.0 * double(frame.size()) / (4 * kPi)) * h;
  const TriangleMesh mesh = meshParticles(frame, scene);
  ASSERT_GT(mesh.triangles.size(), 1000u);
  double sum = 0, lo = 1e9, hi = 0;
  for (const auto& x : mesh.positions) {
    const double r = (x.cast<double>() - centre).norm();
    sum += r;
    lo = std::min(lo, r);
    hi = std::max(hi, r);
  }
  const double mean = sum / double(mesh.positions.size());
  testing::Test::RecordProperty(std::string("mean_radius_error_voxels_") + method,
                                std::to_string((mean - expected) / voxel));
  std::printf(
      "ball (%s): N=%zu expected radius %.5f, mesh mean %.5f (error %.3f voxels), min %.5f max %.5f\n",
      method, frame.size(), expected, mean, (mean - expected) / voxel, lo, hi);
  // One voxel: the erosion is calibrated on flat lattice faces, whereas the ball's surface is a staircase of
  // lattice layers whose steps are a spacing (two voxels) high. Measured: +0.27 voxels (spheres),
  // +0.20 (smooth_spheres), -0.14 (anisotropic).
  EXPECT_NEAR(mean, expected, voxel);
  // Round: after smoothing no vertex strays more than 1.5 voxels (3/4 of a spacing, the height of the
  // staircase steps of the lattice ball) from the mean radius.
  EXPECT_GT(lo, mean - 1.5 * voxel);
  EXPECT_LT(hi, mean + 1.5 * voxel);
  expectClosedAndOriented(mesh);
  EXPECT_GT(signedVolume(mesh), 0);
  expectUnitNormals(mesh);
  // Normals point outward, away from the centre.
  size_t inward = 0;
  for (size_t i = 0; i < mesh.positions.size(); ++i)
    if (mesh.normals[i].cast<double>().dot(mesh.positions[i].cast<double>() - centre) <= 0) ++inward;
  EXPECT_EQ(inward, 0u);

  // The level set itself: zero on the sphere (within the voxel of the mesh), negative inside, the narrow
  // band's background (+3 voxels) far outside.
  const Eigen::Vector3d onSurface = centre + Eigen::Vector3d(expected, 0, 0);
  const std::vector<double> phi =
      signedDistancesAt(frame, scene, {onSurface, centre, centre + Eigen::Vector3d(0, 1, 0)});
  EXPECT_NEAR(phi[0], 0.0, voxel);
  EXPECT_LT(phi[1], 0.0);
  EXPECT_NEAR(phi[2], 3 * voxel, 1e-6);
}

TEST(Surfacer, EveryMethodASceneMayNameIsInTheTableAndNoOther) {
  EXPECT_EQ(sceneChoices("surface.method"), surfaceMethods());
}

// A Scene made in code may name any method; one not in the table is refused naming the key.
TEST(Surfacer, AnUnknownMethodIsAnInputErrorNamingTheKey) {
  const ParticleFrame frame = block(4, 4, 4, 0.02, Eigen::Vector3d(0.1, 0.1, 0.1));
  try {
    meshParticles(frame, sceneWithSpacing(0.02, 3, "metaballs"));
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("surface.method"), std::string::npos) << e.what();
  }
}

TEST(Surfacer, BallOfParticlesGivesASphereOfTheFluidsVolume) {
  expectBallOfTheFluidsVolume("spheres");
}

TEST(Surfacer, RestingBlockEnclosesItsFluidVolumeAndIsClosed) {
  const double h = 0.02;
  const ParticleFrame frame = block(20, 10, 10, h, Eigen::Vector3d(0.11, 0.01, 0.01));
  const Scene scene = sceneWithSpacing(h);
  const TriangleMesh mesh = meshParticles(frame, scene);
  const double fluid = double(frame.size()) * h * h * h;
  const double volume = signedVolume(mesh);
  std::printf("block: N=%zu fluid volume %.6g, mesh volume %.6g (error %.2f%%), %zu triangles\n",
              frame.size(), fluid, volume, 100 * (volume / fluid - 1), mesh.triangles.size());
  // 3%: for this 20x10x10 block the area is 1000 h^2 against 2000 h^3 of volume, so 3% is a face 0.06 h
  // (an eighth of a voxel) off on average, or the 160 h of edges rounded to a radius of about 1.3 h
  // ((1 - pi/4) r^2 lost per unit length). Measured: -1.75%, the faces within 0.001 h (the next test), the
  // loss at the edges.
  EXPECT_NEAR(volume / fluid, 1.0, 0.03);
  expectClosedAndOriented(mesh);
  expectUnitNormals(mesh);
}

// A shape the surfacers' constants were not calibrated on (they were set on the axis-aligned block above): a slab
// of 24 x 24 x 6 lattice points whose lattice is turned 30 degrees about z and then 20 about x, so that its faces
// cross the voxel grid at a slant and its layers are not voxel planes.
TEST(Surfacer, SlantedSlabEnclosesItsVolumeWithFlatFacesAtTheFluidsFace) {
  const double h = 0.02;
  const Eigen::Matrix3d turn = (Eigen::AngleAxisd(20 * kPi / 180, Eigen::Vector3d::UnitX()) *
                                Eigen::AngleAxisd(30 * kPi / 180, Eigen::Vector3d::UnitZ()))
                                   .toRotationMatrix();
  const Eigen::Vector3d centre(0.0137, 0.2, -0.31);
  const int n[3] = {24, 24, 6};  // the slab's thin axis is the lattice's z
  ParticleFrame frame;
  for (int i = 0; i < n[0]; ++i)
    for (int j = 0; j < n[1]; ++j)
      for (int k = 0; k < n[2]; ++k) {
        const Eigen::Vector3d local = h * Eigen::Vector3d(i - (n[0] - 1) / 2.0, j - (n[1] - 1) / 2.0, k - (n[2] - 1) / 2.0);
        add(frame, (centre + turn * local).cast<float>());
      }
  const double fluid = double(frame.size()) * h * h * h, halfThickness = 3 * h;
  // `anisotropic` made an open mesh here (96 unpaired edges) with a lump up to 6 spacings above the top face,
  // until its raw grid kept every block (particle_field.cpp).
  for (const char* method : {"spheres", "smooth_spheres", "anisotropic"}) {
    SCOPED_TRACE(method);
    const TriangleMesh mesh = meshParticles(frame, sceneWithSpacing(h, 3, method));
    expectClosedAndOriented(mesh);
    const double volume = signedVolume(mesh);
    // The faces: vertices over the slab's middle (3 spacings or more in from its edges) sit on its two faces,
    // 3 spacings either side of the mid-plane.
    double offsetSum = 0, worst = 0;
    size_t faceVertices = 0;
    for (const auto& x : mesh.positions) {
      const Eigen::Vector3d local = turn.transpose() * (x.cast<double>() - centre);
      if (std::abs(local.x()) > 9 * h || std::abs(local.y()) > 9 * h) continue;
      const double offset = std::abs(local.z()) - halfThickness;
      offsetSum += offset;
      worst = std::max(worst, std::abs(offset));
      ++faceVertices;
    }
    const double meanOffset = offsetSum / double(faceVertices);
    std::printf("slanted slab (%s): N=%zu volume error %.2f%%, %zu face vertices %.4f spacings off the face on "
                "average, %.3f at worst\n",
                method, frame.size(), 100 * (volume / fluid - 1), faceVertices, meanOffset / h, worst / h);
    ASSERT_GT(faceVertices, 100u);
    // The faces where the fluid's are, to a quarter of a voxel (an eighth of a spacing) on average: the block's
    // calibration holds to 0.006 spacings on voxel-aligned faces; a slanted face also samples the lattice's
    // layers at every phase against the voxels, which the smoothing averages but does not remove.
    EXPECT_NEAR(meanOffset, 0.0, 0.125 * h);
    // Flat: no face vertex a voxel (half a spacing) off the face, the height of a lattice staircase step.
    EXPECT_LT(worst, 0.5 * h);
    // The volume: the faces' allowance over their 1,728 h^2 of area is 216 h^3 (6.3% of the 3,456 h^3), and the
    // 216 h of edges rounded to about 1.3 h take (1 - pi/4) 1.69 h^2 each unit of length, 79 h^3 (2.3%). So the
    // mesh holds between 91% and 100% of the fluid's volume, plus the faces' allowance outward.
    EXPECT_GT(volume / fluid, 1 - 0.063 - 0.023);
    EXPECT_LT(volume / fluid, 1 + 0.063);
  }
}

TEST(Surfacer, BandAcrossABlocksFaceIsASignedDistanceToTheFluidsFace) {
  // Down columns through the top face of the block (16 of them, away from the edges), the level set at 1, 0.5
  // spacings above the fluid's face, on it, and 0.5, 1, 1.5 below: the distance to that face. Tolerance 0.05
  // spacings (a tenth of a voxel): each method's face is calibrated onto the fluid's (kDentFill, kZbInset,
  // kAnisoInset; measured 0.0002, 0.0003 and 0.002 spacings off), and for `spheres` the voxels beside the
  // surface keep the smoothed field's own values, whose slope across a lattice's face is about 0.93, so
  // 0.035 spacings short a voxel out, which the Eikonal iterations carry on at slope 1. Measured worst:
  // 0.038 (spheres, 1 spacing out); under 0.006 for the others.
  const double h = 0.02;
  const ParticleFrame frame = block(20, 10, 10, h, Eigen::Vector3d(0.11, 0.01, 0.01));
  const double top = 0.01 + 9.5 * h;
  for (const char* method : {"spheres", "smooth_spheres", "anisotropic"}) {
    const std::vector<double> heights = {1.0, 0.5, 0.0, -0.5, -1.0, -1.5};
    std::vector<Eigen::Vector3d> points;
    for (double height : heights)
      for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b)
          points.emplace_back(0.11 + 6 * h + a * 0.74 * h, top + height * h, 0.01 + 3 * h + b * 0.37 * h);
    const std::vector<double> phi = signedDistancesAt(frame, sceneWithSpacing(h, 3, method), points);
    for (size_t k = 0; k < heights.size(); ++k) {
      const double height = heights[k];
      double sum = 0;
      for (size_t j = 0; j < 16; ++j) sum += phi[16 * k + j];
      std::printf("%s, top face: phi %.4f spacings at %.1f spacings above it\n", method, sum / 16 / h,
                  height);
      EXPECT_NEAR(sum / 16 / h, height, 0.05) << method << " at " << height << " spacings above the face";
    }
  }
}

TEST(Surfacer, AdaptiveMeshIsCoarserAndStillClosed) {
  const double h = 0.02;
  const ParticleFrame frame = block(20, 10, 10, h, Eigen::Vector3d(0.11, 0.01, 0.01));
  Scene scene = sceneWithSpacing(h);
  const TriangleMesh uniform = meshParticles(frame, scene);
  scene.surface.adaptivity = 0.5;
  const TriangleMesh adaptive = meshParticles(frame, scene);
  EXPECT_LT(adaptive.triangles.size(), uniform.triangles.size());
  expectClosedAndOriented(adaptive);
  // Merging flat cells moves vertices by a fraction of a voxel on the rounded edges only: 3% as for the
  // block.
  EXPECT_NEAR(signedVolume(adaptive) / signedVolume(uniform), 1.0, 0.03);
}

TEST(Surfacer, SurfaceFrameWritesALevelSetVdbAndAMesh) {
  const fs::path dir = uniqueTempDir();
  const double h = 0.05;
  const ParticleFrame frame = block(8, 5, 4, h, Eigen::Vector3d(0.2, 0.1, 0.3));
  const Scene scene = sceneWithSpacing(h);
  const fs::path vdb = dir / "surface" / "frame_00003.vdb", ply = dir / "surface" / "frame_00003.ply";
  const SurfaceStats stats = surfaceFrame(frame, scene, vdb, ply);
  EXPECT_EQ(stats.particles, frame.size());
  EXPECT_DOUBLE_EQ(stats.voxelSize, h / 2);
  EXPECT_GT(stats.activeVoxels, 0u);
  EXPECT_GT(stats.triangles, 0u);

  openvdb::initialize();
  openvdb::io::File file(vdb.string());
  file.open();
  ASSERT_TRUE(file.hasGrid("surface"));
  const openvdb::GridBase::Ptr grid = file.readGrid("surface");
  file.close();
  EXPECT_EQ(grid->getGridClass(), openvdb::GRID_LEVEL_SET);
  EXPECT_NEAR(grid->voxelSize()[0], h / 2, 1e-12);
  EXPECT_EQ(size_t(grid->activeVoxelCount()), stats.activeVoxels);

  const TriangleMesh mesh = readMeshPly(ply);
  EXPECT_EQ(mesh.positions.size(), stats.vertices);
  EXPECT_EQ(mesh.triangles.size(), stats.triangles);
  expectUnitNormals(mesh);
  expectClosedAndOriented(mesh);
  // No temporary file is left beside the outputs.
  size_t files = 0;
  for (const auto& entry : fs::directory_iterator(dir / "surface")) files += entry.is_regular_file();
  EXPECT_EQ(files, 2u);
  fs::remove_all(dir);
}

TEST(Surfacer, OneParticleGivesASmallClosedMesh) {
  const double h = 0.1;
  ParticleFrame frame;
  add(frame, Eigen::Vector3f(0.3f, 0.41f, 0.537f));
  const TriangleMesh mesh = meshParticles(frame, sceneWithSpacing(h));
  // A closed mesh needs at least 4 triangles (a tetrahedron).
  ASSERT_GE(mesh.triangles.size(), 4u);
  expectClosedAndOriented(mesh);
  expectUnitNormals(mesh);
  // A speck, not a droplet of the particle's volume: the sphere of radius h is 2 voxels, and the
  // mean-curvature smoothing that flattens the bumps of a fluid's faces shrinks so small a sphere fast (its
  // speed is the curvature), before the erosion takes the rest. Measured over 200 random positions: 0.6% to
  // 4% of h^3. Asserted: positive, under h^3, and inside the particle's sphere.
  const double volume = signedVolume(mesh);
  EXPECT_GT(volume, 0);
  EXPECT_LT(volume, h * h * h);
  for (const auto& x : mesh.positions) EXPECT_LT((x - frame.position[0]).norm(), h);
}

TEST(Surfacer, EmptyFrameGivesAnEmptyMeshAndAValidVdb) {
  const fs::path dir = uniqueTempDir();
  ParticleFrame frame;
  const Scene scene = sceneWithSpacing(0.05);
  const SurfaceStats stats = surfaceFrame(frame, scene, dir / "empty.vdb", dir / "empty.ply");
  EXPECT_EQ(stats.particles, 0u);
  EXPECT_EQ(stats.triangles, 0u);
  EXPECT_EQ(stats.activeVoxels, 0u);
  openvdb::initialize();
  openvdb::io::File file((dir / "empty.vdb").string());
  file.open();
  const openvdb::GridBase::Ptr grid = file.readGrid("surface");
  file.close();
  EXPECT_EQ(grid->getGridClass(), openvdb::GRID_LEVEL_SET);
  EXPECT_EQ(grid->activeVoxelCount(), 0u);
  const TriangleMesh mesh = readMeshPly(dir / "empty.ply");
  EXPECT_TRUE(mesh.positions.empty());
  EXPECT_TRUE(mesh.triangles.empty());
  EXPECT_TRUE(meshParticles(frame, scene).triangles.empty());
  fs::remove_all(dir);
}

TEST(Surfacer, TwoDimensionalFrameGivesAClosedSlab) {
  const double h = 0.02;
  const ParticleFrame frame = block(30, 15, 1, h, Eigen::Vector3d(0.01, 0.01, 0), 2);
  const TriangleMesh mesh = meshParticles(frame, sceneWithSpacing(h, 2));
  ASSERT_GT(mesh.triangles.size(), 100u);
  expectClosedAndOriented(mesh);
  // The slab holds 7 layers (z = -3h .. 3h): its volume is about 7 N h^3; 5% allows for the rounding of the
  // slab's edges, which are a larger share of its volume than of the block's.
  const double volume = signedVolume(mesh);
  std::printf("slab: N=%zu volume / (7 N h^3) = %.4f\n", frame.size(),
              volume / (7 * double(frame.size()) * h * h * h));
  EXPECT_NEAR(volume / (7 * double(frame.size()) * h * h * h), 1.0, 0.05);
  float zmin = 1, zmax = -1;
  for (const auto& x : mesh.positions) zmin = std::min(zmin, x.z()), zmax = std::max(zmax, x.z());
  EXPECT_NEAR(zmin, -3.5 * h, h / 2);
  EXPECT_NEAR(zmax, 3.5 * h, h / 2);
}

TEST(Surfacer, TooCoarseVoxelsThrowRatherThanDropParticles) {
  Scene scene = sceneWithSpacing(0.02);
  scene.surface.voxel_size = 0.02;  // the radius is one voxel, under OpenVDB's 1.5
  const ParticleFrame frame = block(3, 3, 3, 0.02, Eigen::Vector3d::Zero());
  EXPECT_THROW(meshParticles(frame, scene), RunError);
}

TEST(Surfacer, SurfaceFramesWritesEveryFrameInRange) {
  const fs::path dir = uniqueTempDir();
  const double h = 0.05;
  const Scene scene = sceneWithSpacing(h);
  Progress silent;
  EXPECT_THROW(surfaceFrames(dir, scene, FrameRange{}, silent), InputError);
  for (int f = 0; f < 3; ++f)
    writeParticlePly(framePath(dir, "particles", f, "ply"), block(3 + f, 3, 3, h, Eigen::Vector3d::Zero()));
  struct Counting : Progress {
    size_t total = 0, done = 0;
    void start(const std::string&, size_t n) override { total = n; }
    void advance(size_t n) override { done += n; }
  } progress;
  FrameRange range;
  range.first = 1;
  surfaceFrames(dir, scene, range, progress);
  EXPECT_EQ(progress.total, 2u);
  EXPECT_EQ(progress.done, 2u);
  EXPECT_FALSE(fs::exists(framePath(dir, "surface", 0, "vdb")));
  for (int f = 1; f < 3; ++f) {
    EXPECT_TRUE(fs::exists(framePath(dir, "surface", f, "vdb")));
    EXPECT_GT(readMeshPly(framePath(dir, "surface", f, "ply")).triangles.size(), 0u);
  }
  range.first = 7;
  EXPECT_THROW(surfaceFrames(dir, scene, range, progress), InputError);
  // Ctrl-C stops the stage between frames (and OpenVDB's loops inside one) with surge::Interrupted.
  Progress::setInterrupted(true);
  EXPECT_THROW(surfaceFrames(dir, scene, FrameRange{}, progress), Interrupted);
  EXPECT_THROW(meshParticles(block(3, 3, 3, h, Eigen::Vector3d::Zero()), scene), Interrupted);
  Progress::setInterrupted(false);
  // A particle far beyond any tank (a hand-made file): one line naming the file and the particle, nothing
  // else written; meshParticles refuses it too.
  ParticleFrame far = block(3, 3, 3, h, Eigen::Vector3d::Zero());
  far.position[5].x() = 1e6f;
  writeParticlePly(framePath(dir, "particles", 3, "ply"), far);
  range.first = 3;
  try {
    surfaceFrames(dir, scene, range, progress);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("frame_00003.ply: vertex 5: lies more than 2^22 voxels"),
              std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(fs::exists(framePath(dir, "surface", 3, "vdb")));
  EXPECT_THROW(meshParticles(far, scene), RunError);
  fs::remove_all(dir);
}

// Mesh velocities (issue 36): each vertex carries the Shepard average of the particles' velocities around it.
// A block moving as one gives every vertex its velocity exactly (the average of a constant, to float rounding).
// A ball turning rigidly at omega gives the velocity at the weighted centroid of the particles within the
// support R of the vertex, which lies inside the surface by less than R: within |omega| R of omega x (p - c) at
// the vertex (2 rad/s x 0.04 m here), and on average much closer.
TEST(MeshVelocity, AVertexCarriesTheParticlesVelocity) {
  const fs::path dir = fs::path(::testing::TempDir()) / ("mesh_velocity_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  Scene scene = sceneWithSpacing(0.02);
  scene.surface.mesh_velocity = 1;
  const Eigen::Vector3d centre(0.5, 0.5, 0.5);
  ParticleFrame moving = ball(centre, 0.2, 0.02);
  for (Eigen::Vector3f& v : moving.velocity) v = Eigen::Vector3f(1, -2, 0.5);
  surfaceFrame(moving, scene, dir / "moving.vdb", dir / "moving.ply");
  const TriangleMesh translated = readMeshPly(dir / "moving.ply");
  ASSERT_GT(translated.positions.size(), 100u);
  ASSERT_EQ(translated.velocities.size(), translated.positions.size());
  double worst = 0;
  for (const Eigen::Vector3f& v : translated.velocities) worst = std::max(worst, double((v - Eigen::Vector3f(1, -2, 0.5)).norm()));
  EXPECT_LT(worst, 1e-5);

  const Eigen::Vector3d omega(0, 0, 2);
  ParticleFrame turning = ball(centre, 0.2, 0.02);
  for (size_t i = 0; i < turning.size(); ++i)
    turning.velocity[i] = omega.cross(turning.position[i].cast<double>() - centre).cast<float>();
  surfaceFrame(turning, scene, dir / "turning.vdb", dir / "turning.ply");
  const TriangleMesh turned = readMeshPly(dir / "turning.ply");
  ASSERT_EQ(turned.velocities.size(), turned.positions.size());
  double most = 0, mean = 0;
  for (size_t k = 0; k < turned.positions.size(); ++k) {
    const Eigen::Vector3d expected = omega.cross(turned.positions[k].cast<double>() - centre);
    const double error = (turned.velocities[k].cast<double>() - expected).norm();
    most = std::max(most, error);
    mean += error / double(turned.positions.size());
  }
  std::printf("turning ball: vertex velocity within %.4f m/s of omega x r (mean %.4f), |omega| R = %.3f\n", most,
              mean, 2 * 0.04);
  EXPECT_LT(most, 2 * 0.04);

  // Off by default, on for render.quality final.
  scene.surface.mesh_velocity = -1;
  surfaceFrame(moving, scene, dir / "standard.vdb", dir / "standard.ply");
  EXPECT_TRUE(readMeshPly(dir / "standard.ply").velocities.empty());
  scene.render.quality = "final";
  surfaceFrame(moving, scene, dir / "final.vdb", dir / "final.ply");
  EXPECT_EQ(readMeshPly(dir / "final.ply").velocities.size(), translated.positions.size());
  fs::remove_all(dir);
}

}  // namespace
}  // namespace surge

namespace surge {
namespace {

// A resting block whose particles are jittered by up to `jitter` spacings (a fixed hash, no random state), as
// a simulated fluid at rest is never an exact lattice.
ParticleFrame jitteredBlock(int nx, int ny, int nz, double h, double jitter) {
  ParticleFrame frame = block(nx, ny, nz, h, Eigen::Vector3d(0.01, 0.01, 0.01));
  for (size_t i = 0; i < frame.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      const uint32_t bits = uint32_t(i * 2654435761u) ^ uint32_t((k + 1) * 40503u * (i + 7));
      frame.position[i][k] += float(jitter * h * ((double(bits % 2001) / 1000.0) - 1.0));
    }
  return frame;
}

// Variance of the unit normals over the top face of a block (vertices within a quarter spacing of the top's
// mean height, 3 spacings in from its edges): 0 for a perfectly flat face.
double topNormalVariance(const TriangleMesh& mesh, double h, double x1, double z1, double yTop) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> normals;
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    const Eigen::Vector3d x = mesh.positions[i].cast<double>();
    if (x.x() < 0.01 + 3 * h || x.x() > x1 - 3 * h || x.z() < 0.01 + 3 * h || x.z() > z1 - 3 * h) continue;
    if (std::abs(x.y() - yTop) > h) continue;
    normals.push_back(mesh.normals[i].cast<double>());
    sum += normals.back();
  }
  const Eigen::Vector3d mean = sum / double(normals.size());
  double variance = 0;
  for (const auto& n : normals) variance += (n - mean).squaredNorm();
  return variance / double(normals.size());
}

TEST(SurfacerMethods, EveryMethodKeepsTheBlocksVolumeAndIsClosed) {
  const double h = 0.02;
  const ParticleFrame frame = block(20, 10, 10, h, Eigen::Vector3d(0.11, 0.01, 0.01));
  const double fluid = double(frame.size()) * h * h * h;
  for (const char* method : {"spheres", "smooth_spheres", "anisotropic"}) {
    const TriangleMesh mesh = meshParticles(frame, sceneWithSpacing(h, 3, method));
    const double volume = signedVolume(mesh);
    std::printf("%s: block volume error %.2f%%, %zu triangles\n", method, 100 * (volume / fluid - 1),
                mesh.triangles.size());
    // 3%, argued as for `spheres` in RestingBlockEnclosesItsFluidVolumeAndIsClosed: the faces are calibrated
    // onto the fluid's faces (kZbInset, kAnisoInset), the loss is at the rounded edges.
    EXPECT_NEAR(volume / fluid, 1.0, 0.03) << method;
    expectClosedAndOriented(mesh);
    expectUnitNormals(mesh);
  }
}

// The ball of BallOfParticlesGivesASphereOfTheFluidsVolume, with the same one-voxel tolerances, for the other
// methods: their insets are calibrated on the flat faces of the block, not on the ball.
TEST(SurfacerMethods, EveryMethodGivesABallOfTheFluidsVolume) {
  for (const char* method : {"smooth_spheres", "anisotropic"}) expectBallOfTheFluidsVolume(method);
}

TEST(SurfacerMethods, AnisotropicKernelsLeaveAFlatSurfaceFlatterThanSpheres) {
  const double h = 0.02;
  const int nx = 20, ny = 8, nz = 20;
  const ParticleFrame frame = jitteredBlock(nx, ny, nz, h, 0.1);
  const double yTop = 0.01 + (ny - 1) * h + h / 2, x1 = 0.01 + (nx - 1) * h, z1 = 0.01 + (nz - 1) * h;
  double variance[2];
  const char* methods[2] = {"spheres", "anisotropic"};
  for (int m = 0; m < 2; ++m) {
    const TriangleMesh mesh = meshParticles(frame, sceneWithSpacing(h, 3, methods[m]));
    variance[m] = topNormalVariance(mesh, h, x1, z1, yTop);
    std::printf("%s: normal variance on the top face %.3g\n", methods[m], variance[m]);
  }
  // Strictly lower: the claim of YT13 is qualitative, so the test asserts only the order, at the same voxel
  // size and smoothing. Measured: 0.0045 (spheres), 0.0033 (anisotropic).
  EXPECT_LT(variance[1], variance[0]);
}

TEST(SurfacerMethods, EveryMethodGivesTheSameMeshAndLevelSetAtOneAndTwoThreads) {
  // A jittered block spans about a hundred blocks of voxels, so every parallel loop (rasteriser, kernels,
  // NarrowBand, OpenVDB's filters, normals) splits its work; the results must not depend on how.
  const double h = 0.02;
  const ParticleFrame frame = jitteredBlock(20, 10, 10, h, 0.2);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 30; ++i)
    for (int j = 0; j < 15; ++j) points.emplace_back(0.0 + i * 0.0147, 0.0 + j * 0.0153, 0.1);
  for (const char* method : {"spheres", "smooth_spheres", "anisotropic"}) {
    const Scene scene = sceneWithSpacing(h, 3, method);
    TriangleMesh mesh[2];
    std::vector<double> phi[2];
    for (int threads : {1, 2}) {
      ThreadLimit limit(threads);
      mesh[threads - 1] = meshParticles(frame, scene);
      phi[threads - 1] = signedDistancesAt(frame, scene, points);
    }
    EXPECT_TRUE(mesh[0].positions == mesh[1].positions) << method;
    EXPECT_TRUE(mesh[0].triangles == mesh[1].triangles) << method;
    EXPECT_TRUE(mesh[0].normals == mesh[1].normals) << method;
    EXPECT_TRUE(phi[0] == phi[1]) << method;
  }
}

TEST(SurfacerVdb, RoundTripsNameClassVoxelAndTransformWithVelocityAndPoints) {
  const fs::path dir = uniqueTempDir();
  const double h = 0.05;
  ParticleFrame frame = block(6, 4, 5, h, Eigen::Vector3d(0.2, 0.1, 0.3));
  for (auto& v : frame.velocity) v = Eigen::Vector3f(1.0f, -2.0f, 0.5f);
  Scene scene = sceneWithSpacing(h);
  scene.surface.write_velocity = 1;
  scene.surface.write_points = 1;
  scene.surface.write_obj = 1;
  const fs::path vdb = dir / "f.vdb", ply = dir / "f.ply";
  surfaceFrame(frame, scene, vdb, ply);
  EXPECT_TRUE(fs::exists(dir / "f.obj"));

  openvdb::initialize();
  openvdb::io::File file(vdb.string());
  file.open();
  const openvdb::GridBase::Ptr surface = file.readGrid("surface");
  ASSERT_TRUE(file.hasGrid("v"));
  ASSERT_TRUE(file.hasGrid("points"));
  const openvdb::GridBase::Ptr v = file.readGrid("v");
  const openvdb::GridBase::Ptr points = file.readGrid("points");
  file.close();
  EXPECT_EQ(surface->getName(), "surface");
  EXPECT_EQ(surface->getGridClass(), openvdb::GRID_LEVEL_SET);
  EXPECT_EQ(surface->transform(), *openvdb::math::Transform::createLinearTransform(h / 2));
  // The velocity grid shares the level set's transform; every particle moves alike, so every voxel's Shepard
  // average is that velocity (to float rounding of sum w v / sum w, 1e-5 relative), or zero on voxels of the
  // surface's leaves that no particle's support (2 spacings) reaches.
  EXPECT_EQ(v->transform(), surface->transform());
  const auto vgrid = openvdb::gridPtrCast<openvdb::Vec3SGrid>(v);
  ASSERT_TRUE(vgrid);
  size_t moving = 0, other = 0;
  for (auto it = vgrid->cbeginValueOn(); it; ++it) {
    if ((*it - openvdb::Vec3s(1.0f, -2.0f, 0.5f)).length() < 1e-5f)
      ++moving;
    else if ((*it).length() != 0)
      ++other;
  }
  EXPECT_GT(moving, 0u);
  EXPECT_EQ(other, 0u);
  EXPECT_EQ(points->type(), "Tree_ptdataidx32_5_4_3");
  EXPECT_TRUE(points->activeVoxelCount() > 0);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace surge
