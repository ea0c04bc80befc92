// The OBJ reader of collider and body meshes (tinyobjloader, polygons fanned into triangles). Every triangle it
// returns must index a vertex it returns.
#include <cstdint>

#include "fuzz/fuzz_input.h"
#include "geometry/shape_files.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = surge::fuzz::writeInput(data, size, "obj");
  surge::fuzz::expectOnlySurgeErrors([&] {
    const surge::TriangleMesh mesh = surge::readMeshFile(path, "fuzz.json", "colliders[0].file");
    for (const auto& t : mesh.triangles)
      for (int k = 0; k < 3; ++k)
        if (size_t(t[k]) >= mesh.positions.size()) __builtin_trap();
  });
  return 0;
}
