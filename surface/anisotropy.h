// Anisotropic particle kernels after Yu & Turk 2013, "Reconstructing surfaces of particle-based fluids using
// anisotropic kernels" (ACM TOG 32(1), article 5; "YT13" below): each particle's kernel is stretched along the
// principal axes of a weighted PCA of its neighbours, and centred on a Laplacian-smoothed position, so that a
// flat free surface becomes flat discs rather than a layer of bumps. No OpenVDB here (see particle_field.h for
// the rasteriser that sums these kernels on the voxel grid).
#pragma once

#include <Eigen/Core>
#include <vector>

namespace surge {

struct AnisotropicKernels {
  std::vector<Eigen::Vector3f> centre;  // x-bar_i, the smoothed centres
  std::vector<Eigen::Matrix3f> G;       // G_i: |G_i r| <= 1 is the support of particle i's kernel
  double maxExtent = 0;                 // the largest half-extent of any support along x, y or z (world units)
  // V_j of the field f(x) = sum_j V_j W(x - x-bar_j, G_j): the rest volume spacing^3 divided by the lattice sum
  // of the isotropic kernel (1.0 to 1.5% off the integral's 1 at h = 2 spacings), so that f is exactly 1
  // inside a fluid at rest and an iso-value is a fraction of the rest field.
  double particleVolume = 0;
};

struct AnisotropyParameters {
  double spacing = 0;        // the rest lattice's spacing, which normalises the covariances (k_s below)
  double supportRadius = 0;  // h of YT13: the isotropic kernel's support radius (2 x particle_spacing)
  double pcaRadius = 0;      // r_i of YT13: neighbourhood of the PCA and of the smoothing (2 h in the paper)
  double lambda = 0.9;       // YT13 smoothing weight of the centres (0: no smoothing)
  double kr = 4;             // YT13 k_r: largest ratio of the principal axes
  double kn = 0.5;           // YT13 k_n: isolated particles get a sphere of kn x h
  int neighbourThreshold = 25;  // YT13 N_epsilon: fewer neighbours than this means isolated
};

// The kernels of every particle. Deterministic and independent of the thread count (gather over neighbours,
// each particle writes only itself).
AnisotropicKernels anisotropicKernels(const std::vector<Eigen::Vector3f>& positions, const AnisotropyParameters& p);

}  // namespace surge
