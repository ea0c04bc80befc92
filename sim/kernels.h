// SPH smoothing kernels of Mueller et al. 2003 as used by Position Based Fluids (Macklin & Mueller 2013):
// poly6 for density (PBF eq. 2) and the gradient of spiky for constraint gradients (PBF eq. 8). Templated on
// the dimension; the 2D normalisations make each kernel integrate to one over the plane.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

namespace surge {

template <int Dim>
using Vec = Eigen::Matrix<float, Dim, 1>;

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
    if (r2 >= h2_) return 0.0f;
    const float d = h2_ - r2;
    return poly6_ * d * d * d;
  }

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

}  // namespace surge
