// SCRATCH (to be deleted): diagnostics for the anisotropic field.
#include <gtest/gtest.h>
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
