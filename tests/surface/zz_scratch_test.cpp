// SCRATCH (to be deleted): diagnostics for the anisotropic field.
#include <gtest/gtest.h>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <map>
#include "surface/anisotropy.h"
#include "surface/particle_field.h"
#include "surface/surfacer.h"

namespace surge {
namespace {
ParticleFrame blk(int nx, int ny, int nz, double h, Eigen::Vector3d o, double jitter = 0) {
  ParticleFrame f;
  for (int i = 0; i < nx; ++i) for (int j = 0; j < ny; ++j) for (int k = 0; k < nz; ++k) {
    Eigen::Vector3f x = (o + h * Eigen::Vector3d(i, j, k)).cast<float>();
    f.position.push_back(x); f.velocity.push_back(Eigen::Vector3f::Zero()); f.id.push_back(uint32_t(f.id.size()));
  }
  for (size_t i = 0; i < f.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      const uint32_t bits = uint32_t(i * 2654435761u) ^ uint32_t((k + 1) * 40503u * (i + 7));
      f.position[i][k] += float(jitter * h * ((double(bits % 2001) / 1000.0) - 1.0));
    }
  return f;
}
double vol(const TriangleMesh& m) { double v = 0; for (auto& t : m.triangles) v += m.positions[t[0]].cast<double>().dot(m.positions[t[1]].cast<double>().cross(m.positions[t[2]].cast<double>())) / 6; return v; }
size_t openEdges(const TriangleMesh& mesh) {
  std::map<std::pair<uint32_t, uint32_t>, int> d;
  for (const auto& t : mesh.triangles) for (int e = 0; e < 3; ++e) ++d[{t[e], t[(e + 1) % 3]}];
  size_t bad = 0;
  for (auto& [e, c] : d) { auto r = d.find({e.second, e.first}); if (c != 1 || r == d.end() || r->second != 1) ++bad; }
  return bad;
}
TEST(Scratch, AnisoProfile) {
  const double h = 0.02;
  ParticleFrame f = blk(20, 10, 10, h, Eigen::Vector3d(0.11, 0.01, 0.01));
  Scene s; s.surface.method = "anisotropic"; s.name = "x"; s.dimensions = 3; s.particle_spacing = h;
  s.surface.particle_radius = h; s.surface.voxel_size = h / 2; s.surface.adaptivity = 0;
  // top face at y = 0.01 + 9h + h/2 = 0.2; x centre 0.11 + 9.5h = 0.30, z centre 0.01 + 4.5 h = 0.10
  for (const char* m : {"spheres", "smooth_spheres", "anisotropic"}) {
    s.surface.method = m;
    for (int steps : {0, 2}) {
      s.surface.smoothing_steps = steps;
      TriangleMesh mesh = meshParticles(f, s);
      std::printf("%s steps %d: volume err %.2f%% open %zu tris %zu\n", m, steps, 100 * (vol(mesh) / (2000 * h * h * h) - 1), openEdges(mesh), mesh.triangles.size());
      std::printf("  phi along y at (0.30, y, 0.10) [y in spacings from face]:");
      for (double dy = -2; dy <= 1.01; dy += 0.25) std::printf(" %.2f:%.3f", dy, signedDistanceAt(f, s, Eigen::Vector3d(0.30, 0.2 + dy * h, 0.10)) / h);
      std::printf("\n");
    }
  }
}
}  // namespace
}  // namespace surge
namespace surge {
namespace {
TEST(Scratch, AnisoRaw) {
  const double h = 0.02;
  ParticleFrame f = blk(20, 10, 10, h, Eigen::Vector3d(0.11, 0.01, 0.01));
  AnisotropyParameters a; a.spacing = h; a.supportRadius = 2 * h; a.pcaRadius = 3 * h;
  AnisotropicKernels k = anisotropicKernels(f.position, a);
  std::printf("maxExtent %.4f (h=%.3f)\n", k.maxExtent, h);
  // particle at top centre: i=10,j=9,k=5 -> index (10*10+9)*10+5
  for (int j : {9, 8, 5}) {
    size_t i = size_t((10 * 10 + j) * 10 + 5);
    std::printf("particle j=%d x %.4f %.4f %.4f centre %.4f %.4f %.4f detG*h^3 %.3f\n G*h=\n", j, f.position[i].x(), f.position[i].y(), f.position[i].z(), k.centre[i].x(), k.centre[i].y(), k.centre[i].z(), k.G[i].determinant() * 8 * h * h * h);
    std::cout << k.G[i] * 2 * h << "\n";
  }
  const double sigma = 315 / (64 * 3.14159265358979);
  for (double dy = -3; dy <= 1.01; dy += 0.25) {
    Eigen::Vector3f x(0.30f, float(0.2 + dy * h), 0.10f);
    double fv = 0;
    for (size_t j = 0; j < f.size(); ++j) {
      double q2 = (k.G[j] * (x - k.centre[j])).squaredNorm();
      if (q2 < 1) fv += h * h * h * sigma * k.G[j].determinant() * std::pow(1 - q2, 3);
    }
    std::printf("dy %.2f f %.4f\n", dy, fv);
  }
}
}  // namespace
}  // namespace surge
namespace surge {
namespace {
TEST(Scratch, AnisoRaster) {
  const double h = 0.02, v = h / 2;
  ParticleFrame f = blk(20, 10, 10, h, Eigen::Vector3d(0.11, 0.01, 0.01));
  AnisotropyParameters a; a.spacing = h; a.supportRadius = 2 * h; a.pcaRadius = 3 * h;
  AnisotropicKernels k = anisotropicKernels(f.position, a);
  FieldParticles p; p.position = &f.position; p.kernels = &k;
  FieldParameters fp; fp.kind = FieldKind::Anisotropic; fp.voxel = v; fp.band = 3 * v; fp.radius = h; fp.occupancyCell = 2 * h;
  fp.iso = 0.5; fp.volume = h * h * h; fp.volume = k.particleVolume;
  BlockField b = rasterizeField(p, fp);
  std::printf("blocks %zu\n", b.origins.size());
  // voxel (30, y, 10)
  for (int iy = 12; iy <= 24; ++iy) {
    Eigen::Vector3i vox(30, iy, 10), o(24, (iy / 8) * 8, 8);
    float val = 999;
    for (size_t i = 0; i < b.origins.size(); ++i) if (b.origins[i] == o) val = b.values[i * 512 + ((vox.x() - o.x()) * 8 + vox.y() - o.y()) * 8 + vox.z() - o.z()];
    std::printf("iy %d y %.3f phi/band %.3f\n", iy, iy * v, val / fp.band);
  }
}
}  // namespace
}  // namespace surge
namespace surge {
namespace {
TEST(Scratch, AnisoFaces) {
  const double h = 0.02;
  ParticleFrame f = blk(20, 10, 10, h, Eigen::Vector3d(0.11, 0.01, 0.01));
  Scene s; s.surface.method = "anisotropic"; s.name = "x"; s.dimensions = 3; s.particle_spacing = h;
  s.surface.particle_radius = h; s.surface.voxel_size = h / 2; s.surface.adaptivity = 0;
  // faces: x 0.10..0.50, y 0..0.2, z 0..0.2 ; centre (0.30, 0.10, 0.10)
  const Eigen::Vector3d c(0.30, 0.10, 0.10), half(0.20, 0.10, 0.10);
  for (const char* m : {"spheres", "anisotropic"}) {
    s.surface.method = m;
    TriangleMesh mesh = meshParticles(f, s);
    std::printf("%s vol %.2f%%:", m, 100 * (vol(mesh) / (2000 * h * h * h) - 1));
    for (int k = 0; k < 3; ++k) for (int sgn : {-1, 1}) {
      Eigen::Vector3d p = c; p[k] += sgn * half[k];
      std::printf(" face%d%c %.3f", k, sgn > 0 ? '+' : '-', signedDistanceAt(f, s, p) / h);
    }
    // edge: along the x axis at the y+ z+ corner line, diagonal distance
    Eigen::Vector3d e(0.30, 0.20, 0.20);
    std::printf(" edge %.3f", signedDistanceAt(f, s, e) / h);
    // where is the surface along the diagonal from the edge inward
    for (double t = -1.5; t <= 0.51; t += 0.25) std::printf(" %.2f:%.2f", t, signedDistanceAt(f, s, e + Eigen::Vector3d(0, t * h, t * h)) / h);
    std::printf("\n");
  }
}
}  // namespace
}  // namespace surge
