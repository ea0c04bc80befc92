// Scalar fields of particles on a voxel grid, in blocks of 8^3 voxels (the leaves of an OpenVDB tree, whose
// value order they share), without OpenVDB: surfacer.cpp wraps the blocks into leaf nodes. Every voxel
// gathers over the particles whose support covers it, in a fixed particle order, so the values are the same
// bytes whatever the thread count.
//
// Fields (distances negative inside, in world units, clamped to +-band):
//  - SmoothSpheres: Zhu & Bridson 2005 ("Animating sand as a fluid", SIGGRAPH; "ZB05"), section 3:
//      phi(x) = |x - x-bar| - r-bar,  x-bar = sum_i w_i x_i / sum_i w_i,  r-bar = r (one radius),
//      w_i = k(|x - x_i| / R),  k(s) = max(0, 1 - s^2)^3;
//    +band where no particle is within R.
//  - Anisotropic: Yu & Turk 2013's density field with their anisotropic kernel (anisotropy.h):
//      f(x) = sum_j V W(x - x-bar_j, G_j),  W(r, G) = sigma det(G) P(|G r|),  P(q) = max(0, 1 - q^2)^3,
//    sigma = 315 / (64 pi) (the poly6 normalisation) and V = AnisotropicKernels::particleVolume, so f is 1
//    inside a fluid at rest; stored as the first-order distance (iso - f) / |grad f| (the gradient summed
//    analytically), which is right at the iso-surface whatever f's slope (a flat face's kernels are thin, and
//    f falls from 2 to 0 within one spacing there), and +-band where f is flat.
//  - Velocity: the Shepard average sum_i w_i v_i / sum_i w_i with the ZB05 weights (0 where no particle).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "surface/anisotropy.h"

namespace surge {

constexpr int kBlockDim = 8;
constexpr int kBlockVoxels = kBlockDim * kBlockDim * kBlockDim;

// Voxel (i, j, k) of a grid of voxel size v is the point (i, j, k) * v (OpenVDB's linear transform).
struct BlockField {
  std::vector<Eigen::Vector3i> origins;  // each block's first voxel, a multiple of 8 on every axis
  // kBlockVoxels values per block (3 x that for Velocity, x y z per voxel), voxel (x, y, z) of a block at
  // ((x * 8) + y) * 8 + z, as in openvdb::tree::LeafNode.
  std::vector<float> values;
};

enum class FieldKind { Spheres, SmoothSpheres, Anisotropic, Velocity };

struct FieldParameters {
  FieldKind kind = FieldKind::SmoothSpheres;
  double voxel = 0;
  double radius = 0;    // Spheres, SmoothSpheres: the sphere radius r
  double support = 0;   // SmoothSpheres, Velocity: the weights' support R
  double band = 0;      // distances are clamped to +-band; blocks with no voxel inside (-band, band) are dropped
  double iso = 0.5;     // Anisotropic: the surface is f = iso
  double volume = 0;    // Anisotropic: V, the volume of a particle
  // Distance fields: a block is taken as wholly inside, and skipped, when every cell of this size within
  // `support + band` of it holds a particle (0: never skip). Cells of 2 spacings hold 8 particles at rest.
  double occupancyCell = 0;
};

struct FieldParticles {
  const std::vector<Eigen::Vector3f>* position = nullptr;
  const std::vector<Eigen::Vector3f>* velocity = nullptr;  // Velocity only
  const AnisotropicKernels* kernels = nullptr;              // Anisotropic only
};

// The field over every block that some particle's support reaches; for distance fields, only the blocks that
// hold part of the narrow band (the others are wholly inside or wholly outside). If `only` is given, exactly
// those blocks are evaluated and returned, in that order.
BlockField rasterizeField(const FieldParticles& particles, const FieldParameters& p,
                          const std::vector<Eigen::Vector3i>* only = nullptr);

}  // namespace surge
