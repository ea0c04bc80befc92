// The heightfield reader (a greyscale PNG through stb, 8 or 16 bit) and the solid made of it. Every height must
// be finite and within [0, height].
#include <cmath>
#include <cstdint>

#include "fuzz/fuzz_input.h"
#include "geometry/shape_files.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = surge::fuzz::writeInput(data, size, "png");
  surge::fuzz::expectOnlySurgeErrors([&] {
    const surge::Heightfield field = surge::readHeightfieldPng(path, 1.0f, 1.0f, 0.5f, "fuzz.json", "colliders[0].file");
    for (float h : field.heights)
      if (!std::isfinite(h) || h < 0 || h > 0.5f) __builtin_trap();
    const surge::TriangleMesh mesh = surge::heightfieldMesh(field, -0.1f, 0.05f);
    if (mesh.triangles.empty()) __builtin_trap();
  });
  return 0;
}
