// A 32-bit integer hash with full avalanche (Chris Wellons' "lowbias32" constants): the seed of every random
// number Surge draws, so that a draw depends on what it is for (a frame, a pixel, a particle), never on a thread.
#pragma once

#include <cstdint>

namespace surge {

inline uint32_t hashBits(uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352dU;
  x ^= x >> 15;
  x *= 0x846ca68bU;
  x ^= x >> 16;
  return x;
}

// A uniform number in [0, 1) from hashed bits: their top 24, exact in a float.
inline float unitFromBits(uint32_t bits) { return float(bits >> 8) * (1.0f / 16777216.0f); }

}  // namespace surge
