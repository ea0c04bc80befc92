// The triangle mesh PLY reader (a collider's or a body's mesh file, and surface/frame_NNNNN.ply for the
// renderer). Every triangle it returns must index a vertex it returns.
#include <cstdint>

#include "core/ply.h"
#include "fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = surge::fuzz::writeInput(data, size, "ply");
  surge::fuzz::expectOnlySurgeErrors([&] {
    const surge::TriangleMesh mesh = surge::readMeshPly(path);
    for (const auto& t : mesh.triangles)
      for (int k = 0; k < 3; ++k)
        if (size_t(t[k]) >= mesh.positions.size()) __builtin_trap();
  });
  return 0;
}
