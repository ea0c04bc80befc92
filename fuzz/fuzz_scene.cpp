// The scene reader with --set overrides: lines at the top of the input that start with "--set " are overrides,
// the rest is the scene's JSON. A scene that loads must also survive what every command does next: its JSON
// (scene.json) loads again to the same JSON, and its particles can be counted (the simulator's memory check,
// sim/solver_defaults.h, multiplies that count), and its formulas evaluate.
#include <cstdint>
#include <string>
#include <vector>

#include "core/expression.h"
#include "core/scene.h"
#include "fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string text(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> overrides;
  while (text.rfind("--set ", 0) == 0) {
    const size_t end = text.find('\n');
    overrides.push_back(text.substr(6, end == std::string::npos ? std::string::npos : end - 6));
    text = end == std::string::npos ? std::string() : text.substr(end + 1);
  }
  surge::fuzz::expectOnlySurgeErrors([&] {
    const surge::Scene scene = surge::parseScene(text, "fuzz.json", overrides);
    const std::string json = surge::sceneToJson(scene);
    const surge::Scene again = surge::parseScene(json, "scene.json");
    if (surge::sceneToJson(again) != json) __builtin_trap();  // scene.json must load to itself
    (void)scene.particleCount();
    for (const surge::FluidBlock& fluid : scene.fluids)  // a formula that parsed evaluates (sim's initialParticles)
      for (const std::string& formula : fluid.velocity_field) (void)surge::Expression(formula)(scene.domain.min);
  });
  return 0;
}
