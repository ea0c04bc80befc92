// Narrow-band operations on blocks (see narrow_band.h).
#include "surface/narrow_band.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "core/parallel.h"

namespace surge {
namespace {

constexpr int64_t kOffset = int64_t(1) << 20;

uint64_t blockKey(const Eigen::Vector3i& origin) {
  const Eigen::Vector3i b = origin / kBlockDim;  // origins are multiples of 8, so the division is exact
  return (uint64_t(b.x() + kOffset) << 42) | (uint64_t(b.y() + kOffset) << 21) | uint64_t(b.z() + kOffset);
}

// Blocks per parallel chunk: a block is 512 voxels of stencil work.
constexpr size_t kGrain = 8;

}  // namespace

NarrowBand::NarrowBand(BlockField blocks, double voxel, float outside, float inside)
    : blocks_(std::move(blocks)), voxel_(voxel), outside_(outside), inside_(inside) {
  const size_t n = blocks_.origins.size();
  std::vector<std::pair<uint64_t, int32_t>> keys(n);
  for (size_t b = 0; b < n; ++b) keys[b] = {blockKey(blocks_.origins[b]), int32_t(b)};
  std::sort(keys.begin(), keys.end());
  neighbors_.assign(n * 27, -1);
  parallelFor(0, n, [&](size_t begin, size_t end) {
    for (size_t b = begin; b < end; ++b)
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dz = -1; dz <= 1; ++dz) {
            const uint64_t key = blockKey(blocks_.origins[b] + kBlockDim * Eigen::Vector3i(dx, dy, dz));
            const auto it = std::lower_bound(keys.begin(), keys.end(), std::make_pair(key, int32_t(-1)));
            if (it != keys.end() && it->first == key)
              neighbors_[b * 27 + (dx + 1) * 9 + (dy + 1) * 3 + dz + 1] = it->second;
          }
  });
}

void NarrowBand::gather(const std::vector<float>& values, size_t b, float* out) const {
  const auto pad = [](int x, int y, int z) { return ((x + 1) * kPad + y + 1) * kPad + z + 1; };
  const auto at = [](int x, int y, int z) { return (x * kBlockDim + y) * kBlockDim + z; };
  const float* own = &values[b * kBlockVoxels];
  for (int x = 0; x < kBlockDim; ++x)
    for (int y = 0; y < kBlockDim; ++y)
      std::copy(own + at(x, y, 0), own + at(x, y, 0) + kBlockDim, out + pad(x, y, 0));
  // Per axis, the ghost range in this block's coordinates and where it reads in the neighbour: offset -1 is
  // coordinate -1 (the neighbour's 7), 0 is 0..7, +1 is 8 (the neighbour's 0).
  const int lo[3] = {-1, 0, kBlockDim}, hi[3] = {-1, kBlockDim - 1, kBlockDim},
            shift[3] = {kBlockDim, 0, -kBlockDim};
  for (int dx = 0; dx < 3; ++dx)
    for (int dy = 0; dy < 3; ++dy)
      for (int dz = 0; dz < 3; ++dz) {
        if (dx == 1 && dy == 1 && dz == 1) continue;
        const int32_t n = neighbors_[b * 27 + dx * 9 + dy * 3 + dz];
        const float* theirs = n >= 0 ? &values[size_t(n) * kBlockVoxels] : nullptr;
        for (int x = lo[dx]; x <= hi[dx]; ++x)
          for (int y = lo[dy]; y <= hi[dy]; ++y)
            for (int z = lo[dz]; z <= hi[dz]; ++z) {
              float v;
              if (theirs) {
                v = theirs[at(x + shift[dx], y + shift[dy], z + shift[dz])];
              } else {
                const float near = own[at(std::clamp(x, 0, kBlockDim - 1), std::clamp(y, 0, kBlockDim - 1),
                                          std::clamp(z, 0, kBlockDim - 1))];
                v = near < 0 ? -inside_ : outside_;
              }
              out[pad(x, y, z)] = v;
            }
      }
}

template <typename Body>
void NarrowBand::forEachVoxel(const std::vector<float>& values, const Body& body) const {
  parallelFor(
      0, blocks_.origins.size(),
      [&](size_t begin, size_t end) {
        float p[kPad * kPad * kPad];
        for (size_t b = begin; b < end; ++b) {
          gather(values, b, p);
          for (int x = 0; x < kBlockDim; ++x)
            for (int y = 0; y < kBlockDim; ++y)
              for (int z = 0; z < kBlockDim; ++z)
                body(p, ((x + 1) * kPad + y + 1) * kPad + z + 1,
                     b * kBlockVoxels + size_t((x * kBlockDim + y) * kBlockDim + z));
        }
      },
      kGrain);
}

void NarrowBand::meanCurvatureStep() {
  constexpr int sx = kPad * kPad, sy = kPad;
  std::vector<float> next(blocks_.values.size());
  forEachVoxel(blocks_.values, [&](const float* p, int c, size_t i) {
    const float phi = p[c];
    next[i] = phi;
    if (phi <= -inside_ || phi >= outside_) return;  // clamped: not a distance to differentiate
    // Differences in voxel units (undivided); alpha / |g|^2 then comes out in phi's units.
    const float dx = 0.5f * (p[c + sx] - p[c - sx]), dy = 0.5f * (p[c + sy] - p[c - sy]),
                dz = 0.5f * (p[c + 1] - p[c - 1]);
    const float g2 = dx * dx + dy * dy + dz * dz;
    if (g2 <= 1e-12f * float(voxel_ * voxel_)) return;
    const float dxx = p[c + sx] - 2 * phi + p[c - sx], dyy = p[c + sy] - 2 * phi + p[c - sy],
                dzz = p[c + 1] - 2 * phi + p[c - 1];
    const float dxy = 0.25f * (p[c + sx + sy] - p[c + sx - sy] - p[c - sx + sy] + p[c - sx - sy]);
    const float dxz = 0.25f * (p[c + sx + 1] - p[c + sx - 1] - p[c - sx + 1] + p[c - sx - 1]);
    const float dyz = 0.25f * (p[c + sy + 1] - p[c + sy - 1] - p[c - sy + 1] + p[c - sy - 1]);
    // alpha = |g|^3 (k1 + k2), the level set's curvature times |g|^3; H |g| = alpha / (2 |g|^2), and
    // dt = voxel^2 / 3 cancels the voxel^-2 of the undivided differences: phi += alpha / (6 |g|^2).
    const float alpha = dx * dx * (dyy + dzz) + dy * dy * (dxx + dzz) + dz * dz * (dxx + dyy) -
                        2 * (dx * dy * dxy + dx * dz * dxz + dy * dz * dyz);
    next[i] = std::clamp(phi + alpha / (6 * g2), -inside_, outside_);
  });
  blocks_.values.swap(next);
}

void NarrowBand::offset(float c) {
  parallelFor(
      0, blocks_.values.size(),
      [&](size_t begin, size_t end) {
        for (size_t i = begin; i < end; ++i)
          blocks_.values[i] = std::clamp(blocks_.values[i] + c, -inside_, outside_);
      },
      1 << 16);
}

namespace {

// The u >= 0 with sum_k max(0, u - a_k)^2 = h^2: the first-order upwind distance from the nearest neighbours
// a_k (one per axis, the smaller of the two sides), taken in increasing order until the root exceeds the
// next.
float godunovDistance(float a, float b, float c, float h) {
  if (a > b) std::swap(a, b);
  if (b > c) std::swap(b, c);
  if (a > b) std::swap(a, b);
  float u = a + h;
  if (u <= b) return u;
  u = 0.5f * (a + b + std::sqrt(std::max(0.f, 2 * h * h - (a - b) * (a - b))));
  if (u <= c) return u;
  const float s = a + b + c, q = a * a + b * b + c * c;
  return (s + std::sqrt(std::max(0.f, s * s - 3 * (q - h * h)))) / 3;
}

}  // namespace

void NarrowBand::redistance(int iterations) {
  constexpr int sx = kPad * kPad, sy = kPad;
  const float h = float(voxel_);
  std::vector<float> next(blocks_.values.size());
  for (int iteration = 0; iteration < iterations; ++iteration) {
    forEachVoxel(blocks_.values, [&](const float* p, int c, size_t i) {
      const float phi = p[c];
      next[i] = phi;
      // |phi| of a neighbour of the same sign; a neighbour of the other sign keeps this voxel.
      const bool in = phi < 0;
      float side[6];
      const int strides[6] = {-sx, sx, -sy, sy, -1, 1};
      bool crossing = false;
      for (int k = 0; k < 6; ++k) {
        const float q = p[c + strides[k]];
        crossing |= (q < 0) != in;
        side[k] = std::abs(q);
      }
      if (crossing) return;
      const float u = godunovDistance(std::min(side[0], side[1]), std::min(side[2], side[3]),
                                      std::min(side[4], side[5]), h);
      next[i] = in ? std::max(-u, -inside_) : std::min(u, outside_);
    });
    blocks_.values.swap(next);
  }
}

}  // namespace surge
