// Random numbers for rendering that depend only on (frame, pixel, sample), never on which thread draws them
// or in which order the tiles run: each sample starts a counter-based generator from a hash of the three, so
// an image is the same bytes whatever the thread count.
//
// The first few pairs of numbers of a path (pixel jitter, sun sample and bounce direction of the first hits)
// are stratified across a pixel's samples instead of independent: pair d of sample s is point p(s) of the R2
// sequence (Roberts 2018, the 2D Kronecker lattice of the plastic number), where p is a random permutation of
// the samples drawn afresh for every (frame, pixel, pair) (Kensler 2013, "Correlated Multi-Jittered
// Sampling"), shifted by a random offset modulo 1 (Cranley-Patterson rotation). Each pair is then uniform on
// the unit square for any one sample, as the estimator needs, while the samples of a pixel cover it evenly,
// which makes low sample counts markedly less noisy. Later numbers are plain hashed uniforms.
#pragma once

#include <cstdint>

#include "core/hash.h"

namespace surge {

// Element i of a pseudo-random permutation of 0..length-1 chosen by `seed` (Kensler 2013, listing 3).
inline uint32_t permuteIndex(uint32_t i, uint32_t length, uint32_t seed) {
  uint32_t w = length - 1;
  w |= w >> 1;
  w |= w >> 2;
  w |= w >> 4;
  w |= w >> 8;
  w |= w >> 16;
  do {
    i ^= seed;
    i *= 0xe170893dU;
    i ^= seed >> 16;
    i ^= (i & w) >> 4;
    i ^= seed >> 8;
    i *= 0x0929eb3fU;
    i ^= seed >> 23;
    i ^= (i & w) >> 1;
    i *= 1 | seed >> 27;
    i *= 0x6935fa69U;
    i ^= (i & w) >> 11;
    i *= 0x74dcb303U;
    i ^= (i & w) >> 2;
    i *= 0x9e501cc3U;
    i ^= (i & w) >> 2;
    i *= 0xc860a3dfU;
    i &= w;
    i ^= i >> 5;
  } while (i >= length);
  return (i + seed) % length;
}

// The random stream of one sample of one pixel of one frame.
class SampleRandom {
 public:
  // `samples` is the pixel's sample count, over which the first pairs are stratified (1: no stratification).
  SampleRandom(uint32_t frame, uint32_t pixel, uint32_t sample, uint32_t samples = 1)
      : pixelSeed_(hashBits(hashBits(frame) ^ pixel)),
        seed_(hashBits(pixelSeed_ + sample)),
        sample_(sample),
        samples_(samples) {}

  // Uniform in [0, 1): the top 24 bits of the hashed counter, exact in a float.
  float next() {
    ++counter_;
    return toUnit(hashBits(seed_ ^ hashBits(counter_)));
  }

  // Two uniforms in [0, 1), stratified over the pixel's samples for the first kStratifiedPairs calls.
  void next2(float& a, float& b) {
    if (pair_ >= kStratifiedPairs || samples_ <= 1) {
      a = next();
      b = next();
      return;
    }
    const uint32_t pairSeed = hashBits(pixelSeed_ ^ hashBits(0x9e3779b9U + pair_++));
    const uint32_t index = permuteIndex(sample_, samples_, pairSeed);
    // R2: multiples of 1/phi2 and 1/phi2^2, phi2 = 1.3247... (the plastic number), in 32-bit fixed point.
    const uint32_t x = uint32_t(index * 3242174889U) + hashBits(pairSeed ^ 0x68e31da4U);
    const uint32_t y = uint32_t(index * 2447445414U) + hashBits(pairSeed ^ 0xb5297a4dU);
    a = toUnit(x);
    b = toUnit(y);
  }

 private:
  static constexpr uint32_t kStratifiedPairs = 6;
  static float toUnit(uint32_t bits) { return unitFromBits(bits); }

  uint32_t pixelSeed_, seed_, sample_, samples_;
  uint32_t counter_ = 0, pair_ = 0;
};

}  // namespace surge
