// The particle frame reader (particles/frame_NNNNN.ply: what surge surface, render and sim --resume read). A
// frame that loads must write and load back to the same particles.
#include <cstdint>

#include "core/ply.h"
#include "fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = surge::fuzz::writeInput(data, size, "ply");
  surge::fuzz::expectOnlySurgeErrors([&] {
    const surge::ParticleFrame frame = surge::readParticlePly(path);
    surge::writeParticlePly(path, frame);
    const surge::ParticleFrame again = surge::readParticlePly(path);
    if (again.size() != frame.size() || again.dimensions != frame.dimensions) __builtin_trap();
  });
  return 0;
}
