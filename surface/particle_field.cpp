// Particle fields on blocks of 8^3 voxels (see particle_field.h for the fields and their papers).
//
// Layout: particles are sorted by the block that holds their centre; a block of the output gathers the
// particles of the blocks within m = ceil(support / 8 voxels) of it, in sorted order, and each particle adds
// to (or takes the minimum over) the voxels of its support's bounding box inside the block. Gather per block,
// fixed order per voxel: the same bytes at any thread count.
#include "surface/particle_field.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <memory>

#include "core/parallel.h"

namespace surge {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int64_t kKeyOffset = int64_t(1) << 20;

uint64_t keyOf(const Eigen::Vector3i& b) {
  return (uint64_t(b.x() + kKeyOffset) << 42) | (uint64_t(b.y() + kKeyOffset) << 21) |
         uint64_t(b.z() + kKeyOffset);
}
Eigen::Vector3i blockOfKey(uint64_t key) {
  const uint64_t mask = (uint64_t(1) << 21) - 1;
  return Eigen::Vector3i(int(int64_t(key >> 42) - kKeyOffset), int(int64_t((key >> 21) & mask) - kKeyOffset),
                         int(int64_t(key & mask) - kKeyOffset));
}

int floorDiv8(int i) {
  return i >= 0 ? i / 8 : -((-i + 7) / 8);
}

// ZB05's kernel k(s) = (1 - s^2)^3 for s < 1, from s^2.
float zbKernel(float s2) {
  if (s2 >= 1) return 0;
  const float t = 1 - s2;
  return t * t * t;
}

struct Sorted {
  std::vector<uint64_t> keys;   // occupied blocks, ascending
  std::vector<uint32_t> start;  // particles of keys[b]: order[start[b] .. start[b + 1])
  std::vector<uint32_t> order;
};

Sorted sortByBlock(const std::vector<Eigen::Vector3f>& centre, double voxel) {
  const size_t n = centre.size();
  std::vector<std::pair<uint64_t, uint32_t>> pairs(n);
  parallelFor(0, n, [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      Eigen::Vector3i b;
      for (int k = 0; k < 3; ++k) b[k] = floorDiv8(int(std::floor(double(centre[i][k]) / voxel)));
      pairs[i] = {keyOf(b), uint32_t(i)};
    }
  });
  std::sort(pairs.begin(), pairs.end());  // by block, then by particle index: a fixed order
  Sorted s;
  s.order.resize(n);
  for (size_t i = 0; i < n; ++i) {
    if (i == 0 || pairs[i].first != pairs[i - 1].first) {
      s.keys.push_back(pairs[i].first);
      s.start.push_back(uint32_t(i));
    }
    s.order[i] = pairs[i].second;
  }
  s.start.push_back(uint32_t(n));
  return s;
}

// Spheres: acc[voxel] = min(acc[voxel], |x_voxel - x_i| - r) over the candidates i, for the voxels of block
// origin o within `extent` of each centre.
void stampSpheres(const std::vector<Eigen::Vector3f>& centre, const std::vector<uint32_t>& candidates,
                  const Eigen::Vector3i& o, double v, float r, float extent, float* acc) {
  const float extent2 = extent * extent;
  float grid[3][kBlockDim];  // world coordinates of the block's voxel planes, as float(i * v)
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < kBlockDim; ++j) grid[k][j] = float((o[k] + j) * v);
  for (uint32_t i : candidates) {
    const Eigen::Vector3f& x = centre[i];
    int lo[3], hi[3];
    bool empty = false;
    for (int k = 0; k < 3; ++k) {
      const double q = double(x[k]) / v, e = double(extent) / v;
      lo[k] = std::max(0, int(std::ceil(q - e)) - o[k]);
      hi[k] = std::min(kBlockDim - 1, int(std::floor(q + e)) - o[k]);
      empty |= lo[k] > hi[k];
    }
    if (empty) continue;
    float dz2[kBlockDim];
    for (int iz = lo[2]; iz <= hi[2]; ++iz) dz2[iz] = (grid[2][iz] - x.z()) * (grid[2][iz] - x.z());
    for (int ix = lo[0]; ix <= hi[0]; ++ix) {
      const float dx2 = (grid[0][ix] - x.x()) * (grid[0][ix] - x.x());
      if (dx2 > extent2) continue;
      for (int iy = lo[1]; iy <= hi[1]; ++iy) {
        const float dxy2 = dx2 + (grid[1][iy] - x.y()) * (grid[1][iy] - x.y());
        if (dxy2 > extent2) continue;
        float* row = acc + (ix * kBlockDim + iy) * kBlockDim;
        for (int iz = lo[2]; iz <= hi[2]; ++iz) row[iz] = std::min(row[iz], std::sqrt(dxy2 + dz2[iz]) - r);
      }
    }
  }
}

// The weighted fields (SmoothSpheres, Anisotropic, Velocity): per voxel of the block at origin o, 4 sums
// acc[4 a ..] over the candidates, in their order.
void stampWeights(const FieldParticles& particles, const FieldParameters& p,
                  const std::vector<Eigen::Vector3f>& centre, const std::vector<uint32_t>& candidates,
                  const Eigen::Vector3i& o, double extentVoxels, float* acc) {
  const double v = p.voxel;
  const bool anisotropic = p.kind == FieldKind::Anisotropic;
  const float invR2 = p.support > 0 ? float(1 / (p.support * p.support)) : 0.f;
  const float sigma = float(315 / (64 * kPi));
  for (uint32_t i : candidates) {
    const Eigen::Vector3f& x = centre[i];
    int lo[3], hi[3];
    bool empty = false;
    for (int k = 0; k < 3; ++k) {
      const double q = double(x[k]) / v;
      lo[k] = std::max(o[k], int(std::ceil(q - extentVoxels)));
      hi[k] = std::min(o[k] + kBlockDim - 1, int(std::floor(q + extentVoxels)));
      empty |= lo[k] > hi[k];
    }
    if (empty) continue;
    const Eigen::Matrix3f* G = anisotropic ? &particles.kernels->G[i] : nullptr;
    const float scale = anisotropic ? float(p.volume) * sigma * G->determinant() : 0.f;
    const Eigen::Vector3f* vel = p.kind == FieldKind::Velocity ? &(*particles.velocity)[i] : nullptr;
    for (int ix = lo[0]; ix <= hi[0]; ++ix)
      for (int iy = lo[1]; iy <= hi[1]; ++iy)
        for (int iz = lo[2]; iz <= hi[2]; ++iz) {
          const Eigen::Vector3f d = Eigen::Vector3f(float(ix * v), float(iy * v), float(iz * v)) - x;
          const int a = ((ix - o[0]) * kBlockDim + (iy - o[1])) * kBlockDim + (iz - o[2]);
          switch (p.kind) {
            case FieldKind::Spheres:  // stampSpheres
              break;
            case FieldKind::SmoothSpheres: {
              const float w = zbKernel(d.squaredNorm() * invR2);
              float* s = &acc[4 * a];
              s[0] += w, s[1] += w * x.x(), s[2] += w * x.y(), s[3] += w * x.z();
              break;
            }
            case FieldKind::Anisotropic: {
              // f and its gradient: grad_x P(|G d|^2) = -6 (1 - q^2)^2 G^T G d, and G is symmetric.
              const Eigen::Vector3f u = *G * d;
              const float q2 = u.squaredNorm();
              if (q2 >= 1) break;
              const float w = 1 - q2;
              const Eigen::Vector3f g = (-6 * scale * w * w) * (*G * u);
              float* s = &acc[4 * a];
              s[0] += scale * w * w * w, s[1] += g.x(), s[2] += g.y(), s[3] += g.z();
              break;
            }
            case FieldKind::Velocity: {
              const float w = zbKernel(d.squaredNorm() * invR2);
              float* s = &acc[4 * a];
              s[0] += w, s[1] += w * vel->x(), s[2] += w * vel->y(), s[3] += w * vel->z();
              break;
            }
          }
        }
  }
}

}  // namespace

BlockField rasterizeField(const FieldParticles& particles, const FieldParameters& p,
                          const std::vector<Eigen::Vector3i>* only) {
  BlockField out;
  const bool anisotropic = p.kind == FieldKind::Anisotropic;
  const std::vector<Eigen::Vector3f>& centre = anisotropic ? particles.kernels->centre : *particles.position;
  if (centre.empty() && !only) return out;
  const double v = p.voxel;
  // Half-extent of a particle's support.
  double extent = p.support;
  if (p.kind == FieldKind::Spheres) extent = p.radius + p.band;
  if (anisotropic) extent = particles.kernels->maxExtent;
  const double extentVoxels = extent / v;
  const int m = std::max(1, int(std::ceil(extentVoxels / kBlockDim)));

  const Sorted sorted = sortByBlock(centre, v);
  std::vector<uint64_t> targets;
  if (only) {
    for (const auto& o : *only)
      targets.push_back(keyOf(Eigen::Vector3i(floorDiv8(o.x()), floorDiv8(o.y()), floorDiv8(o.z()))));
  } else {
    targets.reserve(sorted.keys.size() * 8);
    for (uint64_t key : sorted.keys) {
      const Eigen::Vector3i b = blockOfKey(key);
      for (int dx = -m; dx <= m; ++dx)
        for (int dy = -m; dy <= m; ++dy)
          for (int dz = -m; dz <= m; ++dz) targets.push_back(keyOf(b + Eigen::Vector3i(dx, dy, dz)));
    }
    std::sort(targets.begin(), targets.end());
    targets.erase(std::unique(targets.begin(), targets.end()), targets.end());
  }

  // Occupied cells of side occupancyCell, sorted, for the test of blocks wholly inside the fluid.
  std::vector<uint64_t> occupied;
  const bool skipInside = p.occupancyCell > 0 && p.kind != FieldKind::Velocity && !only;
  const auto cellKey = [&](double x, double y, double z) {
    return keyOf(Eigen::Vector3i(int(std::floor(x / p.occupancyCell)), int(std::floor(y / p.occupancyCell)),
                                 int(std::floor(z / p.occupancyCell))));
  };
  if (skipInside) {
    occupied.resize(centre.size());
    for (size_t i = 0; i < centre.size(); ++i)
      occupied[i] = cellKey(centre[i].x(), centre[i].y(), centre[i].z());
    std::sort(occupied.begin(), occupied.end());
    occupied.erase(std::unique(occupied.begin(), occupied.end()), occupied.end());
  }
  // Every cell within reach of the block's voxels (their support and the band) holds a particle: the block
  // lies inside the fluid, under the band. A heuristic: a void of under two cells inside the fluid is filled.
  const auto whollyInside = [&](const Eigen::Vector3i& o) {
    const double reach = extent + p.band;
    Eigen::Vector3i lo, hi;
    for (int k = 0; k < 3; ++k) {
      lo[k] = int(std::floor((o[k] * v - reach) / p.occupancyCell));
      hi[k] = int(std::floor(((o[k] + kBlockDim - 1) * v + reach) / p.occupancyCell));
    }
    for (int x = lo.x(); x <= hi.x(); ++x)
      for (int y = lo.y(); y <= hi.y(); ++y)
        for (int z = lo.z(); z <= hi.z(); ++z)
          if (!std::binary_search(occupied.begin(), occupied.end(), keyOf(Eigen::Vector3i(x, y, z))))
            return false;
    return true;
  };

  const int channels = p.kind == FieldKind::Velocity ? 3 : 1;
  const bool distance = p.kind != FieldKind::Velocity;
  const float band = float(p.band);
  const float r = float(p.radius);
  std::vector<std::unique_ptr<float[]>> kept(targets.size());

  parallelFor(
      0, targets.size(),
      [&](size_t begin, size_t end) {
        std::vector<uint32_t> candidates;
        std::vector<float> acc(size_t(kBlockVoxels) * 4);
        for (size_t t = begin; t < end; ++t) {
          const Eigen::Vector3i b = blockOfKey(targets[t]);
          const Eigen::Vector3i o = b * kBlockDim;
          if (skipInside && whollyInside(o)) continue;
          candidates.clear();
          for (int dx = -m; dx <= m; ++dx)
            for (int dy = -m; dy <= m; ++dy)
              for (int dz = -m; dz <= m; ++dz) {
                const uint64_t key = keyOf(b + Eigen::Vector3i(dx, dy, dz));
                const auto it = std::lower_bound(sorted.keys.begin(), sorted.keys.end(), key);
                if (it == sorted.keys.end() || *it != key) continue;
                const size_t s = size_t(it - sorted.keys.begin());
                candidates.insert(candidates.end(), sorted.order.begin() + sorted.start[s],
                                  sorted.order.begin() + sorted.start[s + 1]);
              }
          if (candidates.empty() && !only) continue;
          if (p.kind == FieldKind::Spheres) {
            // A minimum is exact in any order, so the candidates need no sorting; the loops skip the corners
            // of each particle's box beyond its extent (values there would be over the band, clamped anyway)
            // and run along z innermost, which the compiler vectorises.
            std::fill(acc.begin(), acc.begin() + kBlockVoxels, band);
            stampSpheres(centre, candidates, o, v, r, float(extent), acc.data());
          } else {
            // The neighbouring blocks come in key order, particles in index order within each: sort once more
            // so the sum order is the particle order, independent of how the blocks were visited.
            std::sort(candidates.begin(), candidates.end());
            std::fill(acc.begin(), acc.end(), 0.f);
            stampWeights(particles, p, centre, candidates, o, extentVoxels, acc.data());
          }
          std::unique_ptr<float[]> values(new float[size_t(kBlockVoxels) * channels]);
          bool inBand = false;
          for (int a = 0; a < kBlockVoxels; ++a) {
            float phi = 0;
            switch (p.kind) {
              case FieldKind::Spheres:
                phi = acc[a];
                break;
              case FieldKind::SmoothSpheres: {
                const float* s = &acc[4 * a];
                if (s[0] <= 0) {
                  phi = band;
                  break;
                }
                const int ix = o[0] + a / 64, iy = o[1] + (a / 8) % 8, iz = o[2] + a % 8;
                const Eigen::Vector3f xbar(s[1] / s[0], s[2] / s[0], s[3] / s[0]);
                phi = (Eigen::Vector3f(float(ix * v), float(iy * v), float(iz * v)) - xbar).norm() - r;
                break;
              }
              case FieldKind::Anisotropic: {
                // First-order distance to the iso-surface, (iso - f) / |grad f|: exact at the crossing, which
                // is all the re-distancing needs; +-band where f is flat (far outside, or deep inside).
                const float* s = &acc[4 * a];
                const float gradient = Eigen::Vector3f(s[1], s[2], s[3]).norm();
                const float offset = float(p.iso) - s[0];
                phi = std::abs(offset) < band * gradient ? offset / gradient : (offset < 0 ? -band : band);
                break;
              }
              case FieldKind::Velocity: {
                const float* s = &acc[4 * a];
                for (int k = 0; k < 3; ++k) values[3 * a + k] = s[0] > 0 ? s[k + 1] / s[0] : 0.f;
                continue;
              }
            }
            phi = std::clamp(phi, -band, band);
            inBand |= phi > -band && phi < band;
            values[a] = phi;
          }
          // A block with no voxel in the band is dropped, and the level set's flood fill gives it a sign from
          // its neighbours. The anisotropic field is re-distanced by OpenVDB from a raw grid whose blocks keep
          // every voxel, where that fill reads the sign of the last voxel of the block before it in z order: at
          // a slanted face, an outside block dropped above an inside corner came out inside, a lump 4 to 6
          // spacings high on the face and an open mesh (Surfacer.SlantedSlab...). So its blocks are all kept,
          // at about a fifth more time; giving dropped blocks their known sign as tiles would be cheaper.
          if (distance && !inBand && !only && !anisotropic) continue;
          kept[t] = std::move(values);
        }
      },
      16);

  const size_t stride = size_t(kBlockVoxels) * channels;
  size_t count = 0;
  for (const auto& k : kept) count += k != nullptr;
  out.origins.reserve(count);
  out.values.resize(count * stride);
  size_t at = 0;
  for (size_t t = 0; t < targets.size(); ++t) {
    if (!kept[t]) continue;
    out.origins.push_back(blockOfKey(targets[t]) * kBlockDim);
    std::copy(kept[t].get(), kept[t].get() + stride, out.values.begin() + ptrdiff_t(at * stride));
    ++at;
  }
  return out;
}

}  // namespace surge
