// The attractor that stands in for the SPH demo's mouse: a point moving along the scene's keyframes (linear
// between them, held before the first and after the last) that accelerates every particle within its radius
// towards itself, by `strength` at its centre falling linearly to zero at the radius (away from it when the
// strength is negative). Absent when the scene gives no keyframes.
#pragma once

#include "core/scene.h"
#include "sim/kernels.h"

namespace surge {

template <int Dim>
class Attractor {
 public:
  explicit Attractor(const AttractorSettings& settings) : settings_(settings) {}

  bool active() const { return !settings_.keyframes.empty(); }

  Vec<Dim> position(double time) const {
    const auto& keys = settings_.keyframes;
    if (time <= keys.front().time) return keys.front().position.head<Dim>().template cast<float>();
    for (size_t k = 1; k < keys.size(); ++k)
      if (time <= keys[k].time) {
        const double span = keys[k].time - keys[k - 1].time;
        const double f = span > 0 ? (time - keys[k - 1].time) / span : 1.0;
        return ((1 - f) * keys[k - 1].position + f * keys[k].position).head<Dim>().template cast<float>();
      }
    return keys.back().position.head<Dim>().template cast<float>();
  }

  // The acceleration of a particle at x when the attractor is at `centre`.
  Vec<Dim> acceleration(const Vec<Dim>& x, const Vec<Dim>& centre) const {
    const Vec<Dim> toCentre = centre - x;
    const float distance = toCentre.norm();
    const float radius = static_cast<float>(settings_.radius);
    if (distance >= radius || distance <= 1e-9f * radius) return Vec<Dim>::Zero();
    return (static_cast<float>(settings_.strength) * (1.0f - distance / radius) / distance) * toCentre;
  }

 private:
  AttractorSettings settings_;
};

}  // namespace surge
