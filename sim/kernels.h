// SPH smoothing kernels, templated on the dimension; the 2D normalisations make each integrate to one over the
// plane. Kernels: poly6 and spiky (Mueller et al. 2003), as Position Based Fluids uses them (PBF eq. 2 and 8).
// CubicSplineKernel and WendlandC2Kernel: the SPH methods' (WCSPH, DFSPH), chosen by `solver.kernel` through
// SphKernel, the one place that reads that key. PbfWendlandC2: Wendland C2 in the interface of PBF's Kernels.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <string>

namespace surge {

template <int Dim>
using Vec = Eigen::Matrix<float, Dim, 1>;

// A scene's vector (double, 3D) as the solver's.
template <int Dim>
Vec<Dim> toVec(const Eigen::Vector3d& v) {
  return v.head<Dim>().template cast<float>();
}

template <int Dim>
class Kernels {
 public:
  explicit Kernels(float h) : h_(h), h2_(h * h) {
    const double pi = M_PI, hd = h;
    if (Dim == 3) {
      poly6_ = static_cast<float>(315.0 / (64.0 * pi * std::pow(hd, 9)));
      spiky_ = static_cast<float>(15.0 / (pi * std::pow(hd, 6)));
    } else {
      poly6_ = static_cast<float>(4.0 / (pi * std::pow(hd, 8)));
      spiky_ = static_cast<float>(10.0 / (pi * std::pow(hd, 5)));
    }
  }

  float radius() const { return h_; }

  // W_poly6(r, h) from the squared distance r2.
  float poly6(float r2) const {
    const float d = std::max(h2_ - r2, 0.0f);  // branch-free, for the vectorised loops
    return poly6_ * d * d * d;
  }

  // The names PbfWendlandC2 shares: W of eq. 2 from r^2, and the gradient of eq. 8.
  float weight(float r2) const { return poly6(r2); }
  Vec<Dim> gradient(const Vec<Dim>& r, float rLength) const { return spikyGradient(r, rLength); }

  // W_spiky(r, h); used only to test normalisation, PBF needs only its gradient.
  float spiky(float r) const {
    if (r >= h_) return 0.0f;
    const float d = h_ - r;
    return spiky_ * d * d * d;
  }

  // Both kernels of a pair at once from r2 = |p_i - p_j|^2, with one square root: W_poly6, and the factor g
  // such that grad_{p_i} W_spiky(p_i - p_j, h) = g (p_i - p_j). Branch-free, for the solver's inner loops.
  struct Pair {
    float weight;
    float gradientFactor;
  };
  Pair pair(float r2) const {
    const float length = std::sqrt(r2);
    const float d2 = std::max(h2_ - r2, 0.0f);
    const float d = std::max(h_ - length, 0.0f);
    const float factor = -3.0f * spiky_ * d * d / std::max(length, 1e-12f);
    return {poly6_ * d2 * d2 * d2, length > 1e-12f ? factor : 0.0f};
  }

  // grad_{p_i} W_spiky(p_i - p_j, h) for r = p_i - p_j of length rLength. Zero at r = 0 (no direction).
  Vec<Dim> spikyGradient(const Vec<Dim>& r, float rLength) const {
    if (rLength >= h_ || rLength <= 1e-12f) return Vec<Dim>::Zero();
    const float d = h_ - rLength;
    return (-3.0f * spiky_ * d * d / rLength) * r;
  }

 private:
  float h_, h2_;
  float poly6_, spiky_;
};

// An SPH kernel's value and gradient factor at one distance (CubicSplineKernel::pair, WendlandC2Kernel::pair).
struct SphKernelPair {
  float value, gradientFactor;
};

// The kernels of the SPH methods (WCSPH, DFSPH), with support H (the scene's kernel_radius), q = r / H:
//   cubic spline (Monaghan 1992, in the form of SPlisHSPlasH): 6 (q^3 - q^2) + 1 for q <= 1/2, 2 (1 - q)^3 for
//     q <= 1, times 8 / (pi H^3) in 3D and 40 / (7 pi H^2) in 2D;
//   Wendland C2 (Wendland 1995): (1 - q)^4 (1 + 4 q), times 21 / (2 pi H^3) in 3D and 7 / (pi H^2) in 2D.
// value(r) is W; gradientFactor(r) is g with grad_{p_i} W(p_i - p_j) = g (p_i - p_j), zero at r = 0.
template <int Dim>
class CubicSplineKernel {
 public:
  explicit CubicSplineKernel(float support)
      : support_(support),
        inverseSupport_(1.0f / support),
        sigma_(static_cast<float>(Dim == 3 ? 8.0 / (M_PI * std::pow(double(support), 3))
                                           : 40.0 / (7.0 * M_PI * double(support) * support))) {}
  float radius() const { return support_; }
  float value(float r) const {
    const float q = r * inverseSupport_;
    if (q >= 1.0f) return 0.0f;
    if (q <= 0.5f) return sigma_ * (6.0f * (q * q * q - q * q) + 1.0f);
    const float d = 1.0f - q;
    return sigma_ * 2.0f * d * d * d;
  }
  float gradientFactor(float r) const {
    const float q = r * inverseSupport_;
    if (q >= 1.0f || r <= 1e-12f) return 0.0f;
    const float dWdq = q <= 0.5f ? 6.0f * q * (3.0f * q - 2.0f) : -6.0f * (1.0f - q) * (1.0f - q);
    return sigma_ * dWdq * inverseSupport_ / r;
  }
  // value(r) and gradientFactor(r) at once, from one q.
  SphKernelPair pair(float r) const {
    const float q = r * inverseSupport_;
    if (q >= 1.0f) return {0.0f, 0.0f};
    const float d = 1.0f - q;
    const bool inner = q <= 0.5f;
    const float value = sigma_ * (inner ? 6.0f * (q * q * q - q * q) + 1.0f : 2.0f * d * d * d);
    const float dWdq = inner ? 6.0f * q * (3.0f * q - 2.0f) : -6.0f * d * d;
    return {value, r <= 1e-12f ? 0.0f : sigma_ * dWdq * inverseSupport_ / r};
  }

 private:
  float support_, inverseSupport_, sigma_;
};

template <int Dim>
class WendlandC2Kernel {
 public:
  explicit WendlandC2Kernel(float support)
      : support_(support),
        inverseSupport_(1.0f / support),
        sigma_(static_cast<float>(Dim == 3 ? 21.0 / (2.0 * M_PI * std::pow(double(support), 3))
                                           : 7.0 / (M_PI * double(support) * support))) {}
  float radius() const { return support_; }
  float value(float r) const {
    const float q = r * inverseSupport_;
    if (q >= 1.0f) return 0.0f;
    const float d = 1.0f - q;
    return sigma_ * d * d * d * d * (1.0f + 4.0f * q);
  }
  float gradientFactor(float r) const {
    const float q = r * inverseSupport_;
    if (q >= 1.0f || r <= 1e-12f) return 0.0f;
    const float d = 1.0f - q;
    return sigma_ * (-20.0f * q * d * d * d) * inverseSupport_ / r;
  }
  // value(r) and gradientFactor(r) at once, from one q.
  SphKernelPair pair(float r) const {
    const float q = r * inverseSupport_;
    if (q >= 1.0f) return {0.0f, 0.0f};
    const float d = 1.0f - q;
    return {sigma_ * d * d * d * d * (1.0f + 4.0f * q),
            r <= 1e-12f ? 0.0f : sigma_ * (-20.0f * q * d * d * d) * inverseSupport_ / r};
  }

 private:
  float support_, inverseSupport_, sigma_;
};

// Wendland C2 in the interface of PBF's Kernels: weight and pair from r^2, gradient from r. PBF takes it for both
// its density (eq. 2) and its constraint's gradient (eq. 8) in a 2D scene with surface tension, where poly6 and
// spiky hold a drop's lattice as a stiff body (PbfSolver::wendland_; docs/surface-tension.md, "PBF's 2D kernel").
template <int Dim>
class PbfWendlandC2 {
 public:
  explicit PbfWendlandC2(float h) : inverseSupport_(1.0f / h), sigma_(WendlandC2Kernel<Dim>(h).value(0.0f)) {}
  float weight(float r2) const { return pair(r2).weight; }
  // Branch-free for the vectorised loops: with q = r / h and d = 1 - q, W = sigma d^4 (1 + 4 q) and
  // grad W = -20 sigma d^3 / h^2 r (WendlandC2Kernel's gradient factor with q / r = 1 / h).
  typename Kernels<Dim>::Pair pair(float r2) const {
    const float q = std::sqrt(r2) * inverseSupport_;
    const float d = std::max(1.0f - q, 0.0f), d3 = d * d * d;
    return {sigma_ * d3 * d * (1.0f + 4.0f * q), -20.0f * sigma_ * inverseSupport_ * inverseSupport_ * d3};
  }
  Vec<Dim> gradient(const Vec<Dim>& r, float rLength) const { return pair(rLength * rLength).gradientFactor * r; }

 private:
  float inverseSupport_, sigma_;
};

// The scene's SPH kernel (`solver.kernel`, support `solver.kernel_radius`): visit(use) calls use(kernel) with
// the chosen one, so that a method's loops are compiled for each kernel and pick one per pass, not per pair.
template <int Dim>
class SphKernel {
 public:
  SphKernel(const std::string& name, float support)
      : wendland_(name == "wendland_c2"), cubic_(support), wendlandC2_(support) {}
  float radius() const { return cubic_.radius(); }
  template <typename Use>
  decltype(auto) visit(Use&& use) const {
    return wendland_ ? use(wendlandC2_) : use(cubic_);
  }

 private:
  bool wendland_;
  CubicSplineKernel<Dim> cubic_;
  WendlandC2Kernel<Dim> wendlandC2_;
};

}  // namespace surge
