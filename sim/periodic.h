// domain.periodic: the axes along which the domain wraps. A pair's offset is its nearest image (x_i - x_j less
// the multiple of the period that brings it within half a period), positions are moved back into the domain by
// a whole period when they leave it, and the neighbour grid reaches across the seam (sim/neighbor_grid.h). The
// domain is at least three kernel radii long on a periodic axis (core/scene_validate.cpp), so a neighbour has
// one image within the kernel's support.
//
// A method's pair loop takes the offset through a functor chosen once per loop (withNearestImage): NoWrap in a
// scene without periodic axes, so its loops compile to what they were, byte for byte and at the same speed. Each
// thread's body copies the functor into a local first: read through a reference, the compiler must assume the
// loop's stores may change its periods and reloads them every pair (PBF's vectorised loops gathered them lane by
// lane, and a periodic pool took 2.06 times a walled one's step; with the copy 1.0, docs/performance.md).
#pragma once

#include <cmath>
#include <vector>

#include "core/parallel.h"
#include "core/scene.h"
#include "sim/kernels.h"

namespace surge {

// The identity: offsets in a domain that does not wrap.
struct NoWrap {
  template <typename V>
  void operator()(V&) const {}
};

template <int Dim>
class PeriodicDomain {
 public:
  using VecD = Vec<Dim>;

  PeriodicDomain() = default;
  explicit PeriodicDomain(const Scene& scene) {
    for (int k = 0; k < Dim; ++k) {
      min_[k] = static_cast<float>(scene.domain.min[k]);
      if (!scene.isPeriodic(k)) continue;
      axes_ |= 1 << k;
      period_[k] = static_cast<float>(scene.domain.max[k] - scene.domain.min[k]);
      inverse_[k] = 1.0f / period_[k];
    }
  }

  bool active() const { return axes_ != 0; }
  bool everyAxis() const { return axes_ == (1 << Dim) - 1; }  // a box with no wall at all
  bool periodic(int k) const { return axes_ >> k & 1; }
  float period(int k) const { return period_[k]; }
  float min(int k) const { return min_[k]; }

  // The nearest image of an offset's component k (the identity on an axis that does not wrap: period 0): less a
  // period when over half of one, plus one when under minus half. For a pair, always within a period, that is
  // r - period floor(r / period + 0.5) by two selects.
  float component(int k, float r) const {
    const float x = r * inverse_[k];
    return x >= 0.5f ? r - period_[k] : x < -0.5f ? r + period_[k] : r;
  }
  // The same on an offset held as components (a vectorised loop's; r2 is 0 in 2D and left so).
  void nearest(float& r0, float& r1, float& r2) const {
    r0 = component(0, r0);
    r1 = component(1, r1);
    if constexpr (Dim == 3) r2 = component(2, r2);
  }
  void operator()(VecD& r) const {
    for (int k = 0; k < Dim; ++k) r[k] = component(k, r[k]);
  }

  // Calls f(wrap) with NoWrap in a domain without periodic axes, else with this: a loop written once serves both.
  template <typename F>
  decltype(auto) withNearestImage(F&& f) const {
    if (axes_ == 0) return f(NoWrap{});
    return f(*this);
  }

  // Moves every position of `key` back into the domain, and each of `also` (positions of the same particles
  // taken at another time, or empty) by the same periods, so differences between them stay as they were.
  void wrap(std::vector<VecD>& key, std::vector<VecD>* also = nullptr) const {
    if (axes_ == 0) return;
    parallelFor(0, key.size(), [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i) {
        const VecD shift = wrapPoint(key[i]);
        if (also && !shift.isZero()) (*also)[i] += shift;
      }
    });
  }

  // Moves one position back into the domain; returns the shift it took.
  VecD wrapPoint(VecD& p) const {
    const VecD shift = shiftInto(p);
    if (shift.isZero()) return shift;
    p += shift;
    // Rounding can leave x + period at the upper end of the domain: the lower end is the same place.
    for (int k = 0; k < Dim; ++k)
      if (periodic(k) && !(p[k] < min_[k] + period_[k])) p[k] = min_[k];
    return shift;
  }

 private:
  // The whole periods that bring p into [min, min + period) on the periodic axes (zero elsewhere).
  VecD shiftInto(const VecD& p) const {
    VecD shift = VecD::Zero();
    for (int k = 0; k < Dim; ++k)
      if (periodic(k)) {
        const float periods = std::floor((p[k] - min_[k]) * inverse_[k]);
        if (periods != 0 && std::isfinite(periods)) shift[k] = -periods * period_[k];
      }
    return shift;
  }

  int axes_ = 0;
  float min_[3] = {0, 0, 0}, period_[3] = {0, 0, 0}, inverse_[3] = {0, 0, 0};
};

}  // namespace surge
