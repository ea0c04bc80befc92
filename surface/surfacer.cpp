// The surfacer: particles -> level set -> mesh, with OpenVDB 10. With collider_clip.cpp, the one file of
// surface/ that includes OpenVDB's tools (40-55 s to compile); everything else sees only surfacer.h.
//
// Method: a raw level set from particle_field.h (union of spheres, Zhu & Bridson blend or Yu & Turk
// anisotropic kernels, by surface.method), smoothed by mean-curvature flow and eroded back to the fluid's
// volume, meshed by tools::volumeToMesh at isovalue 0. `spheres` runs its level-set steps on narrow_band.h's
// dense blocks; the blended fields on tools::LevelSetFilter (re-distancing by LevelSetTracker).
#include "surface/surfacer.h"

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/LevelSetFilter.h>
#include <openvdb/tools/SignedFloodFill.h>
#include <openvdb/tools/VolumeToMesh.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <string>
#include <vector>

#include "core/errors.h"
#include "core/parallel.h"
#include "surface/anisotropy.h"
#include "surface/collider_clip.h"
#include "surface/mesh_velocity.h"
#include "surface/narrow_band.h"
#include "surface/particle_field.h"
#include "surface/vdb_output.h"

namespace surge {
namespace {

using openvdb::FloatGrid;

// Narrow-band half-width in voxels, on each side of the surface.
constexpr double kHalfWidthVoxels = 3.0;
// 2D frames become a slab of 2 * kSlabHalfLayers + 1 copies of the particle plane, spaced particle_spacing
// along z (z = -3h .. +3h): a closed solid about 7 spacings thick once eroded, thick enough that the two
// faces of the slab never merge under smoothing, and thin enough to cost only 7x the spheres of the frame.
constexpr int kSlabHalfLayers = 3;
// How far below the sphere tops (in spacings) the smoothed union of spheres of radius = spacing lies on a
// flat face of a square lattice, measured: with it, the faces of a 20x10x10 block's mesh land within 0.001
// spacings of the fluid's faces (tests/surface: BandAcrossABlocksFaceIsASignedDistanceToTheFluidsFace; 0.17
// with OpenVDB's re-distancing between the steps, 0.15 with three Eikonal iterations after every smoothing
// step). For radii other than the spacing it is an approximation.
constexpr double kDentFill = 0.205;
// Eikonal iterations after the smoothing and after the shift: one carries right distances a voxel further out
// from the surface (a third to a whole voxel, by the surface's orientation), and the steps before them leave
// the band nearly a distance already, so 3, one per voxel of the band, suffice.
constexpr int kRedistanceIterations = 3;
// Eikonal iterations of OpenVDB's re-distancing for the blended fields: the band is 3 voxels each side and
// one iteration moves correct distances about a voxel, so 3 reach across it (LevelSetTracker's default is 1,
// meant for a band already nearly right after one step of motion).
constexpr int kRenormalise = 3;

void initOpenVdb() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

// Smooth spheres (ZB05): weights' support R = 2 spacings (the simulator's kernel radius), sphere radius r as
// for `spheres`. The blend x-bar lies under the outer layer of a flat face, by kZbInset spacings (measured on
// the test block: 0, the faces then land within 0.0003 spacings of the fluid's), so the erosion for this
// method is r - 0.5 h - kZbInset h.
constexpr double kZbSupport = 2.0;
constexpr double kZbInset = 0.0;
// Anisotropic (YT13): kernel support h = 2 spacings, PCA radius 3 spacings (60 neighbours at a flat face, above
// N_epsilon = 25), iso-value half the rest field, and kAnisoInset: how far that surface lies under the fluid's
// face, measured on the test block and dilated back after smoothing (docs/performance.md, "Surfacing methods").
constexpr double kAnisoSupport = 2.0;
constexpr double kAnisoPca = 3.0;
constexpr double kAnisoIso = 0.5;
constexpr double kAnisoInset = 0.753;

FloatGrid::Ptr emptyLevelSet(double voxel) {
  FloatGrid::Ptr grid = openvdb::createLevelSet<FloatGrid>(voxel, kHalfWidthVoxels);
  grid->setName("surface");
  grid->setGridClass(openvdb::GRID_LEVEL_SET);
  return grid;
}

// How a method's raw field becomes a level set (buildLevelSet): `spheres` on NarrowBand from the raw union;
// the blended fields re-distanced by OpenVDB's LevelSetTracker first, then smoothed and eroded on NarrowBand
// (smooth_spheres) or by tools::LevelSetFilter (anisotropic).
enum class SmoothingRoute { NarrowBand, TrackedThenNarrowBand, TrackedAndFiltered };

// One surface.method: its raster (particle_field.h), where its smoothed surface lies under the fluid's face,
// and its smoothing. The erosion (erosionOf) is radius - h/2 - inset h when `fromRadius`, else -inset h (a
// dilation), h the spacing.
struct SurfaceMethod {
  const char* name;
  FieldKind raster;
  bool fromRadius;
  double inset;  // spacings
  SmoothingRoute route;
};

constexpr SurfaceMethod kMethods[] = {
    {"spheres", FieldKind::Spheres, true, kDentFill, SmoothingRoute::NarrowBand},
    {"smooth_spheres", FieldKind::SmoothSpheres, true, kZbInset, SmoothingRoute::TrackedThenNarrowBand},
    {"anisotropic", FieldKind::Anisotropic, false, kAnisoInset, SmoothingRoute::TrackedAndFiltered},
};

struct Parameters {
  double spacing = 0, radius = 0, voxel = 0;
  int layers = 1;  // copies of each particle along z (1 in 3D)
  const SurfaceMethod* method = nullptr;
};

// surface.method by name; InputError naming the key for a name not in kMethods.
const SurfaceMethod& surfaceMethod(const Scene& scene) {
  for (const SurfaceMethod& m : kMethods)
    if (scene.surface.method == m.name) return m;
  throw InputError(scene.source.empty() ? "scene" : scene.source, "surface.method",
                   "unknown method '" + scene.surface.method + "'");
}

Parameters resolve(const Scene& scene, int dimensions) {
  Parameters p;
  p.spacing = scene.particle_spacing;
  if (!(p.spacing > 0)) throw RunError("surface: particle_spacing must be positive");
  p.radius = scene.surface.particle_radius > 0 ? scene.surface.particle_radius : p.spacing;
  p.voxel = scene.surface.voxel_size > 0 ? scene.surface.voxel_size : p.radius / 2;
  p.layers = dimensions == 2 ? 2 * kSlabHalfLayers + 1 : 1;
  p.method = &surfaceMethod(scene);
  return p;
}

Parameters resolve(const ParticleFrame& frame, const Scene& scene) {
  return resolve(scene, frame.dimensions);
}

// The first particle more than 2^22 voxels from the origin on some axis, or -1: the blocks of 8^3 voxels are
// keyed by 21-bit coordinates (particle_field.cpp, narrow_band.cpp), 2^23 voxels each way, and half that
// leaves room for the band. (The scene check keeps the domain inside it; a particle file may not be.)
long farParticle(const ParticleFrame& frame, double voxel) {
  const double limit = double(1 << 22) * voxel;
  for (size_t i = 0; i < frame.size(); ++i)
    if (frame.position[i].cast<double>().cwiseAbs().maxCoeff() > limit) return long(i);
  return -1;
}

// Particles as the surfacer sees them: the frame's, or in 2D 2 * kSlabHalfLayers + 1 copies of them spaced
// particle_spacing along z (positions; velocities are copied with vz = 0).
std::vector<Eigen::Vector3f> slabPositions(const ParticleFrame& frame, const Parameters& p,
                                           const std::vector<Eigen::Vector3f>& values, bool isPosition) {
  if (p.layers == 1) return values;
  std::vector<Eigen::Vector3f> out(values.size() * size_t(p.layers));
  for (size_t i = 0; i < out.size(); ++i) {
    Eigen::Vector3f x = values[i / size_t(p.layers)];
    x.z() = isPosition ? float((double(i % size_t(p.layers)) - kSlabHalfLayers) * p.spacing) : 0.f;
    out[i] = x;
  }
  (void)frame;
  return out;
}

// A level set from blocks of distances (particle_field.h): one leaf per block, the tiles around them given
// their sign by a flood fill (blocks wholly inside were never made). With `trim`, values are clamped to
// +-band and only the voxels inside (-band, band) are active, blocks with none of them dropped (a finished
// level set); without, every voxel of a block is active (a raw field for OpenVDB's re-distancing).
FloatGrid::Ptr gridFromBlocks(const BlockField& blocks, double voxel, bool trim) {
  FloatGrid::Ptr grid = emptyLevelSet(voxel);
  auto& tree = grid->tree();
  const float band = float(kHalfWidthVoxels * voxel);
  for (size_t b = 0; b < blocks.origins.size(); ++b) {
    const Eigen::Vector3i& o = blocks.origins[b];
    const float* values = &blocks.values[b * kBlockVoxels];
    if (trim && std::none_of(values, values + kBlockVoxels, [&](float v) { return std::abs(v) < band; }))
      continue;
    auto* leaf = new FloatGrid::TreeType::LeafNodeType(openvdb::Coord(o.x(), o.y(), o.z()), 0.f, !trim);
    float* out = leaf->buffer().data();
    for (int i = 0; i < kBlockVoxels; ++i) {
      out[i] = trim ? std::clamp(values[i], -band, band) : values[i];
      if (trim && std::abs(values[i]) < band) leaf->setValueOn(openvdb::Index(i));
    }
    tree.addLeaf(leaf);
  }
  openvdb::tools::signedFloodFill(tree);
  return grid;
}

// OpenVDB's interrupter interface over Surge's Ctrl-C flag: a long frame stops inside OpenVDB's loops, and
// the caller turns the flag into surge::Interrupted with Progress::checkInterrupt().
struct CtrlCInterrupter {
  void start(const char* = nullptr) {}
  void end() {}
  bool wasInterrupted(int = -1) { return Progress::wasInterrupted(); }
};

// The raw level set of a frame's particles, by method: distances right near the zero crossing, roughly
// right (clamped to the band) elsewhere.
BlockField rawLevelSet(const ParticleFrame& frame, const Parameters& p, double band) {
  const std::vector<Eigen::Vector3f> x = slabPositions(frame, p, frame.position, true);
  FieldParticles particles;
  particles.position = &x;
  FieldParameters f;
  f.voxel = p.voxel;
  f.band = band;
  f.radius = p.radius;
  f.occupancyCell = 2 * p.spacing;
  AnisotropicKernels kernels;
  f.kind = p.method->raster;
  switch (p.method->raster) {
    case FieldKind::Spheres:
      break;
    case FieldKind::SmoothSpheres:
      f.support = kZbSupport * p.spacing;
      break;
    case FieldKind::Anisotropic: {
      AnisotropyParameters a;
      a.spacing = p.spacing;
      a.supportRadius = kAnisoSupport * p.spacing;
      a.pcaRadius = kAnisoPca * p.spacing;
      kernels = anisotropicKernels(x, a);
      particles.kernels = &kernels;
      f.iso = kAnisoIso;
      f.volume = kernels.particleVolume;
      break;
    }
    case FieldKind::Velocity:
      throw RunError("surface: surface.method '" + std::string(p.method->name) + "' rasterises no level set");
  }
  Progress::checkInterrupt();
  return rasterizeField(particles, f);
}

// How far to erode (positive) the smoothed level set of each method so that a flat face of a resting fluid
// lands on the fluid's face, h/2 beyond the centres of its outer layer.
double erosionOf(const Parameters& p) {
  // Each particle stands for a cube of fluid of side h = spacing, so a flat face of the fluid lies h/2 beyond
  // the centres of its outer layer, while the sphere union reaches `radius` beyond them at the centres and
  // h/sqrt(2) (for radius = h) between them. Eroding by radius - h/2 would put the sphere tops on the
  // fluid's face; the smoothed surface lies kDentFill * h under the tops, so that much less is eroded and the
  // faces land on the fluid's (a 20x10x10 block then encloses N h^3 less 1.75%, lost at its rounded edges).
  // (The anisotropic surface lies under the face instead, and is dilated.)
  if (p.method->fromRadius) return p.radius - 0.5 * p.spacing - p.method->inset * p.spacing;
  return -p.method->inset * p.spacing;
}

// Where the water meets a collider (collider_clip.h). The extension reaches as deep into the solid as the
// erosion and the band could carry the end of the water back towards the wall, and a voxel more; it reads the
// water half a spacing out of the solid (the centres of a layer resting on it), and for a method whose raw
// surface lies under the fluid's face (anisotropic) also as much further out as that.
ExtensionParameters extensionOf(const Parameters& p) {
  ExtensionParameters e;
  e.band = kHalfWidthVoxels * p.voxel;
  e.depth = e.band + std::max(erosionOf(p), 0.0) + p.voxel;
  e.near = 0.5 * p.spacing;
  e.far = e.near + std::max(-erosionOf(p), 0.0);
  return e;
}

// The colliders' level sets: on the fluid's side the water's band and a voxel, or the extension's reach there
// and two voxels (its gradient); on the solid's, the extension's depth and band and two voxels. They are cut
// to the tank with room for the extension's reach and a leaf, and in 2D to the water's slab.
ColliderGrids colliderGrids(const Scene& scene) {
  const Parameters p = resolve(scene, scene.dimensions);
  const ExtensionParameters e = extensionOf(p);
  ColliderGrids grids;
  grids.voxel = p.voxel;
  grids.fluid = float(std::max(kHalfWidthVoxels + 1, std::ceil(e.far / p.voxel) + 2));
  grids.solid = float(std::ceil((e.depth + e.band) / p.voxel) + 2);
  grids.output = float(kHalfWidthVoxels);
  grids.flat = scene.dimensions == 2;
  const double margin = (grids.solid + grids.fluid + kBlockDim) * p.voxel;
  Eigen::Vector3d lo = scene.domain.min.array() - margin, hi = scene.domain.max.array() + margin;
  if (grids.flat) {  // the slab and the VDB's band; the solid's band at z = 0 (the section used)
    hi.z() =
        std::max((kSlabHalfLayers + 0.5) * p.spacing + grids.output * p.voxel, (grids.solid + 1) * p.voxel);
    lo.z() = -hi.z();
  }
  // A hand-made scene may have no tank: then the grids are cut only along z in 2D (never beyond the blocks'
  // reach of 2^22 voxels, particle_field.h).
  const double huge = double(1 << 22) * p.voxel;
  for (int a = 0; a < (grids.flat ? 2 : 3); ++a)
    if (!(scene.domain.max[a] > scene.domain.min[a])) lo[a] = -huge, hi[a] = huge;
  grids.region = Eigen::AlignedBox3d(lo, hi);
  return grids;
}

// The blocks of a grid's leaves, in the tree's order.
BlockField blocksOf(const FloatGrid& grid) {
  BlockField blocks;
  for (auto leaf = grid.tree().cbeginLeaf(); leaf; ++leaf) {
    const openvdb::Coord o = leaf->origin();
    blocks.origins.emplace_back(o.x(), o.y(), o.z());
    blocks.values.insert(blocks.values.end(), leaf->buffer().data(), leaf->buffer().data() + kBlockVoxels);
  }
  return blocks;
}

// The level-set steps on NarrowBand: `firstIterations` Eikonal iterations (to make the field a distance, if
// it is not one yet), smoothing, erosion, each followed by Eikonal iterations, then trimmed to the band. The
// field's inside reaches deeper than the band by the erosion and a voxel more, so that the eroded band is
// whole.
FloatGrid::Ptr smoothAndErode(BlockField blocks, const Parameters& p, int smoothingSteps,
                              int firstIterations) {
  const double band = kHalfWidthVoxels * p.voxel;
  NarrowBand field(std::move(blocks), p.voxel, float(band),
                   float(band + std::max(erosionOf(p), 0.0) + p.voxel));
  field.redistance(firstIterations);
  for (int i = 0; i < smoothingSteps; ++i) field.meanCurvatureStep();
  field.redistance(kRedistanceIterations);
  field.offset(float(erosionOf(p)));
  field.redistance(kRedistanceIterations);
  Progress::checkInterrupt();
  return gridFromBlocks(field.blocks(), p.voxel, /*trim=*/true);
}

// `spheres`: the raw union made a distance by Eikonal iterations across the whole working band (its inside
// values are depths under the nearest sphere, not under the union, so never below -radius; the voxels beside
// the zero crossing are exact distances to the union and are kept): one iteration per voxel of the inside's
// depth, band + erosion + 1 voxel.
FloatGrid::Ptr sphereLevelSet(const ParticleFrame& frame, const Parameters& p, int smoothingSteps,
                              const std::vector<SurfaceCollider>& colliders) {
  BlockField raw = rawLevelSet(frame, p, kHalfWidthVoxels * p.voxel);
  Progress::checkInterrupt();
  if (!colliders.empty()) {
    const FloatGrid::Ptr grid = gridFromBlocks(raw, p.voxel, /*trim=*/false);
    extendIntoColliders(*grid, colliders, extensionOf(p));
    raw = blocksOf(*grid);
  }
  const int iterations = int(std::ceil(kHalfWidthVoxels + std::max(erosionOf(p), 0.0) / p.voxel + 1));
  return smoothAndErode(std::move(raw), p, smoothingSteps, iterations);
}

// The blended fields are distances only near their zero crossing, and the voxels beside it need moving too,
// which NarrowBand::redistance does not do (it keeps them): run on NarrowBand from the raw field,
// smooth_spheres' block lost 4% and the anisotropic surface came out bumpy. So OpenVDB's LevelSetTracker
// re-distances them first (kRenormalise Eikonal iterations, HJWENO5, every voxel of the band moving), then
// smooth_spheres goes on with smoothAndErode. `anisotropic` stays with tools::LevelSetFilter for its
// smoothing and dilation: run through smoothAndErode its top face's normal variance went from 0.0033 to 0.013
// (the CFL steps of LevelSetFilter::offset, each re-distanced, smooth it as they dilate it).
// (tools::sdfToSdf, fast sweeping, did the first re-distancing here once and took 85 s for a million
// particles.)
FloatGrid::Ptr blendedLevelSet(const ParticleFrame& frame, const Parameters& p, int smoothingSteps,
                               const std::vector<SurfaceCollider>& colliders) {
  CtrlCInterrupter interrupter;
  FloatGrid::Ptr grid =
      gridFromBlocks(rawLevelSet(frame, p, kHalfWidthVoxels * p.voxel), p.voxel, /*trim=*/false);
  Progress::checkInterrupt();
  if (!colliders.empty()) extendIntoColliders(*grid, colliders, extensionOf(p));
  openvdb::tools::LevelSetFilter<FloatGrid, FloatGrid, CtrlCInterrupter> filter(*grid, &interrupter);
  filter.setNormCount(kRenormalise);
  filter.normalize();
  filter.prune();  // voxels now beyond the band become inactive background
  Progress::checkInterrupt();
  if (p.method->route == SmoothingRoute::TrackedThenNarrowBand)
    return smoothAndErode(blocksOf(*grid), p, smoothingSteps, /*firstIterations=*/0);
  // Anisotropic: 3 Eikonal iterations after each smoothing step (with one, the dilation below lost the block
  // 9% more; kRenormalise is still set), then the dilation in CFL steps, which grow the outer band as the
  // surface moves out.
  for (int i = 0; i < smoothingSteps; ++i) filter.meanCurvature();
  filter.offset(float(erosionOf(p)));
  return grid;
}

// The level set of a frame. Smooth first, erode second: mean-curvature flow fills the dents between the
// spheres and rounds the sphere caps, the erosion then takes the surface back to the fluid. (Eroding first
// would leave a lone particle a sphere of one voxel, which smoothing then erases.) Mean-curvature flow steps
// (surface.smoothing_steps, default 2): enough to take out the bumps of the sphere union (on a flat face they
// go from 0.04 to 0.004 spacings rms in two steps; each step moves the surface by a third of a voxel times
// its curvature in voxels), few enough to keep edges and small droplets.
// With colliders, the water is extended into them before the smoothing and clipped by them at the end.
FloatGrid::Ptr buildLevelSetOf(const ParticleFrame& frame, const Scene& scene,
                               const std::vector<SurfaceCollider>& colliders) {
  initOpenVdb();
  const Parameters p = resolve(frame, scene);
  if (frame.size() == 0) return emptyLevelSet(p.voxel);
  // Spheres under 1.5 voxels are under-resolved: OpenVDB's own rasteriser skips them without a word, and the
  // smoothing would erase what is left. The scene loader forbids such voxels; a hand-made Scene may not
  // have gone through it.
  if (p.radius / p.voxel < 1.5)
    throw RunError("surface: particle_radius " + std::to_string(p.radius) + " is under 1.5 voxels of " +
                   std::to_string(p.voxel) + "; the particles' spheres would be lost");
  if (const long far = farParticle(frame, p.voxel); far >= 0)
    throw RunError("surface: particle " + std::to_string(far) +
                   " lies more than 2^22 voxels from the origin");
  const int steps = scene.surface.smoothing_steps;
  FloatGrid::Ptr grid;
  switch (p.method->route) {
    case SmoothingRoute::NarrowBand:
      grid = sphereLevelSet(frame, p, steps, colliders);
      break;
    case SmoothingRoute::TrackedThenNarrowBand:
    case SmoothingRoute::TrackedAndFiltered:
      grid = blendedLevelSet(frame, p, steps, colliders);
      break;
  }
  if (!colliders.empty()) clipByColliders(*grid, colliders, double(grid->background()));
  Progress::checkInterrupt();
  return grid;
}

// The level set of a frame. On a periodic domain the particles' images across each seam make the surface run on
// through it as the fluid does, and the faces of the periodic axes then cut it (as planes clip the water,
// collider_clip.h): the surface meets each seam square, and matches the other side's there.
FloatGrid::Ptr buildLevelSet(const ParticleFrame& frame, const Scene& scene,
                             const std::vector<SurfaceCollider>& colliders = {}) {
  if (scene.periodicAxes() == 0 || frame.size() == 0) return buildLevelSetOf(frame, scene, colliders);
  const Parameters p = resolve(frame, scene);
  // Beyond the kernel's support and the smoothing's reach a particle does not shape the surface at the seam.
  const double reach = 3 * std::max(scene.solver.kernel_radius, 2 * p.spacing) + 2 * p.radius;
  FloatGrid::Ptr grid = buildLevelSetOf(withPeriodicImages(frame, scene, reach), scene, colliders);
  std::vector<SurfaceCollider> faces;
  for (int k = 0; k < scene.dimensions; ++k) {
    if (!scene.isPeriodic(k)) continue;
    for (const int side : {1, -1}) {
      SurfaceCollider face;
      face.name = std::string(side > 0 ? "-" : "+") + char('x' + k);
      face.plane = true;
      openvdb::Vec3d normal(0, 0, 0);
      normal[k] = side;  // into the domain: the solid is beyond the face
      face.normal = normal;
      face.offset = side > 0 ? scene.domain.min[k] : -scene.domain.max[k];
      faces.push_back(face);
    }
  }
  clipByColliders(*grid, faces, double(grid->background()));
  return grid;
}

// volumeToMesh's polygons wind clockwise seen from outside (their right-hand normal points into the
// level set, towards negative values); Surge's meshes wind counter-clockwise, so every polygon is reversed.
void addTriangle(TriangleMesh& mesh, uint32_t a, uint32_t b, uint32_t c) {
  mesh.triangles.push_back({a, c, b});
}

TriangleMesh meshLevelSet(const FloatGrid& grid, double adaptivity) {
  TriangleMesh mesh;
  if (grid.activeVoxelCount() == 0) return mesh;
  std::vector<openvdb::Vec3s> points;
  std::vector<openvdb::Vec3I> triangles;
  std::vector<openvdb::Vec4I> quads;
  openvdb::tools::volumeToMesh(grid, points, triangles, quads, /*isovalue=*/0.0, adaptivity);

  mesh.positions.resize(points.size());
  for (size_t i = 0; i < points.size(); ++i)
    mesh.positions[i] = Eigen::Vector3f(points[i].x(), points[i].y(), points[i].z());
  mesh.triangles.reserve(triangles.size() + 2 * quads.size());
  for (const auto& t : triangles) addTriangle(mesh, t[0], t[1], t[2]);
  // Quads are split along their shorter diagonal, which gives the better-shaped pair of triangles.
  for (const auto& q : quads) {
    const auto& x = mesh.positions;
    if ((x[q[0]] - x[q[2]]).squaredNorm() <= (x[q[1]] - x[q[3]]).squaredNorm()) {
      addTriangle(mesh, q[0], q[1], q[2]);
      addTriangle(mesh, q[0], q[2], q[3]);
    } else {
      addTriangle(mesh, q[0], q[1], q[3]);
      addTriangle(mesh, q[1], q[2], q[3]);
    }
  }

  // Vertex normals: the gradient of the level set, by central differences of trilinear samples half a voxel
  // either side, normalised. Where it vanishes (never on a proper level set), the area-weighted face normal.
  mesh.normals.assign(mesh.positions.size(), Eigen::Vector3f::Zero());
  const openvdb::math::Transform& transform = grid.transform();
  parallelFor(0, mesh.positions.size(), [&](size_t begin, size_t end) {
    const auto accessor = grid.getConstAccessor();
    const auto sample = [&](const openvdb::Vec3d& ijk) {
      return double(openvdb::tools::BoxSampler::sample(accessor, ijk));
    };
    for (size_t i = begin; i < end; ++i) {
      const Eigen::Vector3f& x = mesh.positions[i];
      const openvdb::Vec3d c = transform.worldToIndex(openvdb::Vec3d(x.x(), x.y(), x.z()));
      Eigen::Vector3d g;
      for (int k = 0; k < 3; ++k) {
        openvdb::Vec3d plus = c, minus = c;
        plus[k] += 0.5;
        minus[k] -= 0.5;
        g[k] = sample(plus) - sample(minus);
      }
      if (g.norm() > 1e-12) mesh.normals[i] = g.normalized().cast<float>();
    }
  });
  std::vector<Eigen::Vector3f> faceSum;
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3f n =
        (mesh.positions[t[1]] - mesh.positions[t[0]]).cross(mesh.positions[t[2]] - mesh.positions[t[0]]);
    for (uint32_t v : t) {
      if (mesh.normals[v].squaredNorm() > 0) continue;
      if (faceSum.empty()) faceSum.assign(mesh.positions.size(), Eigen::Vector3f::Zero());
      faceSum[v] += n;
    }
  }
  for (size_t i = 0; i < faceSum.size(); ++i)
    if (mesh.normals[i].squaredNorm() == 0 && faceSum[i].squaredNorm() > 0)
      mesh.normals[i] = faceSum[i].normalized();
  return mesh;
}

// OBJ with vertex normals (v, vn, f a//a), 1-based indices, as text: Blender and Houdini read it.
void writeMeshObj(const fs::path& path, const TriangleMesh& mesh) {
  writeFileAtomically(path, [&](std::ostream& out) {
    char line[128];
    for (const auto& x : mesh.positions) {
      std::snprintf(line, sizeof line, "v %.7g %.7g %.7g\n", double(x.x()), double(x.y()), double(x.z()));
      out << line;
    }
    for (const auto& n : mesh.normals) {
      std::snprintf(line, sizeof line, "vn %.6g %.6g %.6g\n", double(n.x()), double(n.y()), double(n.z()));
      out << line;
    }
    const bool normals = !mesh.normals.empty();
    for (const auto& t : mesh.triangles) {
      if (normals)
        std::snprintf(line, sizeof line, "f %u//%u %u//%u %u//%u\n", t[0] + 1, t[0] + 1, t[1] + 1, t[1] + 1,
                      t[2] + 1, t[2] + 1);
      else
        std::snprintf(line, sizeof line, "f %u %u %u\n", t[0] + 1, t[1] + 1, t[2] + 1);
      out << line;
    }
  });
}

// surfaceFrame, with the colliders as they stand at this frame: the water meets them (collider_clip.h) and
// the VDB holds their level sets after the water's grids (planes have none: a half-space has no narrow band).
SurfaceStats surfaceFrameWith(const ParticleFrame& frame, const Scene& scene, const fs::path& vdbPath,
                              const fs::path& meshPath, const std::vector<SurfaceCollider>& colliders,
                              const DiffuseFrame* whitewater = nullptr,
                              const std::vector<FloatGrid::ConstPtr>& otherFluids = {}) {
  const FloatGrid::Ptr grid = buildLevelSet(frame, scene, colliders);
  TriangleMesh mesh = meshLevelSet(*grid, scene.surface.adaptivity);
  if (!colliders.empty()) snapOutOfColliders(mesh, colliders, grid->voxelSize()[0]);

  const Parameters p = resolve(frame, scene);
  VdbExtras extras;
  extras.fluids = otherFluids;
  BlockField velocity;
  std::vector<Eigen::Vector3f> x, v;
  const bool meshVelocity =
      scene.surface.mesh_velocity == 1 || (scene.surface.mesh_velocity < 0 && scene.render.quality == "final");
  if (scene.surface.write_velocity || scene.surface.write_points || meshVelocity) {
    x = slabPositions(frame, p, frame.position, true);
    v = slabPositions(frame, p, frame.velocity, false);
  }
  if (meshVelocity) sampleVertexVelocities(mesh, x, v, float(kZbSupport * p.spacing));
  if (scene.surface.write_velocity) {
    // The Shepard average of the particle velocities (ZB05 weights, support 2 spacings) on every voxel of the
    // surface's leaves, where a renderer's motion blur or a re-simulation looks them up.
    std::vector<Eigen::Vector3i> leaves;
    for (auto leaf = grid->tree().cbeginLeaf(); leaf; ++leaf) {
      const openvdb::Coord o = leaf->origin();
      leaves.emplace_back(o.x(), o.y(), o.z());
    }
    FieldParticles particles;
    particles.position = &x;
    particles.velocity = &v;
    FieldParameters f;
    f.kind = FieldKind::Velocity;
    f.voxel = p.voxel;
    f.support = kZbSupport * p.spacing;
    velocity = rasterizeField(particles, f, &leaves);
    extras.velocity = &velocity;
  }
  if (scene.surface.write_points) {
    extras.pointPositions = &x;
    extras.pointVelocities = &v;
    extras.pointVoxel = 4 * p.spacing;  // about 64 particles per voxel of the points grid
  }
  if (whitewater) {
    extras.whitewater = whitewater;
    if (!scene.surface.write_points) extras.pointVoxel = 4 * p.spacing;
  }
  for (const SurfaceCollider& c : colliders)
    if (c.output) extras.colliders.push_back(c.output);
  writeSurfaceVdb(vdbPath, grid, extras);
  writeMeshPly(meshPath, mesh);
  if (scene.surface.write_obj) {
    fs::path obj = meshPath;
    writeMeshObj(obj.replace_extension(".obj"), mesh);
  }
  SurfaceStats stats;
  stats.particles = frame.size();
  stats.activeVoxels = size_t(grid->activeVoxelCount());
  stats.vertices = mesh.positions.size();
  stats.triangles = mesh.triangles.size();
  stats.voxelSize = grid->voxelSize()[0];
  return stats;
}

// The particles of fluid `fluid` (Scene::fluidOf) of a frame of several, as a frame of one.
ParticleFrame particlesOfFluid(const ParticleFrame& frame, uint8_t fluid) {
  ParticleFrame part;
  part.dimensions = frame.dimensions;
  for (size_t i = 0; i < frame.size(); ++i)
    if (frame.fluid[i] == fluid) {
      part.position.push_back(frame.position[i]);
      part.velocity.push_back(frame.velocity[i]);
      part.id.push_back(frame.id[i]);
    }
  return part;
}

// A frame of several fluids: each fluid after the first made a level set `surface_<name>` and a mesh
// surface_<name>/frame_NNNNN.ply (fluidMeshPath), then the first as a frame of one with those grids beside it.
SurfaceStats surfaceFluids(const ParticleFrame& frame, const Scene& scene, const fs::path& vdbPath,
                           const fs::path& meshPath, const std::vector<SurfaceCollider>& colliders,
                           const DiffuseFrame* whitewater) {
  std::vector<FloatGrid::ConstPtr> others;
  for (size_t f : scene.laterFluids()) {
    const FloatGrid::Ptr grid = buildLevelSet(particlesOfFluid(frame, uint8_t(f)), scene, colliders);
    grid->setName("surface_" + scene.fluids[f].name);
    TriangleMesh mesh = meshLevelSet(*grid, scene.surface.adaptivity);
    if (!colliders.empty()) snapOutOfColliders(mesh, colliders, grid->voxelSize()[0]);
    writeMeshPly(fluidMeshPath(meshPath, scene.fluids[f].name), mesh);
    others.push_back(grid);
  }
  return surfaceFrameWith(particlesOfFluid(frame, 0), scene, vdbPath, meshPath, colliders, whitewater, others);
}

}  // namespace

SurfaceStats surfaceFrame(const ParticleFrame& frame, const Scene& scene, const fs::path& vdbPath,
                          const fs::path& meshPath) {
  return surfaceFrameWith(frame, scene, vdbPath, meshPath, {});
}

void surfaceFrames(const fs::path& dir, const Scene& scene, const FrameRange& range, Progress& progress,
                   bool resume) {
  const std::vector<int> all = listFrames(dir, "particles", "ply");
  if (all.empty())
    throw InputError(dir.string(), "no particle frames (particles/frame_NNNNN.ply) to surface");
  std::vector<int> frames;
  std::copy_if(all.begin(), all.end(), std::back_inserter(frames), [&](int f) { return range.contains(f); });
  if (frames.empty())
    throw InputError(
        dir.string(), "--frames",
        "no particle frame in " + std::to_string(range.first) + ":" + std::to_string(range.last));
  for (const char* ext : {"vdb", "ply", "obj"}) removeTemporaries(dir, "surface", ext, range);
  for (size_t b : scene.laterFluids()) removeTemporaries(dir, "surface_" + scene.fluids[b].name, "ply", range);
  // Written before any frame, so that every frame made with these settings is newer than it.
  const fs::path settings = writeStageSettings(dir, "surface", scene);
  if (resume) {
    const auto done = [&](int f) {
      std::vector<fs::path> outputs = {framePath(dir, "surface", f, "vdb"),
                                       framePath(dir, "surface", f, "ply")};
      if (scene.surface.write_obj) outputs.push_back(framePath(dir, "surface", f, "obj"));
      for (size_t b : scene.laterFluids())
        outputs.push_back(fluidMeshPath(framePath(dir, "surface", f, "ply"), scene.fluids[b].name));
      std::vector<fs::path> inputs = {framePath(dir, "particles", f, "ply"), settings};
      if (std::error_code error; fs::exists(framePath(dir, "whitewater", f, "ply"), error))
        inputs.push_back(framePath(dir, "whitewater", f, "ply"));
      for (const fs::path& file : colliderFrameFiles(dir, scene, f)) inputs.push_back(file);
      return isUpToDate(outputs, inputs);
    };
    frames.erase(std::remove_if(frames.begin(), frames.end(), done), frames.end());
  }
  // The colliders and bodies, the standing ones made level sets once here: none for a scene without them, nor
  // when no frame is left to do.
  const bool meet = !frames.empty() && (!scene.colliders.empty() || !scene.bodies.empty());
  const SurfaceColliders colliders(dir, meet ? solidFiles(scene) : std::vector<SolidFiles>(),
                                   scene.particle_spacing, meet ? colliderGrids(scene) : ColliderGrids());
  progress.start("surface", frames.size());
  // Frames in parallel, one chunk each (OpenVDB's and our own loops inside a frame share the same oneTBB
  // workers). Each frame's files depend only on its particles, so the bytes are the same at any thread count.
  std::mutex advance;
  parallelFor(
      0, frames.size(),
      [&](size_t begin, size_t end) {
        for (size_t i = begin; i < end; ++i) {
          Progress::checkInterrupt();
          const int f = frames[i];
          const fs::path path = framePath(dir, "particles", f, "ply");
          const ParticleFrame frame = readParticlePly(path);
          if (const long far = farParticle(frame, resolve(frame, scene).voxel); far >= 0)
            throw InputError(path.string(), "vertex " + std::to_string(far),
                             "lies more than 2^22 voxels (surface.voxel_size) from the origin");
          // Isolated: a frame beside one that fails runs to its end and is written whole (runIsolated).
          // The frame's whitewater, when the folder has it, goes into the VDB beside the water.
          DiffuseFrame diffuse;
          const bool whitewater = readDiffusePlyIfPresent(framePath(dir, "whitewater", f, "ply"), diffuse);
          runIsolated([&] {
            const fs::path vdb = framePath(dir, "surface", f, "vdb"), mesh = framePath(dir, "surface", f, "ply");
            const std::vector<SurfaceCollider> solids =
                colliders.empty() ? std::vector<SurfaceCollider>() : colliders.atFrame(f);
            if (!frame.fluid.empty()) surfaceFluids(frame, scene, vdb, mesh, solids, whitewater ? &diffuse : nullptr);
            else surfaceFrameWith(frame, scene, vdb, mesh, solids, whitewater ? &diffuse : nullptr);
          });
          const std::lock_guard<std::mutex> lock(advance);
          progress.advance();
        }
      },
      1);
  progress.finish();
}

std::vector<std::string> surfaceMethods() {
  std::vector<std::string> names;
  for (const SurfaceMethod& m : kMethods) names.emplace_back(m.name);
  return names;
}

TriangleMesh meshParticles(const ParticleFrame& frame, const Scene& scene) {
  const FloatGrid::Ptr grid = buildLevelSet(frame, scene);
  return meshLevelSet(*grid, scene.surface.adaptivity);
}

std::vector<double> signedDistancesAt(const ParticleFrame& frame, const Scene& scene,
                                      const std::vector<Eigen::Vector3d>& points) {
  const FloatGrid::Ptr grid = buildLevelSet(frame, scene);
  std::vector<double> distances;
  for (const Eigen::Vector3d& x : points) {
    const openvdb::Vec3d ijk = grid->transform().worldToIndex(openvdb::Vec3d(x.x(), x.y(), x.z()));
    distances.push_back(double(openvdb::tools::BoxSampler::sample(grid->getConstAccessor(), ijk)));
  }
  return distances;
}

}  // namespace surge
