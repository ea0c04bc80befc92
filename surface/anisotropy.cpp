// Yu & Turk 2013 anisotropic kernels (YT13, ACM TOG 32(1)). Their section 3 in four steps, per particle i:
//  1. Isotropic weights of the neighbours within r_i:  w_ij = 1 - (|x_i - x_j| / r_i)^3.
//  2. Weighted mean and covariance:
//       x_i^w = sum_j w_ij x_j / sum_j w_ij,   C_i = sum_j w_ij (x_j - x_i^w)(x_j - x_i^w)^T / sum_j w_ij.
//  3. Principal axes C_i = R diag(s1, s2, s3) R^T (s1 >= s2 >= s3, an SVD in YT13, an eigen-decomposition
//     of the symmetric C_i here), the small axes clamped to s1 / k_r and isolated particles (N_i < N_epsilon
//     neighbours) made spheres:
//       Sigma~ = k_s diag(s1, max(s2, s1/k_r), max(s3, s1/k_r))  if N_i >= N_epsilon, else k_n I,
//     and G_i = (1/h) R Sigma~^-1 R^T, so that the kernel W(r, G) = sigma det(G) P(|G r|) is thinner across
//     the surface than along it.
//  4. Laplacian smoothing of the centres:  x-bar_i = (1 - lambda) x_i + lambda x_i^w.
// (No equation numbers: the earlier ones were written from memory and we could not check them against the
// article. The formulas above are what the code does, with YT13's symbols.)
//
// k_s: YT13 pick k_s = 1400 for their units; here it is 1 / s_iso, the variance that the same weights give on
// the full rest lattice, so that an interior particle of a resting fluid gets G = I / h exactly and the
// anisotropic field is the isotropic SPH field wherever the fluid is at rest and away from the surface.
#include "surface/anisotropy.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "core/parallel.h"

namespace surge {
namespace {

double weight(double distance, double radius) {  // step 1
  if (distance >= radius) return 0;
  const double q = distance / radius;
  return 1 - q * q * q;
}

// Variance along x that the weights give on the infinite rest lattice of `spacing` (the mean is the particle
// itself by symmetry): the k_s of step 3.
double latticeVariance(double spacing, double radius) {
  const int n = int(std::ceil(radius / spacing));
  double sum = 0, sumX2 = 0;
  for (int i = -n; i <= n; ++i)
    for (int j = -n; j <= n; ++j)
      for (int k = -n; k <= n; ++k) {
        const double dx = i * spacing, d = spacing * std::sqrt(double(i * i + j * j + k * k));
        const double w = weight(d, radius);
        sum += w;
        sumX2 += w * dx * dx;
      }
  return sumX2 / sum;
}

// Sum over the infinite rest lattice of `spacing` of the poly6 kernel of support h, sigma / h^3 P(|r| / h)
// with P(q) = (1 - q^2)^3 and sigma = 315 / (64 pi): about 1 / spacing^3.
double latticeKernelSum(double spacing, double h) {
  const int n = int(std::ceil(h / spacing));
  double sum = 0;
  for (int i = -n; i <= n; ++i)
    for (int j = -n; j <= n; ++j)
      for (int k = -n; k <= n; ++k) {
        const double q2 = spacing * spacing * double(i * i + j * j + k * k) / (h * h);
        if (q2 < 1) sum += (1 - q2) * (1 - q2) * (1 - q2);
      }
  return sum * 315 / (64 * 3.14159265358979323846 * h * h * h);
}

// A uniform grid of cells of side >= radius over the particles' bounding box, particles counting-sorted by
// cell: neighbours within `radius` lie in the 27 cells around a particle's own.
struct CellGrid {
  Eigen::Vector3d origin;
  double cell = 0;
  Eigen::Vector3i dims;
  std::vector<uint32_t> start, order;
  std::vector<Eigen::Vector3f> sorted;  // x[order[k]]: a cell's particles lie together in memory

  CellGrid(const std::vector<Eigen::Vector3f>& x, double radius) {
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
    for (const auto& p : x) lo = lo.cwiseMin(p.cast<double>()), hi = hi.cwiseMax(p.cast<double>());
    origin = lo;
    cell = radius;
    // A far-flung particle must not make the grid huge: at most 2^24 cells, coarser cells otherwise.
    for (;;) {
      for (int k = 0; k < 3; ++k) dims[k] = int(std::floor((hi[k] - lo[k]) / cell)) + 1;
      if (double(dims[0]) * dims[1] * dims[2] <= double(1 << 24)) break;
      cell *= 2;
    }
    const size_t cells = size_t(dims[0]) * dims[1] * dims[2];
    std::vector<uint32_t> key(x.size());
    start.assign(cells + 1, 0);
    for (size_t i = 0; i < x.size(); ++i) {
      key[i] = uint32_t(index(cellOf(x[i])));
      ++start[key[i] + 1];
    }
    for (size_t c = 0; c < cells; ++c) start[c + 1] += start[c];
    order.resize(x.size());
    std::vector<uint32_t> fill(start.begin(), start.end() - 1);
    for (size_t i = 0; i < x.size(); ++i) order[fill[key[i]]++] = uint32_t(i);  // stable: index order per cell
    sorted.resize(x.size());
    for (size_t k = 0; k < x.size(); ++k) sorted[k] = x[order[k]];
  }
  Eigen::Vector3i cellOf(const Eigen::Vector3f& p) const {
    Eigen::Vector3i c;
    for (int k = 0; k < 3; ++k) c[k] = std::clamp(int(std::floor((p[k] - origin[k]) / cell)), 0, dims[k] - 1);
    return c;
  }
  size_t index(const Eigen::Vector3i& c) const { return (size_t(c.z()) * dims.y() + c.y()) * dims.x() + c.x(); }

  template <typename F>
  void forNeighbours(const Eigen::Vector3f& p, F&& f) const {
    const Eigen::Vector3i c = cellOf(p);
    for (int z = std::max(c.z() - 1, 0); z <= std::min(c.z() + 1, dims.z() - 1); ++z)
      for (int y = std::max(c.y() - 1, 0); y <= std::min(c.y() + 1, dims.y() - 1); ++y)
        for (int x = std::max(c.x() - 1, 0); x <= std::min(c.x() + 1, dims.x() - 1); ++x) {
          const size_t cellIndex = index(Eigen::Vector3i(x, y, z));
          for (uint32_t k = start[cellIndex]; k < start[cellIndex + 1]; ++k) f(order[k], sorted[k]);
        }
  }
};

}  // namespace

AnisotropicKernels anisotropicKernels(const std::vector<Eigen::Vector3f>& x, const AnisotropyParameters& p) {
  AnisotropicKernels out;
  const size_t n = x.size();
  out.centre.resize(n);
  out.G.resize(n);
  if (n == 0) return out;
  const double h = p.supportRadius, r = p.pcaRadius;
  const double ks = 1 / latticeVariance(p.spacing, r);
  const CellGrid grid(x, r);
  std::vector<float> extent(n);
  // Deep particles: every cell within 3 cells of theirs holds a particle. A free surface passes through cells
  // that border an empty one, so it is at least 2 cells (6 spacings) away: beyond their kernel's support (2
  // spacings) and the level set's band (at most 2), so their kernels' shapes cannot reach the surface, and
  // they keep the interior's isotropic kernel, G = I / h (what the PCA gives on the rest lattice), without
  // the PCA. (A bubble smaller than a cell is filled, as the rasteriser's skipping of blocks inside does.)
  const auto deepCells = [&] {
    const Eigen::Vector3i& d = grid.dims;
    std::vector<uint8_t> deep(size_t(d.x()) * d.y() * d.z(), 0);
    parallelFor(0, deep.size(), [&](size_t begin, size_t end) {
      for (size_t c = begin; c < end; ++c) {
        const Eigen::Vector3i at(int(c % size_t(d.x())), int((c / size_t(d.x())) % size_t(d.y())),
                                 int(c / (size_t(d.x()) * d.y())));
        bool full = true;
        for (int z = at.z() - 3; z <= at.z() + 3 && full; ++z)
          for (int y = at.y() - 3; y <= at.y() + 3 && full; ++y)
            for (int x0 = at.x() - 3; x0 <= at.x() + 3 && full; ++x0) {
              if (x0 < 0 || y < 0 || z < 0 || x0 >= d.x() || y >= d.y() || z >= d.z()) full = false;
              else {
                const size_t cell = grid.index(Eigen::Vector3i(x0, y, z));
                full = grid.start[cell + 1] > grid.start[cell];
              }
            }
        deep[c] = full;
      }
    });
    return deep;
  }();

  const double r2 = r * r;
  // Particles in the grid's cell order, so that neighbouring particles' neighbours are still in cache; each
  // particle's result depends only on its neighbours, not on the order.
  parallelFor(0, n, [&](size_t begin, size_t end) {
    std::vector<std::pair<uint32_t, double>> within;  // the neighbours j with their weights w_ij
    for (size_t k = begin; k < end; ++k) {
      const size_t i = grid.order[k];
      if (deepCells[grid.index(grid.cellOf(x[i]))]) {
        out.centre[i] = x[i];
        out.G[i] = Eigen::Matrix3f::Identity() / float(h);
        extent[i] = float(h);
        continue;
      }
      const Eigen::Vector3d xi = x[i].cast<double>();
      // Step 2: the weighted mean, then the covariance about it (two passes, for accuracy in float data).
      double sumW = 0;
      int neighbours = 0;
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      within.clear();
      grid.forNeighbours(x[i], [&](uint32_t j, const Eigen::Vector3f& xjf) {
        const Eigen::Vector3d xj = xjf.cast<double>();
        const double d2 = (xj - xi).squaredNorm();
        if (d2 >= r2) return;
        const double w = weight(std::sqrt(d2), r);
        if (w <= 0) return;
        within.emplace_back(j, w);
        sumW += w;
        mean += w * xj;
        neighbours += j != i;
      });
      mean /= sumW;  // sumW >= 1: the particle itself has weight 1
      out.centre[i] = ((1 - p.lambda) * xi + p.lambda * mean).cast<float>();  // step 4

      Eigen::Matrix3d G;
      if (neighbours + 1 < p.neighbourThreshold) {
        G = Eigen::Matrix3d::Identity() / (p.kn * h);  // isolated: a small sphere (Sigma~ = k_n I)
      } else {
        Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
        for (const auto& [j, w] : within) {
          const Eigen::Vector3d d = x[j].cast<double>() - mean;
          C += w * d * d.transpose();
        }
        C /= sumW;
        // Step 3: eigen-decomposition of the symmetric C (ascending eigenvalues), the small axes clamped.
        const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(C);
        const Eigen::Vector3d s = eigen.eigenvalues().cwiseMax(0.0);
        const double s1 = s[2];
        Eigen::Vector3d sigma(std::max(s[0], s1 / p.kr), std::max(s[1], s1 / p.kr), s1);
        sigma *= ks;
        const Eigen::Matrix3d& R = eigen.eigenvectors();
        G = R * sigma.cwiseInverse().asDiagonal() * R.transpose() / h;  // G_i of step 3
      }
      out.G[i] = G.cast<float>();
      // Half-extent of {r : |G r| <= 1} along each axis: the norm of the row of G^-1 (G is symmetric).
      const Eigen::Matrix3d Ginv = G.inverse();
      extent[i] = float(std::max({Ginv.row(0).norm(), Ginv.row(1).norm(), Ginv.row(2).norm()}));
    }
  });
  out.maxExtent = double(*std::max_element(extent.begin(), extent.end()));
  out.particleVolume = 1 / latticeKernelSum(p.spacing, h);
  return out;
}

}  // namespace surge
