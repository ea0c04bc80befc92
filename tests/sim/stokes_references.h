// Reference solutions of creeping flow past solids, for the tests that hold Surge's drag to them.
#pragma once

#include <cmath>

namespace surge {

// Faxen's drag per unit length per unit speed on a cylinder of radius a moving along the midline between two
// plane walls 2 l apart, at low Reynolds number (Happel and Brenner 1965, to (a/l)^4):
// F / U = 4 pi mu / (ln(l / a) - 0.9157 + 1.7244 (a/l)^2 - 1.7302 (a/l)^4).
inline double faxenDragPerSpeed(double mu, double a, double l) {
  const double ratio = a / l;
  return 4 * M_PI * mu / (std::log(l / a) - 0.9157 + 1.7244 * std::pow(ratio, 2) - 1.7302 * std::pow(ratio, 4));
}

}  // namespace surge
