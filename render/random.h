// Random numbers for rendering that depend only on (frame, pixel, sample), never on which thread draws them
// or in which order the tiles run: each sample starts a counter-based generator from a hash of the three, so
// an image is the same bytes whatever the thread count.
#pragma once

#include <cstdint>

namespace surge {

// A 32-bit integer hash with full avalanche (Chris Wellons' "lowbias32" constants).
inline uint32_t hashBits(uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352dU;
  x ^= x >> 15;
  x *= 0x846ca68bU;
  x ^= x >> 16;
  return x;
}

// The random stream of one sample of one pixel of one frame.
class SampleRandom {
 public:
  SampleRandom(uint32_t frame, uint32_t pixel, uint32_t sample)
      : seed_(hashBits(hashBits(hashBits(frame) ^ pixel) + sample)) {}

  // Uniform in [0, 1): the top 24 bits of the hashed counter, exact in a float.
  float next() {
    ++counter_;
    return float(hashBits(seed_ ^ hashBits(counter_)) >> 8) * (1.0f / 16777216.0f);
  }

 private:
  uint32_t seed_;
  uint32_t counter_ = 0;
};

}  // namespace surge
