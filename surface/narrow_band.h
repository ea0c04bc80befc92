// A narrow-band level set on blocks of 8^3 voxels (particle_field.h's BlockField), and the few operations the
// surfacer needs on it, as plain loops over dense blocks: no OpenVDB, so it compiles in seconds and every
// stencil reads a block and its ghost layer from one padded array instead of through a tree accessor.
//
// Values are signed distances in world units, negative inside, clamped to [-inside, +outside]: the two limits
// differ because the erosion that follows the smoothing moves the surface inward, so the inside must reach
// that much deeper than the final band. A block missing from the field lies wholly on one side of the
// surface: its voxels read as the clamp value of the sign of the nearest voxel of the block beside it (a
// block next to the band is never missing: the rasteriser, like OpenVDB's pruning, keeps every block with a
// voxel in the band).
//
// Every operation is Jacobi (reads the field before it, writes a new one), so the values are the same bytes
// at any thread count.
#pragma once

#include <cstdint>
#include <vector>

#include "surface/particle_field.h"

namespace surge {

class NarrowBand {
 public:
  // Takes the blocks of a distance field (clamped at +-band by the rasteriser) and widens the inside clamp to
  // `inside` (>= band; values are not changed, only allowed that deep from now on).
  NarrowBand(BlockField blocks, double voxel, float outside, float inside);

  // One explicit step of mean-curvature flow, phi += dt H |grad phi| with H the mean curvature (the mean of
  // the principal curvatures) from central differences, dt = voxel^2 / 3 (tools::LevelSetFilter's step):
  // the surface moves by at most a third of a voxel times its curvature in voxels.
  void meanCurvatureStep();

  // Adds c to every value (c > 0 erodes), then clamps to [-inside, outside].
  void offset(float c);

  // Jacobi iterations of the Eikonal equation |grad phi| = 1 away from the surface: the voxels beside the
  // zero crossing (a face neighbour of the other sign) are kept, every other voxel takes the first-order
  // upwind (Godunov) solution from its neighbours of its own sign. Each iteration makes one more layer of
  // voxels a distance to the surface the kept voxels define; a plane is a fixed point at any orientation.
  void redistance(int iterations);

  const BlockField& blocks() const { return blocks_; }
  double voxel() const { return voxel_; }

 private:
  static constexpr int kPad = kBlockDim + 2;  // a block and its ghost layer
  // Block b and its ghost layer from `values` into out[kPad^3], at ((x + 1) * kPad + y + 1) * kPad + z + 1.
  void gather(const std::vector<float>& values, size_t b, float* out) const;
  // Calls body(p, c, i) for every voxel, in parallel over blocks: p is the voxel's block gathered from
  // `values` with its ghost layer, c the voxel's index in p, i its index in the blocks' values.
  template <typename Body>
  void forEachVoxel(const std::vector<float>& values, const Body& body) const;

  BlockField blocks_;
  double voxel_;
  float outside_, inside_;
  std::vector<int32_t> neighbors_;  // 27 per block, (dx + 1) * 9 + (dy + 1) * 3 + dz + 1; -1 where missing
};

}  // namespace surge
