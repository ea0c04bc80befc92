#include "sim/kernels.h"

#include <gtest/gtest.h>

namespace surge {
namespace {

// Integrates a radial kernel over the plane or space with the midpoint rule in r: 20000 intervals of a
// polynomial of degree <= 6 leave a relative error far below the 1e-4 asserted.
template <int Dim, typename F>
double radialIntegral(float h, F kernel) {
  const int steps = 20000;
  const double dr = h / steps;
  double total = 0;
  for (int s = 0; s < steps; ++s) {
    const double r = (s + 0.5) * dr;
    const double shell = Dim == 3 ? 4 * M_PI * r * r : 2 * M_PI * r;
    total += kernel(float(r)) * shell * dr;
  }
  return total;
}

template <int Dim>
void expectNormalised(float h) {
  Kernels<Dim> k(h);
  EXPECT_NEAR(radialIntegral<Dim>(h, [&](float r) { return k.poly6(r * r); }), 1.0, 1e-4);
  EXPECT_NEAR(radialIntegral<Dim>(h, [&](float r) { return k.spiky(r); }), 1.0, 1e-4);
}

TEST(Kernels, IntegrateToOne) {
  expectNormalised<3>(0.1f);
  expectNormalised<3>(1.0f);
  expectNormalised<2>(0.1f);
  expectNormalised<2>(2.0f);
}

template <int Dim>
void expectGradientMatchesFiniteDifferences() {
  const float h = 1.0f;
  Kernels<Dim> k(h);
  // Central differences of W_spiky in double precision along each axis at points inside the support.
  for (float radius : {0.1f, 0.35f, 0.6f, 0.9f}) {
    Vec<Dim> r = Vec<Dim>::Zero();
    r[0] = radius * 0.6f;
    r[1] = radius * 0.8f;
    const Vec<Dim> analytic = k.spikyGradient(r, r.norm());
    for (int axis = 0; axis < Dim; ++axis) {
      const float step = 1e-3f;
      Vec<Dim> plus = r, minus = r;
      plus[axis] += step;
      minus[axis] -= step;
      const double numeric = (double(k.spiky(plus.norm())) - double(k.spiky(minus.norm()))) / (2.0 * step);
      // The central difference error is O(step^2 W''') ~ 1e-6 relative; float rounding of W near ~1 over a
      // 2e-3 step gives ~1e-4 absolute on gradients of order 1-10, hence 1e-3 relative plus 1e-3 absolute.
      EXPECT_NEAR(analytic[axis], numeric, 1e-3 * std::abs(numeric) + 1e-3) << "r=" << radius << " axis " << axis;
    }
  }
}

TEST(Kernels, SpikyGradientMatchesFiniteDifferences) {
  expectGradientMatchesFiniteDifferences<2>();
  expectGradientMatchesFiniteDifferences<3>();
}

TEST(Kernels, SpikyGradientIsZeroAtTheCentreAndOutside) {
  Kernels<3> k(0.1f);
  const Vec<3> zero = Vec<3>::Zero();
  const Vec<3> g = k.spikyGradient(zero, 0.0f);
  EXPECT_TRUE(g.allFinite());
  EXPECT_EQ(g, zero);
  const Vec<3> outside(0.2f, 0, 0);
  EXPECT_EQ(k.spikyGradient(outside, 0.2f), zero);
  EXPECT_EQ(k.poly6(0.1f * 0.1f), 0.0f);  // r = h exactly
  Kernels<2> k2(0.1f);
  EXPECT_EQ(k2.spikyGradient(Vec<2>::Zero(), 0.0f), Vec<2>::Zero());
}

TEST(Kernels, GradientPointsTowardsTheOtherParticle) {
  // grad_{p_i} W(p_i - p_j) points from p_i towards p_j: density rises as i approaches j.
  Kernels<3> k(1.0f);
  const Vec<3> r(0.5f, 0, 0);  // p_i - p_j with p_i to the right of p_j
  EXPECT_LT(k.spikyGradient(r, 0.5f).x(), 0.0f);
}

}  // namespace
}  // namespace surge

namespace surge {
namespace {

template <int Dim, typename Kernel>
void expectKernelNormalisedWithMatchingGradient(float support) {
  const Kernel kernel(support);
  EXPECT_NEAR(radialIntegral<Dim>(support, [&](float r) { return kernel.value(r); }), 1.0, 1e-4);
  // The gradient factor against central differences of W along r, at points on both pieces of the cubic.
  for (float q : {0.1f, 0.3f, 0.45f, 0.55f, 0.8f, 0.95f}) {
    const float r = q * support, step = 1e-3f * support;
    const double numeric = (double(kernel.value(r + step)) - double(kernel.value(r - step))) / (2.0 * step);
    // g r is the radial derivative; float rounding over the 2e-3 H step bounds the error as in the spiky test.
    EXPECT_NEAR(kernel.gradientFactor(r) * r, numeric, 1e-3 * std::abs(numeric) + 1e-3 * kernel.value(0) / support)
        << "q = " << q;
  }
  EXPECT_EQ(kernel.gradientFactor(0.0f), 0.0f);
  EXPECT_EQ(kernel.value(support), 0.0f);
}

TEST(Kernels, CubicSplineAndWendlandAreNormalised) {
  expectKernelNormalisedWithMatchingGradient<3, CubicSplineKernel<3>>(0.1f);
  expectKernelNormalisedWithMatchingGradient<2, CubicSplineKernel<2>>(0.1f);
  expectKernelNormalisedWithMatchingGradient<3, WendlandC2Kernel<3>>(0.1f);
  expectKernelNormalisedWithMatchingGradient<2, WendlandC2Kernel<2>>(2.0f);
}

// PBF's Wendland C2 (PbfWendlandC2, its closed form from r^2) is the SPH methods' WendlandC2Kernel: the same W and
// gradient factor within float rounding across the support, W(0) = sigma, and nothing at or beyond h.
template <int Dim>
void expectPbfWendlandIsWendland(float support) {
  const PbfWendlandC2<Dim> pbf(support);
  const WendlandC2Kernel<Dim> sph(support);
  for (float q : {0.05f, 0.2f, 0.4f, 0.5f, 0.7f, 0.9f, 0.99f}) {
    const float r = q * support;
    const auto pair = pbf.pair(r * r);
    EXPECT_NEAR(pair.weight, sph.value(r), 1e-5f * sph.value(0)) << "q = " << q;
    EXPECT_NEAR(pair.gradientFactor, sph.gradientFactor(r), 1e-5f * std::abs(sph.gradientFactor(0.5f * support)))
        << "q = " << q;
    EXPECT_EQ(pbf.weight(r * r), pair.weight);
    const Vec<Dim> offset = Vec<Dim>::Constant(r / std::sqrt(float(Dim)));
    EXPECT_TRUE(pbf.gradient(offset, r).isApprox(pair.gradientFactor * offset));
  }
  EXPECT_FLOAT_EQ(pbf.weight(0.0f), sph.value(0.0f));
  EXPECT_EQ(pbf.pair(support * support).weight, 0.0f);
  EXPECT_EQ(pbf.pair(support * support).gradientFactor, 0.0f);
  EXPECT_EQ(pbf.pair(4 * support * support).weight, 0.0f);
}

TEST(Kernels, PbfsWendlandIsTheSphMethodsWendland) {
  expectPbfWendlandIsWendland<2>(0.0025f);
  expectPbfWendlandIsWendland<3>(0.1f);
}

}  // namespace
}  // namespace surge
