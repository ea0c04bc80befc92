// Tests of surface/anisotropy.h on a rest lattice: the interior gets the isotropic kernel, whether through
// the PCA or through the shortcut for deep particles, and the faces get kernels flattened across them.
#include "surface/anisotropy.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

namespace surge {
namespace {

TEST(AnisotropicKernels, InteriorIsIsotropicAndFacesAreFlattened) {
  // A 36^3 block of spacing 1: cells of the PCA radius (3) make it 12 cells a side, so the middle cells are
  // deep (all cells within 3 occupied) and the particles just outside them go through the PCA.
  const int n = 36;
  std::vector<Eigen::Vector3f> x;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) x.emplace_back(float(i), float(j), float(k));
  AnisotropyParameters p;
  p.spacing = 1;
  p.supportRadius = 2;
  p.pcaRadius = 3;
  const AnisotropicKernels kernels = anisotropicKernels(x, p);
  const Eigen::Matrix3f isotropic = Eigen::Matrix3f::Identity() / 2.0f;
  size_t interior = 0;
  for (size_t a = 0; a < x.size(); ++a) {
    const float depth = std::min({x[a].minCoeff(), float(n - 1) - x[a].maxCoeff()});
    if (depth >= 3) {
      // Three spacings in, the PCA neighbourhood is a full lattice: k_s makes G exactly I / h (to the float
      // rounding of a covariance of ~100 terms, 1e-5), and the weighted mean is the particle itself.
      ASSERT_LT((kernels.G[a] - isotropic).norm(), 1e-5f) << x[a].transpose();
      ASSERT_LT((kernels.centre[a] - x[a]).norm(), 1e-4f) << x[a].transpose();
      ++interior;
    }
  }
  EXPECT_EQ(interior, size_t(30 * 30 * 30));
  // The middle of the top face: the kernel is thinner across the face (y) than along it, by at least the
  // clamp's factor of the axes (k_r = 4) to within the lattice's discreteness (so at least 2 here).
  const size_t top = (size_t(n / 2) * n + (n - 1)) * n + n / 2;
  ASSERT_EQ(x[top], Eigen::Vector3f(float(n / 2), float(n - 1), float(n / 2)));
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3f> eigen(kernels.G[top]);
  const Eigen::Vector3f stretch = eigen.eigenvalues();  // |G r| grows fastest across the face
  EXPECT_GT(stretch[2] / stretch[0], 2.0f);
  EXPECT_GT(std::abs(eigen.eigenvectors().col(2).y()), 0.99f);
}

}  // namespace
}  // namespace surge
